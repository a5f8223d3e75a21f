#pragma once
// The 2D LiDAR's scan lifted into 3D: each range along its step's ray in the scanner's plane (x forward,
// y left, counter-clockwise angles: scip_data.hpp), through the scanner's mounting into the vehicle frame,
// then into the 3D LiDAR's frame, so the frame's two sources merge into one cloud. A scanner tilted down
// (positive pitch) sweeps the ground and low obstacles in front of the bumper, below the 3D LiDAR's
// lowest beam.

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "fieldguard/core/mounting.hpp"
#include "fieldguard/drivers/scip_data.hpp"
#include "fieldguard/geo/sourced_point.hpp"

namespace fieldguard::geo {

struct ScanLiftParams {
  Mounting scanner;  // the 2D LiDAR in the vehicle frame
  Mounting lidar;    // the 3D LiDAR in the vehicle frame (the output frame)
  // Time of one turn of the scanner's mirror (UTM-30LX-EW: 25 ms). Step i is measured
  // (i - first_step) / steps_per_turn turns after the scan's first step.
  double turn_period_s = 0.025;

  [[nodiscard]] std::vector<std::string> validate() const;
};

struct ScanLiftStats {
  std::size_t values = 0;        // ranges in the scan
  std::size_t lifted = 0;        // appended
  std::size_t out_of_range = 0;  // error codes and ranges beyond dmax (not points)
};

// Thread-compatible; const calls may run concurrently.
class ScanLifter {
 public:
  explicit ScanLifter(const ScanLiftParams& params);  // throws std::invalid_argument when invalid

  // Appends the scan's points to `out` (not cleared), source Lidar2d, channel = step, time_s = the step's
  // time after the scan's first step plus `time_offset_s` (the scan's first step after the frame's stamp).
  ScanLiftStats lift(const scip::Scan& scan, const scip::Geometry& geometry, float time_offset_s,
                     std::vector<SourcedPoint>& out) const;

  [[nodiscard]] const ScanLiftParams& params() const { return params_; }

 private:
  ScanLiftParams params_;
  Eigen::Matrix3d r_;  // scanner -> 3D LiDAR
  Eigen::Vector3d t_;
};

}  // namespace fieldguard::geo
