#include "sim/props.hpp"

#include <algorithm>
#include <cmath>

namespace fieldguard::sim {

namespace {

// A primitive built in an object's local frame (x along its heading, z up from the ground), moved into the
// world at `origin` turned by `yaw`.
Primitive place(Primitive p, Vec3 origin, double yaw) {
  const Mat3 r = rot_z(yaw);
  p.center = origin + r * p.center;
  p.rot = r * p.rot;
  return p;
}

Primitive with_reflectivity(Primitive p, double refl, double mean_free_path = 0.0) {
  p.reflectivity = refl;
  p.mean_free_path_m = mean_free_path;
  return p;
}

SceneObject finish(std::string id, ObjectClass cls, std::vector<Primitive> parts) {
  SceneObject o;
  o.id = std::move(id);
  o.cls = cls;
  o.parts = std::move(parts);
  for (const Primitive& p : o.parts) o.bounds.add(bounds(p));
  return o;
}

// Lowest smooth ground under a footprint (so that a building on a slope does not float).
double lowest_ground(const Terrain& t, double x, double y, double half_x, double half_y, double yaw) {
  double g = t.base(x, y);
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      const Vec3 c = rot_z(yaw) * Vec3{sx * half_x, sy * half_y, 0.0};
      g = std::min(g, t.base(x + c.x, y + c.y));
    }
  }
  return g;
}

}  // namespace

Aabb visible_bounds(const std::vector<Primitive>& parts, double ground_z) {
  Aabb b;
  for (const Primitive& p : parts) b.add(bounds(p));
  b.min.z = std::max(b.min.z, ground_z);
  return b;
}

std::vector<Primitive> tractor_body() {
  std::vector<Primitive> body;
  auto box = [&](Vec3 lo, Vec3 hi, double refl) { body.push_back(with_reflectivity(make_box_minmax(lo, hi), refl)); };
  box({-0.75, -0.45, -0.70}, {0.30, 0.45, -0.30}, 30.0);  // front weights and the sensor bracket below it
  box({-2.90, -0.50, -0.50}, {-0.60, 0.50, 0.45}, 70.0);  // hood
  box({-4.60, -0.95, -0.20}, {-2.90, 0.95, 1.50}, 60.0);  // cab
  for (const double s : {-1.0, 1.0}) {
    body.push_back(with_reflectivity(make_lying_cylinder({-1.5, 0.92 * s, -0.45}, 0.50, 0.20, kPi / 2.0), 8.0));
    body.push_back(with_reflectivity(make_lying_cylinder({-4.1, 1.25 * s, -0.10}, 0.85, 0.25, kPi / 2.0), 8.0));
    box({-4.95, s > 0 ? 1.0 : -1.5, 0.75}, {-3.25, s > 0 ? 1.5 : -1.0, 0.85}, 70.0);  // fender
  }
  body.push_back(with_reflectivity(make_vertical_cylinder({-2.7, 0.35, 0.45}, 0.06, 1.0), 20.0));  // exhaust
  return body;
}

SceneObject make_implement(const std::string& id, double x, double y, double yaw, const Terrain& t) {
  const Vec3 o{x, y, lowest_ground(t, x, y, 1.5, 1.25, yaw)};
  std::vector<Primitive> parts;
  auto add = [&](Primitive p, double refl) { parts.push_back(place(with_reflectivity(p, refl), o, yaw)); };
  add(make_box({0.2, 0.0, 0.65}, {1.1, 1.25, 0.10}), 90.0);     // frame, 0.55..0.75 m
  add(make_box({-0.2, 0.0, 1.125}, {0.6, 1.2, 0.375}), 110.0);  // hopper, up to 1.5 m
  add(make_box({1.7, 0.0, 0.55}, {0.4, 0.08, 0.06}), 90.0);     // drawbar
  add(make_box({2.0, 0.0, 0.25}, {0.05, 0.05, 0.25}), 90.0);    // parking stand
  for (const double s : {-1.0, 1.0}) add(make_lying_cylinder({-0.6, 1.0 * s, 0.35}, 0.35, 0.12, kPi / 2.0), 8.0);
  for (int k = 0; k < 6; ++k) add(make_box({0.9, -1.0 + 0.4 * k, 0.33}, {0.03, 0.02, 0.22}), 60.0);  // tines
  return finish(id, ObjectClass::Implement, std::move(parts));
}

SceneObject make_round_bale(const std::string& id, double x, double y, double yaw, const Terrain& t) {
  const double g = lowest_ground(t, x, y, 0.6, 0.75, yaw);
  std::vector<Primitive> parts{with_reflectivity(make_lying_cylinder({x, y, g + 0.75}, 0.75, 0.6, yaw), 55.0)};
  return finish(id, ObjectClass::Haystack, std::move(parts));
}

SceneObject make_bale_stack(const std::string& id, double x, double y, double yaw, const Terrain& t) {
  const Vec3 o{x, y, lowest_ground(t, x, y, 0.6, 2.25, yaw)};
  std::vector<Primitive> parts;
  const double top_z = 0.75 + 1.5 * std::sin(kPi / 3.0);
  for (const double ly : {-1.5, 0.0, 1.5}) {
    parts.push_back(place(with_reflectivity(make_lying_cylinder({0.0, ly, 0.75}, 0.75, 0.6, 0.0), 55.0), o, yaw));
  }
  for (const double ly : {-0.75, 0.75}) {
    parts.push_back(place(with_reflectivity(make_lying_cylinder({0.0, ly, top_z}, 0.75, 0.6, 0.0), 55.0), o, yaw));
  }
  return finish(id, ObjectClass::Haystack, std::move(parts));
}

