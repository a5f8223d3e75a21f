#pragma once
// The published ground segmentation: one plane for the whole frame by RANSAC, as pcl::SACSegmentation
// with SACMODEL_PLANE and SAC_RANSAC does it: random 3-point hypotheses (collinear samples skipped), inliers
// nearer than the threshold counted over every point, the best kept, trials stopped once a plane is found
// with 99 % confidence (k = log(0.01) / log(1 - w^3)) or after the maximum; then the plane refitted to its
// inliers (least squares, PCA) and the inliers selected again. Ground = those inliers. Its own seeded
// generator, so the same frame gives the same plane on every platform.
// Thread-compatible.

#include <array>
#include <cstdint>

#include "fieldguard/perception/cloud.hpp"
#include "fieldguard/perception/ground.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

class RansacGround {
 public:
  // sensor_height_m: where the ground is assumed when there is no plane to find (fewer than 3 points).
  // Throws std::invalid_argument for a non-positive iteration count or distance.
  RansacGround(const RansacParams& params, double sensor_height_m);

  void segment(const Cloud& in, GroundLabels& out);

  // The last frame's plane: n . p + d = 0 with |n| = 1 and n_z >= 0; found() is false when there was none
  // (then the level plane at -sensor_height_m stands in).
  [[nodiscard]] const std::array<float, 4>& coefficients() const { return coeff_; }
  [[nodiscard]] bool found() const { return found_; }
  [[nodiscard]] int trials() const { return trials_; }  // hypotheses scored in the last frame
  // Height of the plane under (x, y); the plane's level when it is (near) vertical.
  [[nodiscard]] float ground_z(float x, float y) const;

 private:
  RansacParams params_;
  float sensor_height_m_;
  std::array<float, 4> coeff_{};
  bool found_ = false;
  int trials_ = 0;
  Buffer<std::uint32_t> inliers_;
};

// Points whose distance |a x + b y + c z + d| is below `threshold`: the inner loop of RANSAC, vectorised.
[[nodiscard]] std::size_t count_plane_inliers(const Cloud& in, const std::array<float, 4>& plane, float threshold);

}  // namespace fieldguard::perception
