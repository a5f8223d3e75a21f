#pragma once
// A synthetic HDL-32E rotation over a field, for the perception benchmarks and tests until the scene
// simulator (tools/) exists: 32 beams at the HDL-32E's vertical angles, one firing every 46.08 us, ray-cast
// against a height-field ground (slope, undulation, furrows, an optional ridge), boxes, vertical cylinders,
// spheres and an optional forest edge all round, with Gaussian range noise and dropouts from a fixed seed.
// Test scaffolding, header-only; not part of any library.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"

namespace fieldguard::sim {

// HDL-32E vertical angles (degrees), lowest beam first: ../shared/docs/protocols.md section 1.5 (the same in the
// ROS driver's 32db.yaml and VeloView's table), sorted by elevation, so the index is the ring.
inline constexpr std::array<double, 32> kHdl32eVerticalDeg = {
    -30.67, -29.33, -28.00, -26.67, -25.33, -24.00, -22.67, -21.33, -20.00, -18.67, -17.33,
    -16.00, -14.67, -13.33, -12.00, -10.67, -9.33,  -8.00,  -6.67,  -5.33,  -4.00,  -2.67,
    -1.33,  0.00,   1.33,   2.67,   4.00,   5.33,   6.67,   8.00,   9.33,   10.67};
inline constexpr double kHdl32eFiringPeriodS = 46.08e-6;  // one firing sequence of all 32 lasers

// Ground height (m) in the field frame: x forward, y left, z up, the sensor above (0, 0).
struct Terrain {
  double slope_x = 0.0;       // rise per metre forward
  double slope_y = 0.0;       // rise per metre to the left
  double undulation_m = 0.0;  // amplitude of gentle waves ...
  double undulation_wavelength_m = 25.0;
  double furrow_m = 0.0;  // amplitude of furrows running along x ...
  double furrow_period_m = 0.75;
  // A field ridge across the direction of travel: a raised cos^2 bump centred at x = ridge_x_m.
  double ridge_x_m = 0.0;
  double ridge_width_m = 0.0;  // 0 = no ridge
  double ridge_height_m = 0.0;

  [[nodiscard]] double z(double x, double y) const {
    double h = slope_x * x + slope_y * y;
    if (undulation_m != 0.0) {
      const double k = 2.0 * std::numbers::pi / undulation_wavelength_m;
      h += undulation_m * std::sin(k * x + 0.3) * std::cos(0.7 * k * y);
    }
    if (furrow_m != 0.0) h += furrow_m * std::sin(2.0 * std::numbers::pi * y / furrow_period_m);
    if (ridge_width_m > 0.0) {
      const double u = (x - ridge_x_m) / ridge_width_m;
      if (std::fabs(u) < 0.5) {
        const double c = std::cos(std::numbers::pi * u);
        h += ridge_height_m * c * c;
      }
    }
    return h;
  }
  // Upper bound of |z - (slope_x x + slope_y y)|, for the ray march.
  [[nodiscard]] double relief() const {
    return std::fabs(undulation_m) + std::fabs(furrow_m) + std::fabs(ridge_height_m);
  }
};

// Obstacles stand on the terrain: their z is above the terrain height at their centre (base_on_ground).
struct Box {
  std::array<double, 3> center{};  // base centre when base_on_ground
  std::array<double, 3> size{};    // length (along yaw), width, height
  double yaw_rad = 0.0;
};
struct Cylinder {  // vertical
  double x = 0.0, y = 0.0, radius = 0.25, height = 1.75;
  double base_z = 0.0;  // above the terrain at (x, y)
};
struct Sphere {
  double x = 0.0, y = 0.0, z = 0.0;  // centre height above the terrain at (x, y)
  double radius = 1.0;
};

struct Scene {
  Terrain terrain;
  std::vector<Box> boxes;
  std::vector<Cylinder> cylinders;
  std::vector<Sphere> spheres;
  double sensor_height_m = 0.95;
  double roll_deg = 0.0;   // of the sensor (the vehicle) about x, + right side down ... (REP-103 roll)
  double pitch_deg = 0.0;  // about y, + nose down
  // A forest edge all round at a horizontal distance varying with azimuth (0 = none).
  double forest_distance_m = 0.0;
  double forest_height_m = 18.0;
};

struct ScanSpec {
  double rotation_hz = 10.0;    // 10 Hz: ~2170 firings, ~69,000 points; 5 Hz: ~138,900
  double range_noise_m = 0.01;  // standard deviation
  double dropout = 0.01;        // probability that a return is missing
  double max_range_m = 100.0;
  std::uint64_t seed = 1;
};

namespace detail {

struct Rng {
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31U);
  }
  double uniform() { return static_cast<double>(next() >> 11U) * 0x1.0p-53; }
  double gauss() {
    const double u = std::max(uniform(), 1e-300), v = uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * std::numbers::pi * v);
  }
};

