// Ray / primitive intersection in the primitive's local frame.
#include "sim/primitives.hpp"

#include <algorithm>
#include <cmath>

namespace fieldguard::sim {

namespace {

constexpr double kParallelEps = 1e-12;

struct LocalRay {
  Vec3 o;
  Vec3 d;
};

LocalRay to_local(const Primitive& p, const Ray& ray) {
  return {p.rot.transpose_times(ray.origin - p.center), p.rot.transpose_times(ray.dir)};
}

bool finish(const Primitive& p, double t_in, double t_out, Vec3 local_normal, double tmax, Span& span) {
  if (!(t_in <= t_out) || t_out <= 0.0 || t_in >= tmax) return false;
  span.t_in = t_in;
  span.t_out = t_out;
  span.normal = normalized(p.rot * local_normal);
  return true;
}

bool box_span(const Primitive& p, const LocalRay& r, double tmax, Span& span) {
  const std::array<double, 3> o{r.o.x, r.o.y, r.o.z};
  const std::array<double, 3> d{r.d.x, r.d.y, r.d.z};
  const std::array<double, 3> h{p.half_size.x, p.half_size.y, p.half_size.z};
  double t_in = -kInf;
  double t_out = kInf;
  std::size_t axis = 0;
  double sign = 1.0;
  for (std::size_t a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < kParallelEps) {
      if (std::abs(o[a]) > h[a]) return false;
      continue;
    }
    const double inv = 1.0 / d[a];
    double tn = (-h[a] - o[a]) * inv;
    double tf = (h[a] - o[a]) * inv;
    double s = -1.0;  // entering through the -h face when moving in +direction
    if (tn > tf) {
      std::swap(tn, tf);
      s = 1.0;
    }
    if (tn > t_in) {
      t_in = tn;
      axis = a;
      sign = s;
    }
    t_out = std::min(t_out, tf);
  }
  Vec3 n;
  (axis == 0 ? n.x : axis == 1 ? n.y : n.z) = sign;
  return finish(p, t_in, t_out, n, tmax, span);
}

// Capped cylinder of radius `radius` and half length `half` about local z, centred at local z = `zc`.
bool cylinder_span(const LocalRay& r, double radius, double half, double zc, double& t_in, double& t_out, Vec3& n) {
  const double oz = r.o.z - zc;
  double ts0 = -kInf;
  double ts1 = kInf;
  const double a = r.d.x * r.d.x + r.d.y * r.d.y;
  const double c = r.o.x * r.o.x + r.o.y * r.o.y - radius * radius;
  if (a < kParallelEps) {
    if (c > 0.0) return false;
  } else {
    const double bh = r.o.x * r.d.x + r.o.y * r.d.y;
    const double disc = bh * bh - a * c;
    if (disc < 0.0) return false;
    const double sq = std::sqrt(disc);
    ts0 = (-bh - sq) / a;
    ts1 = (-bh + sq) / a;
  }
  double tz0 = -kInf;
  double tz1 = kInf;
  if (std::abs(r.d.z) < kParallelEps) {
    if (std::abs(oz) > half) return false;
  } else {
    tz0 = (-half - oz) / r.d.z;
    tz1 = (half - oz) / r.d.z;
    if (tz0 > tz1) std::swap(tz0, tz1);
  }
  t_in = std::max(ts0, tz0);
  t_out = std::min(ts1, tz1);
  if (t_in > t_out) return false;
  if (ts0 >= tz0) {
    n = {r.o.x + t_in * r.d.x, r.o.y + t_in * r.d.y, 0.0};
  } else {
    n = {0.0, 0.0, r.d.z > 0.0 ? -1.0 : 1.0};
  }
  return true;
}

bool sphere_span(const LocalRay& r, Vec3 c, double radius, double& t_in, double& t_out, Vec3& n) {
  const Vec3 oc = r.o - c;
  const double a = dot(r.d, r.d);
  const double bh = dot(oc, r.d);
  const double disc = bh * bh - a * (dot(oc, oc) - radius * radius);
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc);
  t_in = (-bh - sq) / a;
  t_out = (-bh + sq) / a;
  n = oc + r.d * t_in;
  return true;
}

bool ellipsoid_span(const Primitive& p, const LocalRay& r, double tmax, Span& span) {
  const Vec3 s = p.half_size;
  const LocalRay q{{r.o.x / s.x, r.o.y / s.y, r.o.z / s.z}, {r.d.x / s.x, r.d.y / s.y, r.d.z / s.z}};
  double t_in = 0.0;
  double t_out = 0.0;
  Vec3 n;
  if (!sphere_span(q, {}, 1.0, t_in, t_out, n)) return false;
  const Vec3 hit = r.o + r.d * t_in;
  return finish(p, t_in, t_out, {hit.x / (s.x * s.x), hit.y / (s.y * s.y), hit.z / (s.z * s.z)}, tmax, span);
}

