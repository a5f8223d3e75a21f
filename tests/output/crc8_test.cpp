#include "fieldguard/output/crc8.hpp"

#include <gtest/gtest.h>

#include <array>
#include <string_view>

namespace fieldguard::output {
namespace {

std::span<const std::uint8_t> bytes(std::string_view s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};  // NOLINT: test data
}

// The CRC catalogue's check value: the CRC of the ASCII string "123456789".
TEST(Crc8, SaeJ1850MatchesTheCatalogueCheckValue) { EXPECT_EQ(crc8<kCrc8SaeJ1850>(bytes("123456789")), 0x4B); }

TEST(Crc8, AutosarMatchesTheCatalogueCheckValue) { EXPECT_EQ(crc8<kCrc8Autosar>(bytes("123456789")), 0xDF); }

// protocols.md §7.5's example stop frame: bytes 0-6 01 00 00 00 00 00 05 -> CRC 0x3E.
TEST(Crc8, SaeJ1850OfTheStopFrameExample) {
  constexpr std::array<std::uint8_t, 7> payload{0x01, 0, 0, 0, 0, 0, 0x05};
  EXPECT_EQ(crc8<kCrc8SaeJ1850>(payload), 0x3E);
}

TEST(Crc8, EmptyInputIsInitXorOut) {
  EXPECT_EQ(crc8<kCrc8SaeJ1850>({}), 0x00);  // 0xFF ^ 0xFF
  constexpr Crc8Params kNoXor{0x1D, 0xFF, 0x00};
  EXPECT_EQ(crc8<kNoXor>({}), 0xFF);
}

TEST(Crc8, EverySingleBitFlipChangesTheCrc) {
  std::array<std::uint8_t, 7> p{0x01, 0x1F, 0, 0, 0, 0, 0x05};
  const auto ref = crc8<kCrc8SaeJ1850>(p);
  for (std::size_t i = 0; i < p.size() * 8; ++i) {
    p[i / 8] = static_cast<std::uint8_t>(p[i / 8] ^ (1U << (i % 8)));
    EXPECT_NE(crc8<kCrc8SaeJ1850>(p), ref) << "bit " << i;
    p[i / 8] = static_cast<std::uint8_t>(p[i / 8] ^ (1U << (i % 8)));
  }
}

}  // namespace
}  // namespace fieldguard::output
