#pragma once
// The RoboSense RS-LiDAR-32 (protocols.md §2.1-§2.4): MSOP data packets to port 6699 and DIFOP device-info packets
// to port 7788, 1248 bytes each, big-endian; distances in 0.5 cm units (the firmware since about Dec 2018).
// Independent of src/drivers on purpose, like hdl32e.hpp.

#include <array>
#include <cstddef>
#include <cstdint>

namespace fieldguard::sim::rs32 {

inline constexpr std::size_t kChannels = 32;
inline constexpr std::size_t kPacketSize = 1248;
inline constexpr std::int64_t kBlockNs = 55520;  // one firing of all 32 channels, 55.52 us
// Channel c fires this long after the block's first firing (rs_driver decoder_RS32.hpp; protocols.md §2.2).
inline constexpr std::array<std::int64_t, kChannels> kFiringOffsetNs{
    0,    2880, 5760, 8640,  11520, 14400, 17280, 20160, 23040, 25920, 28800, 31680, 34560, 37440, 40320, 44640,
    1440, 4320, 7200, 10080, 12960, 15840, 18720, 21600, 24480, 27360, 30240, 33120, 36000, 38880, 41760, 46080};
inline constexpr double kDistanceUnitM = 0.005;
inline constexpr double kMinRangeM = 0.4;  // nearer returns are not reported (rs_driver's RS-32 distance section)
// The optical centre sits this far from the rotation axis along the firing azimuth (rs_driver's RX for the RS-32),
// so every ray starts there.
inline constexpr double kOpticalCentreM = 0.03997;
inline constexpr std::uint16_t kMsopPort = 6699;
inline constexpr std::uint16_t kDifopPort = 7788;
inline constexpr std::int64_t kDifopPeriodNs = 1000000000;  // DIFOP about once a second

// The simulated unit's calibration, as its DIFOP sends it (0.001 degree steps). Vertical: the example unit of
// protocols.md §2.4 (ros_rslidar's rs_lidar_32/angle.csv), channel 0..31. Horizontal (added to the firing azimuth,
// clockwise): +0.3 degree on even channels and -0.3 on odd ones, made up, so that a decoder that ignores the
// correction or applies it against the rotation puts points 0.3 or 0.6 degree off.
inline constexpr std::array<double, kChannels> kVerticalDeg{
    -10.26, 0.30,  -6.41,  -0.02, 2.28,  -0.33, 3.30,  -0.67, 4.61,  1.68,  7.02,  1.30,  10.30, 1.00,  15.02, 0.70,
    -25.00, -2.28, -14.64, -2.67, -7.91, -3.02, -5.41, -3.30, -3.65, -1.02, -4.05, -1.33, -4.39, -1.63, -4.65, -1.98};
inline constexpr std::array<double, kChannels> kHorizontalDeg = [] {
  std::array<double, kChannels> deg{};
  for (std::size_t c = 0; c < kChannels; ++c) deg[c] = c % 2 == 0 ? 0.3 : -0.3;
  return deg;
}();

}  // namespace fieldguard::sim::rs32
