#pragma once
// The vertical layout of a 3D LiDAR's rings, for the rules whose scale is the gap between adjacent rings (the
// clustering radii, the canopy's ring neighbours). An HDL-32E's 32 rings are 1.33 degrees apart everywhere, a
// VLP-16's 16 are 2 degrees apart, an RS-32's are 0.33 degrees apart near the horizon and 4 to 10 degrees at
// the ends. Taken from the decoder's table (built-in, calibration file or DIFOP: lidar3d::Stream::
// ring_elevations_deg()), or one spacing everywhere when the configuration fixes it.
//
// The spacing at an elevation is the larger of the two gaps beside the ring nearest that elevation (beyond the
// outermost rings, the outermost gap); rings even to within 0.05 degree have one spacing, their median gap: a point on
// a ring must reach both its neighbours, and two points join by the larger of their radii. Elevations are seen from the
// detection frame's origin (the sensor, levelled when the frame is fused): a mounting tilt of a few degrees moves the
// lookup by as much, which on a sensor with uneven rings changes the spacing only where the gaps change.

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace fieldguard::perception {

class BeamGeometry {
 public:
  // The HDL-32E's: 32 rings 1.33 degrees apart (what the detection settings were first tuned on).
  BeamGeometry();
  // One spacing everywhere (degrees, > 0 and < 45).
  [[nodiscard]] static BeamGeometry uniform(double spacing_deg);
  // The sensor's rings (degrees, up positive, any order; at least two distinct, each within +-90).
  // Throws std::invalid_argument otherwise.
  explicit BeamGeometry(std::span<const double> ring_elevations_deg);

  [[nodiscard]] double spacing_deg(double elevation_deg) const;
  // tan(spacing) at the elevation whose sine is `sin_elevation` (z / 3D range), from a table of 0.056-degree
  // steps near the horizon: for the hot loops.
  [[nodiscard]] float tan_spacing(float sin_elevation) const { return tan_by_sin_[bin(sin_elevation)]; }
  // The spacing in radians, likewise.
  [[nodiscard]] float spacing_rad(float sin_elevation) const { return rad_by_sin_[bin(sin_elevation)]; }
  [[nodiscard]] double min_spacing_deg() const { return min_deg_; }
  [[nodiscard]] double max_spacing_deg() const { return max_deg_; }
  // One spacing everywhere: configured, or rings whose gaps differ by 0.05 degree at most (then the median gap).
  [[nodiscard]] bool is_uniform() const { return min_deg_ == max_deg_; }
  [[nodiscard]] std::size_t rings() const { return rings_.size(); }  // 0 when uniform() made it
  // "32 rings from -25.00 to 15.02 deg, 0.30 to 10.36 deg apart" or "1.33 deg apart everywhere".
  [[nodiscard]] std::string describe() const;

  friend bool operator==(const BeamGeometry& a, const BeamGeometry& b) {
    return a.rings_ == b.rings_ && a.min_deg_ == b.min_deg_ && a.max_deg_ == b.max_deg_;
  }

 private:
  static constexpr unsigned kBins = 2048;
  static constexpr float kHalfBins = kBins / 2.F;
  static unsigned bin(float sin_elevation) {
    const float f = (sin_elevation + 1.F) * kHalfBins;
    return f <= 0.F ? 0U : (f >= kBins - 1.F ? kBins - 1U : static_cast<unsigned>(f));
  }
  void tabulate();

  std::vector<double> rings_;  // sorted; empty when uniform
  double min_deg_ = 0.0;
  double max_deg_ = 0.0;
  std::vector<float> tan_by_sin_;  // kBins over sin(elevation) in [-1, 1]
  std::vector<float> rad_by_sin_;
};

}  // namespace fieldguard::perception