using V3 = std::array<double, 3>;

inline std::optional<double> hit_box(const V3& o, const V3& d, const Box& b, double base) {
  const double c = std::cos(b.yaw_rad), s = std::sin(b.yaw_rad);
  // Into the box frame (centre at the origin, axes along its sides).
  const V3 rel{o[0] - b.center[0], o[1] - b.center[1], o[2] - (base + b.size[2] / 2.0)};
  const V3 lo{c * rel[0] + s * rel[1], -s * rel[0] + c * rel[1], rel[2]};
  const V3 ld{c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]};
  double t0 = 0.0, t1 = 1e30;
  for (int a = 0; a < 3; ++a) {
    const double h = b.size[static_cast<std::size_t>(a)] / 2.0;
    const auto i = static_cast<std::size_t>(a);
    if (std::fabs(ld[i]) < 1e-12) {
      if (std::fabs(lo[i]) > h) return std::nullopt;
      continue;
    }
    double ta = (-h - lo[i]) / ld[i], tb = (h - lo[i]) / ld[i];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return std::nullopt;
  }
  return t0 > 1e-6 ? std::optional<double>(t0) : std::nullopt;
}

inline std::optional<double> hit_cylinder(const V3& o, const V3& d, const Cylinder& c, double z0) {
  const double ox = o[0] - c.x, oy = o[1] - c.y;
  const double a = d[0] * d[0] + d[1] * d[1];
  if (a < 1e-12) return std::nullopt;
  const double b = ox * d[0] + oy * d[1];
  const double cc = ox * ox + oy * oy - c.radius * c.radius;
  const double disc = b * b - a * cc;
  if (disc < 0.0) return std::nullopt;
  const double t = (-b - std::sqrt(disc)) / a;
  if (t <= 1e-6) return std::nullopt;
  const double z = o[2] + t * d[2];
  if (z < z0 || z > z0 + c.height) return std::nullopt;
  return t;
}

inline std::optional<double> hit_sphere(const V3& o, const V3& d, const V3& c, double r) {
  const V3 oc{o[0] - c[0], o[1] - c[1], o[2] - c[2]};
  const double b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
  const double cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r;
  const double disc = b * b - cc;
  if (disc < 0.0) return std::nullopt;
  const double t = -b - std::sqrt(disc);
  return t > 1e-6 ? std::optional<double>(t) : std::nullopt;
}

// First crossing of the terrain along the ray, by marching and bisection.
inline std::optional<double> hit_terrain(const V3& o, const V3& d, const Terrain& g, double t_max) {
  const double relief = g.relief() + 1e-3;
  const auto above = [&](double t) { return o[2] + t * d[2] - g.z(o[0] + t * d[0], o[1] + t * d[1]); };
  double t = 0.3, prev = above(t);
  if (prev <= 0.0) return std::nullopt;
  while (t < t_max) {
    // No hit while the ray is above the highest the ground can be: skip in larger steps there.
    const double plane = g.slope_x * (o[0] + t * d[0]) + g.slope_y * (o[1] + t * d[1]);
    const double clearance = o[2] + t * d[2] - plane - relief;
    const double slope_rate = d[2] - g.slope_x * d[0] - g.slope_y * d[1];
    if (clearance > 0.0 && slope_rate >= 0.0) return std::nullopt;
    const double step = std::clamp(0.01 * t, 0.02, 0.25);
    const double tn = t + step;
    const double cur = above(tn);
    if (cur <= 0.0) {
      double lo = t, hi = tn;
      for (int i = 0; i < 30; ++i) {
        const double mid = 0.5 * (lo + hi);
        (above(mid) > 0.0 ? lo : hi) = mid;
      }
      return 0.5 * (lo + hi);
    }
    t = tn;
    prev = cur;
  }
  (void)prev;
  return std::nullopt;
}

}  // namespace detail

