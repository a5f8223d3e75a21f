#pragma once
// The Velodyne HDL-32E (protocols.md §1.2-§1.8); the VLP-16 (vlp16.hpp) shares its packet layout, distance unit
// and factory bytes. Independent of src/drivers on purpose: the simulator's encoders and the project's decoders are
// checked against each other.

#include <array>
#include <cstddef>
#include <cstdint>

namespace fieldguard::sim::hdl32e {

inline constexpr std::size_t kLasers = 32;
inline constexpr std::size_t kBlocksPerPacket = 12;
inline constexpr std::size_t kPacketSize = 1206;
inline constexpr std::int64_t kFiringNs = 1152;           // one laser firing, 1.152 us
inline constexpr std::int64_t kBlockNs = 46080;           // one firing sequence (= one block), 46.08 us
inline constexpr std::int64_t kPacketNs = 12 * kBlockNs;  // 552.96 us
// The packet timestamp marks the LAST firing of the packet (HDL-32E manual, appendix E; protocols.md §1.7):
// 11 * 46.08 + 31 * 1.152 = 542.592 us after block 0 slot 0.
inline constexpr std::int64_t kLastFiringNs = 11 * kBlockNs + 31 * kFiringNs;
inline constexpr double kDistanceUnitM = 0.002;
inline constexpr std::uint8_t kReturnStrongest = 0x37;
inline constexpr std::uint8_t kReturnDual = 0x39;
inline constexpr std::uint8_t kProductHdl32e = 0x21;
inline constexpr std::uint16_t kDataPort = 2368;

// Vertical angle (degrees, + up) of each laser slot in firing order (protocols.md §1.5).
inline constexpr std::array<double, kLasers> kVerticalDeg{
    -30.67, -9.33, -29.33, -8.00, -28.00, -6.67, -26.67, -5.33,  //
    -25.33, -4.00, -24.00, -2.67, -22.67, -1.33, -21.33, 0.00,   //
    -20.00, 1.33,  -18.67, 2.67,  -17.33, 4.00,  -16.00, 5.33,   //
    -14.67, 6.67,  -13.33, 8.00,  -12.00, 9.33,  -10.67, 10.67};

}  // namespace fieldguard::sim::hdl32e
