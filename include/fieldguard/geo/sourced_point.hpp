#pragma once
// A point of the merged frame: 3D LiDAR or lifted 2D LiDAR, marked by its source so detection (and the
// field engineer) can tell which sensor saw it.

#include <cstdint>

#include "fieldguard/core/lidar_point.hpp"  // PointSource

namespace fieldguard::geo {

struct SourcedPoint {
  float x = 0.F;  // m, in the frame the producing function names
  float y = 0.F;
  float z = 0.F;
  float intensity = 0.F;
  float time_s = 0.F;         // after the frame's sensor stamp
  std::uint16_t channel = 0;  // 3D: laser ring; 2D: SCIP step
  PointSource source = PointSource::Lidar3d;
  std::uint8_t flags = 0;  // kExtrapolatedPose when the pose at time_s was held or continued past the samples
};
static_assert(sizeof(SourcedPoint) == 24, "SourcedPoint is a plain 24-byte record");

inline constexpr std::uint8_t kExtrapolatedPose = 1;

}  // namespace fieldguard::geo