// One full rotation, points in the sensor frame (REP-103), firing order, as a decoder would give them.
inline std::vector<LidarPoint> scan(const Scene& scene, const ScanSpec& spec) {
  using detail::V3;
  detail::Rng rng{spec.seed * 0x2545F4914F6CDD1DULL + 17};
  const double cr = std::cos(scene.roll_deg * std::numbers::pi / 180.0);
  const double sr = std::sin(scene.roll_deg * std::numbers::pi / 180.0);
  const double cp = std::cos(scene.pitch_deg * std::numbers::pi / 180.0);
  const double sp = std::sin(scene.pitch_deg * std::numbers::pi / 180.0);
  // Sensor to field: R = Ry(pitch) Rx(roll).
  const auto to_field = [&](const V3& v) {
    const V3 a{v[0], cr * v[1] - sr * v[2], sr * v[1] + cr * v[2]};
    return V3{cp * a[0] + sp * a[2], a[1], -sp * a[0] + cp * a[2]};
  };
  const auto to_sensor = [&](const V3& v) {
    const V3 a{cp * v[0] - sp * v[2], v[1], sp * v[0] + cp * v[2]};
    return V3{a[0], cr * a[1] + sr * a[2], -sr * a[1] + cr * a[2]};
  };
  const V3 origin{0.0, 0.0, scene.terrain.z(0.0, 0.0) + scene.sensor_height_m};
  const auto firings = static_cast<int>(std::lround(1.0 / (spec.rotation_hz * kHdl32eFiringPeriodS)));
  std::vector<LidarPoint> out;
  out.reserve(static_cast<std::size_t>(firings) * 32);
  for (int f = 0; f < firings; ++f) {
    const double az_deg = 360.0 * static_cast<double>(f) / static_cast<double>(firings);
    const double az = az_deg * std::numbers::pi / 180.0;
    for (std::size_t ring = 0; ring < 32; ++ring) {
      // Firing order alternates lower and upper half (protocols.md 1.5); only the time depends on it.
      const double w = kHdl32eVerticalDeg[ring] * std::numbers::pi / 180.0;
      const V3 ds{std::cos(w) * std::cos(az), -std::cos(w) * std::sin(az), std::sin(w)};
      const V3 d = to_field(ds);
      double best = spec.max_range_m;
      bool hit = false;
      const auto take = [&](std::optional<double> t) {
        if (t && *t < best) {
          best = *t;
          hit = true;
        }
      };
      for (const auto& b : scene.boxes)
        take(detail::hit_box(origin, d, b, scene.terrain.z(b.center[0], b.center[1]) + b.center[2]));
      for (const auto& c : scene.cylinders)
        take(detail::hit_cylinder(origin, d, c, scene.terrain.z(c.x, c.y) + c.base_z));
      for (const auto& s : scene.spheres) {
        take(detail::hit_sphere(origin, d, V3{s.x, s.y, scene.terrain.z(s.x, s.y) + s.z}, s.radius));
      }
      if (scene.forest_distance_m > 0.0) {
        const double horiz = std::hypot(d[0], d[1]);
        const double theta = std::atan2(d[1], d[0]);
        const double r =
            scene.forest_distance_m * (1.0 + 0.25 * std::sin(3.0 * theta) + 0.1 * std::sin(7.0 * theta + 1.0));
        if (horiz > 1e-9) {
          const double t = r / horiz;
          const double z = origin[2] + t * d[2] - scene.terrain.z(origin[0] + t * d[0], origin[1] + t * d[1]);
          if (z >= 0.0 && z <= scene.forest_height_m * (1.0 + 0.2 * std::sin(11.0 * theta))) take(t);
        }
      }
      take(detail::hit_terrain(origin, d, scene.terrain, std::min(best, spec.max_range_m)));
      const double drop = rng.uniform();
      const double noise = rng.gauss() * spec.range_noise_m;
      if (!hit || drop < spec.dropout) continue;
      const double t = best + noise;
      const V3 p = to_sensor(V3{t * d[0], t * d[1], t * d[2]});
      LidarPoint lp;
      lp.x = static_cast<float>(p[0]);
      lp.y = static_cast<float>(p[1]);
      lp.z = static_cast<float>(p[2]);
      lp.range_m = static_cast<float>(t);
      lp.intensity = 40.F;
      lp.time_s =
          static_cast<float>(static_cast<double>(f) * kHdl32eFiringPeriodS + static_cast<double>(ring) * 1.152e-6);
      lp.azimuth_cdeg = static_cast<std::uint16_t>(std::lround(az_deg * 100.0) % 36000);
      lp.ring = static_cast<std::uint16_t>(ring);
      out.push_back(lp);
    }
  }
  return out;
}

