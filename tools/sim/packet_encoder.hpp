#pragma once
// Encodes HDL-32E single-return data packets (protocols.md §1.2-§1.4): 12 blocks of FF EE, azimuth in
// 0.01 degree, 32 x (distance in 2 mm units, intensity); then the timestamp (us past the hour) and the
// factory bytes 0x37 (strongest) and 0x21 (HDL-32E). All fields little-endian.

#include <array>
#include <cstdint>

#include "sim/hdl32e.hpp"

namespace fieldguard::sim {

struct EncodedReturn {
  std::uint16_t distance = 0;  // 2 mm units; 0 = no return
  std::uint8_t intensity = 0;
};

struct EncodedBlock {
  std::uint16_t azimuth_cdeg = 0;  // of slot 0 of the block, 0..35999
  std::array<EncodedReturn, hdl32e::kLasers> returns{};
};

using PacketBytes = std::array<std::uint8_t, hdl32e::kPacketSize>;

[[nodiscard]] PacketBytes encode_packet(const std::array<EncodedBlock, hdl32e::kBlocksPerPacket>& blocks,
                                        std::uint32_t timestamp_us);

// Range (m) -> distance units, rounded; 0 (no return) for ranges that do not fit the 16-bit field.
[[nodiscard]] std::uint16_t encode_distance(double range_m);

}  // namespace fieldguard::sim
