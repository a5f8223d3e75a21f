#pragma once
// Encodes RS-LiDAR-32 packets (protocols.md §2.2, §2.3), all fields big-endian.
// MSOP: header magic 55 AA 05 0A 5A A5 50 A0, the UTC time of the packet's first firing at 20 (year - 2000, month,
// day, hour, minute, second, ms u16, us u16), a constant 25 degC at 38; 12 blocks of FF EE, azimuth in 0.01 degree,
// 32 x (distance in 0.5 cm units, reflectivity) from 42; tail 00 FF.
// DIFOP: magic A5 FF 00 5A 11 11 55 55, rpm at 8, FOV 0..360 degrees at 32, firmware at 40 (a made-up version whose
// top-board bytes 41..43 are none of the old firmware's markers, so it says 0.5 cm), serial at 292, return mode at
// 300 (0 dual, 1 strongest), UTC time at 303, the angle tables at 468 (vertical) and 564 (horizontal: sign byte 00
// or 01, magnitude u16 in 0.001 degree); tail 0F F0.

#include <cstdint>

#include "sim/packet_encoder.hpp"

namespace fieldguard::sim::rs32 {

[[nodiscard]] PacketBytes encode_msop(const PacketBlocks& blocks, std::int64_t first_firing_unix_ns);

// The simulated unit's DIFOP at `unix_ns`, with its angle table (rs32.hpp).
[[nodiscard]] PacketBytes encode_difop(std::uint16_t rpm, bool dual, std::int64_t unix_ns);

}  // namespace fieldguard::sim::rs32
