#pragma once
// A 1.75 m adult walking across the tractor's path on straight lines (crossings), one after the other.
// Body: two legs (cylinders, r 7.5 cm, 0.87 m) swinging in stride, a torso box (0.38 x 0.24 x 0.62 m), two
// arms (cylinders, r 4.5 cm) swinging against the legs, a head (ellipsoid, top at 1.75 m). About 0.56 m
// shoulder to shoulder and 0.25-0.55 m front to back depending on the stride. Walking across the path the
// sensor sees the person side-on: the front-to-back depth faces it.

#include <utility>
#include <vector>

#include "sim/geometry.hpp"
#include "sim/primitives.hpp"
#include "sim/terrain.hpp"

namespace fieldguard::sim {

struct Crossing {
  double x_m = 10.0;  // world x of the body's centre line while crossing
  double y_from_m = -8.0;
  double y_to_m = 8.0;
  double t_begin_s = 0.0;  // at y_from
  double t_end_s = 10.0;   // at y_to; the next crossing starts where this one ends in time
};

inline constexpr double kPedestrianHalfWidthM = 0.28;  // shoulder half-width incl. arms, as bounds see it
inline constexpr double kStrideM = 1.3;                // one full gait cycle

// Parts of the person with feet at `feet` (world, z on the ground), facing `heading` (rad), in gait phase
// `phase` (rad).
[[nodiscard]] std::vector<Primitive> person_parts(Vec3 feet, double heading, double phase);

class Pedestrian {
 public:
  explicit Pedestrian(std::vector<Crossing> crossings) : crossings_(std::move(crossings)) {}
  // The person at time t_s (before the first crossing: at its start; after the last: at its end).
  void parts_at(double t_s, const Terrain& terrain, std::vector<Primitive>& out) const;
  [[nodiscard]] const std::vector<Crossing>& crossings() const { return crossings_; }

 private:
  std::vector<Crossing> crossings_;
};

}  // namespace fieldguard::sim