// A person (vertical cylinder, 0.25 m radius: side-on width 0.5 m) of the given height at (x, y).
inline Cylinder person(double x, double y, double height = 1.75) { return Cylinder{x, y, 0.25, height, 0.0}; }

// The benchmark field: gently undulating, furrowed, a ridge, a forest edge all round (so that every beam
// returns, as in a bordered field), pedestrians at 5 to 30 m, an implement, a haystack, a house, roadside trees
// and orchard crowns, clods.
inline Scene benchmark_scene() {
  Scene s;
  s.terrain.undulation_m = 0.15;
  s.terrain.undulation_wavelength_m = 30.0;
  s.terrain.furrow_m = 0.04;
  s.terrain.slope_x = 0.02;
  s.terrain.ridge_x_m = 23.0;
  s.terrain.ridge_width_m = 1.2;
  s.terrain.ridge_height_m = 0.35;
  s.forest_distance_m = 60.0;
  for (int i = 1; i <= 6; ++i) s.cylinders.push_back(person(5.0 * i, (i % 2 == 0 ? 1.0 : -1.5)));
  s.boxes.push_back(Box{{16.0, 5.0, 0.0}, {4.0, 2.6, 1.4}, 0.4});   // parked implement
  s.boxes.push_back(Box{{32.0, -6.0, 0.0}, {2.4, 2.4, 2.0}, 0.0});  // haystack
  s.boxes.push_back(Box{{44.0, 7.0, 0.0}, {10.0, 7.0, 4.0}, 0.2});  // low farm house
  for (int i = 0; i < 8; ++i) {                                     // roadside trees along y = -9 m
    const double x = 4.0 + 6.0 * i;
    s.cylinders.push_back(Cylinder{x, -9.0, 0.15, 2.5, 0.0});
    s.spheres.push_back(Sphere{x, -9.0, 3.6, 1.4});
  }
  for (int i = 0; i < 6; ++i) {  // orchard crowns, some nearly touching
    s.spheres.push_back(Sphere{12.0 + 3.1 * i, 8.5, 1.8, 1.2 + 0.15 * (i % 3)});
  }
  detail::Rng rng{99};
  for (int i = 0; i < 40; ++i) {  // clods up to 0.3 m
    const double x = 2.0 + 40.0 * rng.uniform(), y = -8.0 + 16.0 * rng.uniform();
    const double h = 0.08 + 0.22 * rng.uniform();
    s.boxes.push_back(
        Box{{x, y, -0.05}, {0.3 + 0.3 * rng.uniform(), 0.3 + 0.2 * rng.uniform(), h + 0.05}, rng.uniform() * 3.0});
  }
  return s;
}

}  // namespace fieldguard::sim
