#pragma once
// Region of interest and removal of the tractor's own body: the first stage, the cheapest, and the one
// that shrinks the data most.

#include <span>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/perception/cloud.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

// Keeps the points that are finite, inside `roi` and outside `body`, in input order, with their ring.
// Boxes are closed, as pcl::CropBox's: a point on a face of the ROI is kept, one on a face of the body box
// is removed. NaN and infinite coordinates are dropped.
void crop_box(std::span<const LidarPoint> in, const Box3& roi, const Box3& body, Cloud& out);

}  // namespace fieldguard::perception
