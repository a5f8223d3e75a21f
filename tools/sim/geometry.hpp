#pragma once
// Small double-precision vector, rotation and box types of the scene simulator.
// World frame: x forward along the tractor's path, y left, z up, metres; origin on the ground where the
// tractor starts. Sensor frame: REP-103 (x forward, y left, z up) at the LiDAR's optical centre.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace fieldguard::sim {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kInf = std::numeric_limits<double>::infinity();

struct Vec3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

[[nodiscard]] inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
[[nodiscard]] inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
[[nodiscard]] inline Vec3 operator*(Vec3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
[[nodiscard]] inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
[[nodiscard]] inline double norm(Vec3 a) { return std::sqrt(dot(a, a)); }
[[nodiscard]] inline Vec3 normalized(Vec3 a) {
  const double n = norm(a);
  return n > 0.0 ? a * (1.0 / n) : a;
}

// Row-major 3x3 matrix; used for rotations only (transpose = inverse).
struct Mat3 {
  std::array<double, 9> m{1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};

  [[nodiscard]] Vec3 operator*(Vec3 v) const {
    return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
            m[6] * v.x + m[7] * v.y + m[8] * v.z};
  }
  [[nodiscard]] Mat3 operator*(const Mat3& o) const {
    Mat3 r;
    for (std::size_t i = 0; i < 3; ++i) {
      for (std::size_t j = 0; j < 3; ++j) {
        r.m[i * 3 + j] = m[i * 3] * o.m[j] + m[i * 3 + 1] * o.m[3 + j] + m[i * 3 + 2] * o.m[6 + j];
      }
    }
    return r;
  }
  [[nodiscard]] Mat3 transposed() const { return {{m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8]}}; }
  // Multiplies by the transpose (the inverse rotation) without forming it.
  [[nodiscard]] Vec3 transpose_times(Vec3 v) const {
    return {m[0] * v.x + m[3] * v.y + m[6] * v.z, m[1] * v.x + m[4] * v.y + m[7] * v.z,
            m[2] * v.x + m[5] * v.y + m[8] * v.z};
  }
};

// Right-handed rotations about the axes (angles in radians).
[[nodiscard]] inline Mat3 rot_x(double a) {
  const double c = std::cos(a);
  const double s = std::sin(a);
  return {{1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c}};
}
[[nodiscard]] inline Mat3 rot_y(double a) {
  const double c = std::cos(a);
  const double s = std::sin(a);
  return {{c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c}};
}
[[nodiscard]] inline Mat3 rot_z(double a) {
  const double c = std::cos(a);
  const double s = std::sin(a);
  return {{c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0}};
}
// Vehicle attitude as in fieldguard::Mounting: R = Rz(yaw) Ry(pitch) Rx(roll); sensor -> world.
[[nodiscard]] inline Mat3 attitude(double roll_rad, double pitch_rad, double yaw_rad = 0.0) {
  return rot_z(yaw_rad) * rot_y(pitch_rad) * rot_x(roll_rad);
}

struct Ray {
  Vec3 origin;
  Vec3 dir;  // unit length, so t is the range in metres
};

// Axis-aligned box; empty (min > max) until something is added.
struct Aabb {
  Vec3 min{kInf, kInf, kInf};
  Vec3 max{-kInf, -kInf, -kInf};

  void add(Vec3 p) {
    min = {std::min(min.x, p.x), std::min(min.y, p.y), std::min(min.z, p.z)};
    max = {std::max(max.x, p.x), std::max(max.y, p.y), std::max(max.z, p.z)};
  }
  void add(const Aabb& b) {
    if (b.empty()) return;
    add(b.min);
    add(b.max);
  }
  [[nodiscard]] bool empty() const { return min.x > max.x; }
  [[nodiscard]] Vec3 center() const { return (min + max) * 0.5; }
  [[nodiscard]] Vec3 corner(int i) const {
    return {(i & 1) != 0 ? max.x : min.x, (i & 2) != 0 ? max.y : min.y, (i & 4) != 0 ? max.z : min.z};
  }
};

// Axis-aligned bounds of box `b` after the affine map p -> rot * (p - offset).
[[nodiscard]] inline Aabb transform_box(const Aabb& b, const Mat3& rot, Vec3 offset) {
  Aabb out;
  if (b.empty()) return out;
  for (int i = 0; i < 8; ++i) out.add(rot * (b.corner(i) - offset));
  return out;
}

// Slab test. `inv` = 1/dir per component (may be infinite). Entry distance in [0, tmax) or false.
[[nodiscard]] inline bool ray_hits_aabb(const Ray& ray, Vec3 inv, const Aabb& b, double tmax, double& t_entry) {
  double t0 = 0.0;
  double t1 = tmax;
  const std::array<double, 3> o{ray.origin.x, ray.origin.y, ray.origin.z};
  const std::array<double, 3> iv{inv.x, inv.y, inv.z};
  const std::array<double, 3> lo{b.min.x, b.min.y, b.min.z};
  const std::array<double, 3> hi{b.max.x, b.max.y, b.max.z};
  for (std::size_t a = 0; a < 3; ++a) {
    double tn = (lo[a] - o[a]) * iv[a];
    double tf = (hi[a] - o[a]) * iv[a];
    if (std::isnan(tn) || std::isnan(tf)) {  // parallel to the slab and on its plane: inside iff within
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    if (tn > tf) std::swap(tn, tf);
    t0 = std::max(t0, tn);
    t1 = std::min(t1, tf);
    if (t0 > t1) return false;
  }
  t_entry = t0;
  return true;
}

// Horizontal (x-y) distance from the origin to the nearest point of a box.
[[nodiscard]] inline double horizontal_distance(const Aabb& b) {
  const double dx = std::max({b.min.x, 0.0, -b.max.x});
  const double dy = std::max({b.min.y, 0.0, -b.max.y});
  return std::hypot(dx, dy);
}

}  // namespace fieldguard::sim
