#pragma once
// CRC-8 without reflection, parametrised as in the CRC catalogue (width 8, refin = refout = false).
// The stop request and the heartbeat carry CRC-8/SAE-J1850 (protocols.md §7.5).

#include <array>
#include <cstdint>
#include <span>

namespace fieldguard::output {

struct Crc8Params {
  std::uint8_t poly;
  std::uint8_t init;
  std::uint8_t xorout;
};

// CRC catalogue "CRC-8/SAE-J1850": poly 0x1D, init 0xFF, xorout 0xFF, check("123456789") = 0x4B.
inline constexpr Crc8Params kCrc8SaeJ1850{0x1D, 0xFF, 0xFF};
// CRC catalogue "CRC-8/AUTOSAR" (CRC-8H2F): poly 0x2F, init 0xFF, xorout 0xFF, check = 0xDF.
inline constexpr Crc8Params kCrc8Autosar{0x2F, 0xFF, 0xFF};

[[nodiscard]] constexpr std::array<std::uint8_t, 256> crc8_table(std::uint8_t poly) {
  std::array<std::uint8_t, 256> t{};
  for (unsigned i = 0; i < 256; ++i) {
    unsigned c = i;
    for (int b = 0; b < 8; ++b) c = (c & 0x80U) != 0 ? ((c << 1U) ^ poly) & 0xFFU : (c << 1U) & 0xFFU;
    t[i] = static_cast<std::uint8_t>(c);
  }
  return t;
}

template <Crc8Params P>
[[nodiscard]] constexpr std::uint8_t crc8(std::span<const std::uint8_t> bytes) {
  constexpr auto kTable = crc8_table(P.poly);
  std::uint8_t c = P.init;
  for (const std::uint8_t b : bytes) c = kTable[static_cast<std::uint8_t>(c ^ b)];
  return static_cast<std::uint8_t>(c ^ P.xorout);
}

}  // namespace fieldguard::output
