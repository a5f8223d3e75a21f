#pragma once
// Region of interest and removal of the tractor's own body: the first stage, the cheapest, and the one
// that shrinks the data most.

#include <cstdint>
#include <span>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/perception/cloud.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

// Keeps the points that are finite, inside `roi` and outside `body`, in input order, with their ring.
// Boxes are closed, as pcl::CropBox's: a point on a face of the ROI is kept, one on a face of the body box
// is removed. NaN and infinite coordinates are dropped.
void crop_box(std::span<const LidarPoint> in, const Box3& roi, const Box3& body, Cloud& out);

// The same for the 3D LiDAR's points of a merged frame; the 2D LiDAR's (LidarPoint::source Lidar2d) go to
// `scan2d` instead (cleared first), all of them, in input order: in one pass, not a copy of the frame.
void crop_box(std::span<const LidarPoint> in, const Box3& roi, const Box3& body, Cloud& out,
              std::vector<LidarPoint>& scan2d);

// The same, returning how many of the kept points have x <= count_x_max (the points of `out` a second pass
// `x <= count_x_max` would count; a NaN count_x_max counts none).
[[nodiscard]] std::uint32_t crop_box(std::span<const LidarPoint> in, const Box3& roi, const Box3& body, Cloud& out,
                                     std::vector<LidarPoint>& scan2d, float count_x_max);

}  // namespace fieldguard::perception