SceneObject make_standing_person(const std::string& id, double x, double y, double heading, const Terrain& t) {
  return finish(id, ObjectClass::Pedestrian, person_parts({x, y, t.base(x, y)}, heading, 0.6));
}

SceneObject make_house(const std::string& id, double x, double y, double yaw, const Terrain& t) {
  const Vec3 o{x, y, lowest_ground(t, x, y, 4.0, 3.0, yaw)};
  std::vector<Primitive> parts;
  auto add = [&](Vec3 c, Vec3 h, double refl) {
    parts.push_back(place(with_reflectivity(make_box(c, h), refl), o, yaw));
  };
  add({0.0, 0.0, 1.2}, {4.0, 3.0, 1.2}, 120.0);  // plastered walls
  add({0.0, 0.0, 2.5}, {4.2, 3.2, 0.1}, 40.0);   // roof, stepped towards the ridge
  add({0.0, 0.0, 2.7}, {4.2, 2.0, 0.1}, 40.0);
  add({0.0, 0.0, 2.9}, {4.2, 1.0, 0.1}, 40.0);
  return finish(id, ObjectClass::House, std::move(parts));
}

SceneObject make_roadside_tree(const std::string& id, double x, double y, const Terrain& t, Rng& rng) {
  const double g = t.base(x, y);
  const double trunk_r = rng.uniform(0.15, 0.25);
  const double crown_base = rng.uniform(1.8, 2.6);
  const double a = rng.uniform(1.5, 2.5);
  const double b = a * rng.uniform(0.85, 1.0);
  const double c = rng.uniform(1.5, 2.2);
  const double yaw = rng.uniform(0.0, kPi);
  std::vector<Primitive> parts;
  parts.push_back(with_reflectivity(make_vertical_cylinder({x, y, g - 0.1}, trunk_r, crown_base + c + 0.1), 35.0));
  parts.push_back(with_reflectivity(make_ellipsoid({x, y, g + crown_base + c}, {a, b, c}, yaw), 50.0, 0.5));
  return finish(id, ObjectClass::Tree, std::move(parts));
}

SceneObject make_orchard_tree(const std::string& id, double x, double y, Vec3 semi_axes, double crown_base_m,
                              const Terrain& t, Rng& rng) {
  const double g = t.base(x, y);
  const double trunk_r = rng.uniform(0.06, 0.10);
  const double cz = g + crown_base_m + semi_axes.z;
  std::vector<Primitive> parts;
  parts.push_back(with_reflectivity(
      make_vertical_cylinder({x, y, g - 0.1}, trunk_r, crown_base_m + 0.5 * semi_axes.z + 0.1), 35.0));
  parts.push_back(with_reflectivity(make_ellipsoid({x, y, cz}, semi_axes), 55.0, 0.45));
  return finish(id, ObjectClass::Crown, std::move(parts));
}

SceneObject make_clod(const std::string& id, double x, double y, double height_m, const Terrain& t, Rng& rng) {
  const double g = t.height(x, y);
  const double a = std::max(0.06, height_m * rng.uniform(0.8, 1.4));
  const double b = a * rng.uniform(0.6, 1.0);
  const double c = height_m * rng.uniform(1.2, 1.6);
  const double yaw = rng.uniform(0.0, kPi);
  const double refl = rng.uniform(15.0, 35.0);
  std::vector<Primitive> parts{with_reflectivity(make_ellipsoid({x, y, g + height_m - c}, {a, b, c}, yaw), refl)};
  SceneObject o = finish(id, ObjectClass::Clod, std::move(parts));
  o.bounds = visible_bounds(o.parts, g - t.furrow_bound());
  return o;
}

std::vector<SceneObject> make_ridge(const std::string& id_prefix, double x0, double y0, double x1, double y1,
                                    double height_m, double width_m, const Terrain& t) {
  const double radius = (width_m * width_m / 4.0 + height_m * height_m) / (2.0 * height_m);
  const double length = std::hypot(x1 - x0, y1 - y0);
  const int n = std::max(1, static_cast<int>(std::ceil(length / 4.0)));
  std::vector<SceneObject> out;
  auto node = [&](int k) {
    const double f = static_cast<double>(k) / n;
    const double x = x0 + (x1 - x0) * f;
    const double y = y0 + (y1 - y0) * f;
    return Vec3{x, y, t.base(x, y) + height_m - radius};
  };
  for (int k = 0; k < n; ++k) {
    const Vec3 a = node(k);
    const Vec3 b = node(k + 1);
    Primitive cap = with_reflectivity(make_capsule(a, b, radius), 28.0);
    const double ground = std::min(a.z, b.z) + radius - height_m - t.furrow_bound();
    SceneObject o = finish(id_prefix + "-" + std::to_string(k), ObjectClass::Ridge, {cap});
    o.bounds = visible_bounds(o.parts, ground);
    out.push_back(std::move(o));
  }
  return out;
}

}  // namespace fieldguard::sim
