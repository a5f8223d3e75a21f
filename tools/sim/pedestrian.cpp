#include "sim/pedestrian.hpp"

#include <algorithm>
#include <cmath>

namespace fieldguard::sim {

std::vector<Primitive> person_parts(Vec3 feet, double heading, double phase) {
  const Vec3 fwd{std::cos(heading), std::sin(heading), 0.0};
  const Vec3 side{-std::sin(heading), std::cos(heading), 0.0};
  const double swing = std::sin(phase);
  std::vector<Primitive> parts;
  parts.reserve(6);
  for (const double s : {-1.0, 1.0}) {
    Primitive leg = make_vertical_cylinder(feet + side * (0.10 * s) + fwd * (0.20 * swing * s), 0.075, 0.87);
    leg.reflectivity = 22.0;  // denim
    parts.push_back(leg);
  }
  Primitive torso = make_box(feet + Vec3{0.0, 0.0, 1.17}, {0.12, 0.19, 0.31}, heading);
  torso.reflectivity = 45.0;
  parts.push_back(torso);
  for (const double s : {-1.0, 1.0}) {
    Primitive arm = make_vertical_cylinder(feet + side * (0.235 * s) + fwd * (-0.15 * swing * s) + Vec3{0.0, 0.0, 0.80},
                                           0.045, 0.64);
    arm.reflectivity = 45.0;
    parts.push_back(arm);
  }
  Primitive head = make_ellipsoid(feet + Vec3{0.0, 0.0, 1.635}, {0.10, 0.08, 0.115}, heading);
  head.reflectivity = 35.0;
  parts.push_back(head);
  return parts;
}

void Pedestrian::parts_at(double t_s, const Terrain& terrain, std::vector<Primitive>& out) const {
  if (crossings_.empty()) {
    out.clear();
    return;
  }
  const Crossing* c = &crossings_.front();
  for (const Crossing& k : crossings_) {
    if (t_s >= k.t_begin_s) c = &k;
  }
  const double span = c->t_end_s - c->t_begin_s;
  const double f = span > 0.0 ? std::clamp((t_s - c->t_begin_s) / span, 0.0, 1.0) : 0.0;
  const double y = c->y_from_m + (c->y_to_m - c->y_from_m) * f;
  const double heading = c->y_to_m >= c->y_from_m ? kPi / 2.0 : -kPi / 2.0;
  const double walked = std::abs(y - c->y_from_m);
  const Vec3 feet{c->x_m, y, terrain.base(c->x_m, y)};
  out = person_parts(feet, heading, 2.0 * kPi * walked / kStrideM);
}

}  // namespace fieldguard::sim
