#pragma once
// Writes one rotation as a binary PCD file (PCL I/O) with fields x y z intensity ring time.

#include <string>

#include "fieldguard/core/lidar_point.hpp"

namespace fieldguard::app {

// Returns "" on success, else what went wrong.
[[nodiscard]] std::string write_pcd(const std::string& path, const LidarFrame& frame);

}  // namespace fieldguard::app