bool capsule_span(const Primitive& p, const LocalRay& r, double tmax, Span& span) {
  const double radius = p.half_size.x;
  const double half = p.half_size.z;
  double best_in = kInf;
  double best_out = -kInf;
  Vec3 best_n;
  auto take = [&](bool hit, double t0, double t1, Vec3 n) {
    if (!hit) return;
    if (t0 < best_in) {
      best_in = t0;
      best_n = n;
    }
    best_out = std::max(best_out, t1);
  };
  double t0 = 0.0;
  double t1 = 0.0;
  Vec3 n;
  bool hit = cylinder_span(r, radius, half, 0.0, t0, t1, n);
  take(hit, t0, t1, n);
  hit = sphere_span(r, {0.0, 0.0, -half}, radius, t0, t1, n);
  take(hit, t0, t1, n);
  hit = sphere_span(r, {0.0, 0.0, half}, radius, t0, t1, n);
  take(hit, t0, t1, n);
  if (best_in == kInf) return false;
  return finish(p, best_in, best_out, best_n, tmax, span);
}

}  // namespace

bool intersect(const Primitive& p, const Ray& ray, double tmax, Span& span) {
  const LocalRay r = to_local(p, ray);
  switch (p.shape) {
    case Shape::Box: return box_span(p, r, tmax, span);
    case Shape::Cylinder: {
      double t0 = 0.0;
      double t1 = 0.0;
      Vec3 n;
      if (!cylinder_span(r, p.half_size.x, p.half_size.z, 0.0, t0, t1, n)) return false;
      return finish(p, t0, t1, n, tmax, span);
    }
    case Shape::Ellipsoid: return ellipsoid_span(p, r, tmax, span);
    case Shape::Capsule: return capsule_span(p, r, tmax, span);
  }
  return false;
}

Aabb bounds(const Primitive& p) {
  const auto& m = p.rot.m;
  std::array<double, 3> ext{};
  const Vec3 h = p.half_size;
  for (std::size_t i = 0; i < 3; ++i) {
    const double r0 = m[i * 3];
    const double r1 = m[i * 3 + 1];
    const double r2 = m[i * 3 + 2];
    switch (p.shape) {
      case Shape::Box: ext[i] = std::abs(r0) * h.x + std::abs(r1) * h.y + std::abs(r2) * h.z; break;
      case Shape::Ellipsoid: ext[i] = std::sqrt(r0 * r0 * h.x * h.x + r1 * r1 * h.y * h.y + r2 * r2 * h.z * h.z); break;
      case Shape::Cylinder: ext[i] = h.x * std::sqrt(std::max(0.0, 1.0 - r2 * r2)) + std::abs(r2) * h.z; break;
      case Shape::Capsule: ext[i] = h.x + std::abs(r2) * h.z; break;
    }
  }
  Aabb b;
  b.add(p.center - Vec3{ext[0], ext[1], ext[2]});
  b.add(p.center + Vec3{ext[0], ext[1], ext[2]});
  return b;
}

Primitive make_box(Vec3 center, Vec3 half, double yaw) {
  Primitive p;
  p.shape = Shape::Box;
  p.center = center;
  p.rot = rot_z(yaw);
  p.half_size = half;
  return p;
}

Primitive make_box_minmax(Vec3 min, Vec3 max) { return make_box((min + max) * 0.5, (max - min) * 0.5); }

Primitive make_vertical_cylinder(Vec3 base, double radius, double height) {
  Primitive p;
  p.shape = Shape::Cylinder;
  p.center = base + Vec3{0.0, 0.0, height * 0.5};
  p.half_size = {radius, radius, height * 0.5};
  return p;
}

Primitive make_lying_cylinder(Vec3 center, double radius, double half_length, double yaw) {
  Primitive p;
  p.shape = Shape::Cylinder;
  p.center = center;
  p.rot = rot_z(yaw) * rot_y(kPi / 2.0);  // local z -> world x, then turned by yaw
  p.half_size = {radius, radius, half_length};
  return p;
}

Primitive make_ellipsoid(Vec3 center, Vec3 semi_axes, double yaw) {
  Primitive p;
  p.shape = Shape::Ellipsoid;
  p.center = center;
  p.rot = rot_z(yaw);
  p.half_size = semi_axes;
  return p;
}

Primitive make_capsule(Vec3 a, Vec3 b, double radius) {
  Primitive p;
  p.shape = Shape::Capsule;
  p.center = (a + b) * 0.5;
  const Vec3 axis = b - a;
  const double len = norm(axis);
  // Rotation taking local z onto the axis: yaw about z, then tilt from vertical.
  const double yaw = std::atan2(axis.y, axis.x);
  const double tilt = len > 0.0 ? std::acos(std::clamp(axis.z / len, -1.0, 1.0)) : 0.0;
  p.rot = rot_z(yaw) * rot_y(tilt);
  p.half_size = {radius, radius, len * 0.5};
  return p;
}

}  // namespace fieldguard::sim
