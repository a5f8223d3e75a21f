#pragma once
// Test support for the safety tests: obstacles built from their footprint.

#include "fieldguard/perception/obstacle.hpp"

namespace fieldguard::output::safety::test {

// An axis-aligned obstacle whose oriented footprint is the same box, 0.5 m below to 1.2 m above the sensor,
// of 40 points, at the distance of its near edge.
inline perception::Obstacle box(float x0, float y0, float x1, float y1) {
  perception::Obstacle o;
  o.min = {x0, y0, -0.5F};
  o.max = {x1, y1, 1.2F};
  o.obb_center = {0.5F * (x0 + x1), 0.5F * (y0 + y1)};
  o.obb_length_m = x1 - x0;
  o.obb_width_m = y1 - y0;
  o.obb_yaw_rad = 0.F;
  o.distance_m = x0;
  o.points = 40;
  return o;
}

}  // namespace fieldguard::output::safety::test
