#pragma once
// The Velodyne VLP-16 (protocols.md §1.10): the HDL-32E's packet (hdl32e.hpp) with 16 lasers, each block holding
// two firing sequences of all 16 (slots 0-15, then 16-31).

#include <array>
#include <cstddef>
#include <cstdint>

namespace fieldguard::sim::vlp16 {

inline constexpr std::size_t kLasers = 16;
inline constexpr std::int64_t kFiringNs = 2304;     // one laser firing, 2.304 us
inline constexpr std::int64_t kSequenceNs = 55296;  // one firing sequence of all 16 lasers, 55.296 us
inline constexpr std::int64_t kBlockNs = 2 * kSequenceNs;
inline constexpr std::uint8_t kProductVlp16 = 0x22;

// Vertical angle (degrees, + up) of each laser in firing order.
inline constexpr std::array<double, kLasers> kVerticalDeg{-15.0, 1.0, -13.0, 3.0,  -11.0, 5.0,  -9.0, 7.0,
                                                          -7.0,  9.0, -5.0,  11.0, -3.0,  13.0, -1.0, 15.0};

}  // namespace fieldguard::sim::vlp16
