#pragma once
// One classic CAN frame as the sinks take it, and the J1939 identifier fields (protocols.md §7.4).

#include <array>
#include <cstdint>

namespace fieldguard::output {

struct CanFrame {
  std::uint32_t id = 0;  // 29-bit identifier, no flag bits: every frame we send is extended (EFF)
  std::uint8_t len = 0;  // 0..8
  std::array<std::uint8_t, 8> data{};

  friend bool operator==(const CanFrame&, const CanFrame&) = default;
};

inline constexpr std::uint32_t kEffMask = 0x1FFFFFFFU;

// priority (0 highest .. 7), PGN (18 bits) and source address -> 29-bit id. For a PDU1 PGN (PF < 240) the
// PS byte is the destination address, which the PGN itself leaves 0; for PDU2 the PGN carries the group
// extension and `destination` is ignored.
[[nodiscard]] constexpr std::uint32_t j1939_id(std::uint8_t priority, std::uint32_t pgn, std::uint8_t source,
                                               std::uint8_t destination = 0xFF) {
  const std::uint32_t pf = (pgn >> 8U) & 0xFFU;
  std::uint32_t id = (std::uint32_t{priority} & 7U) << 26U | (pgn & 0x3FFFFU) << 8U | source;
  if (pf < 240U) id = (id & ~0xFF00U) | std::uint32_t{destination} << 8U;
  return id;
}

struct J1939Fields {
  std::uint8_t priority = 0;
  std::uint32_t pgn = 0;            // PDU1: PS (the destination) cleared
  std::uint8_t destination = 0xFF;  // PDU1 only; 0xFF (global) for PDU2
  std::uint8_t source = 0;
};

[[nodiscard]] constexpr J1939Fields j1939_fields(std::uint32_t id) {
  J1939Fields f;
  f.priority = static_cast<std::uint8_t>((id >> 26U) & 7U);
  f.source = static_cast<std::uint8_t>(id & 0xFFU);
  const std::uint32_t pf = (id >> 16U) & 0xFFU;
  f.pgn = (id >> 8U) & 0x3FFFFU;
  if (pf < 240U) {
    f.destination = static_cast<std::uint8_t>(f.pgn & 0xFFU);
    f.pgn &= ~0xFFU;
  }
  return f;
}

}  // namespace fieldguard::output
