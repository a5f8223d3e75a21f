#pragma once
// Is a cluster porous (a crop canopy, low foliage) or solid?
//
// A single-return LiDAR ray that enters a canopy stops at a random depth inside it (exponential, mean a few
// tenths of a metre), so the returns of one scan ring that are neighbours in bearing lie at ranges that jump
// back and forth: the ring's trace is a band, not a line. Along a solid surface (a face, a top, a person's
// legs) the same ring's returns lie on a curve whose range changes smoothly with bearing, however obliquely
// the surface is seen. The measure: group the cluster's points by elevation angle (a ring; the groups split
// where the elevation jumps by more than half the ring spacing), sort each group by bearing, and for every
// three consecutive points no farther apart than max_gap_m take how far the middle one's horizontal range lies
// off the mean of its two neighbours'. The median of these is the cluster's ring jitter (m): about the range
// noise on a solid surface, tenths of a metre on a canopy.
//
// Elevation groups are exact in the sensor frame (a ring has one elevation); on a surface seen from nearly
// level (a canopy top, 0.2-0.5 m below the sensor) the voxel grid's centroids keep it too, since a centroid
// that moves along the ray does not change its elevation. Thread-compatible.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "fieldguard/perception/beam_geometry.hpp"
#include "fieldguard/perception/cloud.hpp"

namespace fieldguard::perception {

struct RingJitter {
  float median_m = 0.F;       // median off-curve range of the triples (m); 0 when there are none
  std::uint32_t triples = 0;  // how many triples it was taken over
  // The cluster seen from the sensor: how deep it reaches along the rays (farthest minus nearest horizontal
  // range, m) and how wide it is across them (its bearings' span times its mean range, m). A few returns of
  // one ring that reach deep along nearly one bearing are a ray going into a canopy: no solid surface but one
  // seen edge-on gives them, and a person is 0.3 m deep.
  float depth_m = 0.F;
  float width_m = 0.F;
};

class RingJitterMeter {
 public:
  // `ring_spacing_deg`: the sensor's vertical angle between adjacent rings (HDL-32E 1.33); `max_gap_m`: two
  // points farther apart than this (horizontally) are not neighbours on a ring.
  RingJitterMeter(double ring_spacing_deg, double max_gap_m);
  // The sensor's rings instead (uneven on an RS-32): samples belong to one ring while their elevations step less
  // than half the spacing at their elevation.
  void set_beams(const BeamGeometry& beams);

  [[nodiscard]] RingJitter measure(const Cloud& cloud, std::span<const std::uint32_t> indices);
  // Over every point of `cloud`.
  [[nodiscard]] RingJitter measure_all(const Cloud& cloud);

 private:
  struct Sample {
    float elevation, bearing, range;
  };
  float group_gap_rad_;
  float max_gap_m_;
  std::optional<BeamGeometry> beams_;  // uneven rings: the gap by elevation
  std::vector<Sample> samples_;        // scratch, reused
  std::vector<float> offs_;
  std::vector<std::uint32_t> all_;
};

// A slice of a crop canopy's top (far out the sensor's level ring grazes the canopy, and each ring's returns on it
// form their own small cluster) has too few returns to tell porous from solid, but it sits in the canopy: the
// returns around it lower down (the canopy's front and the ground inside it, labelled ground or standing less
// than the obstacle height) are rays stopping at random depths too, while a person on bare ground stands on
// ground rings whose ranges change smoothly. Measured together with those, the slice's ring jitter says canopy
// or not over enough triples.
struct LowSurroundings {
  std::array<float, 2> min{};  // the cluster's x-y box (m)
  std::array<float, 2> max{};
  float radius_m = 0.F;      // how far around the box on x and y (m)
  float max_height_m = 0.F;  // points at least this high above their ground are not low (m)
};

// Writes to `out` the cluster's points (`members` of `cluster_cloud`), then every point of `cloud` lower than
// around.max_height_m above its ground (`height_m`, one per point) whose x, y lie within around.radius_m of the box,
// except those `skip` marks nonzero (the cluster's own points in `cloud`; empty: none). Throws
// std::invalid_argument when `height_m` (or a non-empty `skip`) does not have one value per point of `cloud`.
void gather_low_surroundings(const Cloud& cluster_cloud, std::span<const std::uint32_t> members, const Cloud& cloud,
                             std::span<const float> height_m, std::span<const std::uint8_t> skip,
                             const LowSurroundings& around, Cloud& out);

}  // namespace fieldguard::perception
