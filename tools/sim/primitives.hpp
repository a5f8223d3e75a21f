#pragma once
// Analytic ray intersection with the solids scenes are built of: boxes, capped cylinders, ellipsoids and
// capsules, each with its own position and orientation. A primitive is either solid (the ray stops at its
// surface) or porous (foliage, crops: the ray stops at an exponentially distributed depth inside it, or
// passes through).

#include <cstdint>

#include "sim/geometry.hpp"

namespace fieldguard::sim {

enum class Shape : std::uint8_t {
  Box,        // half_size = half extents along the local axes
  Cylinder,   // half_size.x = radius, half_size.z = half length along local z; capped
  Ellipsoid,  // half_size = semi-axes
  Capsule,    // half_size.x = radius, half_size.z = half length of the axis segment (local z)
};

struct Primitive {
  Shape shape = Shape::Box;
  Vec3 center;                    // world position of the local origin
  Mat3 rot;                       // local -> world
  Vec3 half_size;                 // see Shape
  double reflectivity = 40.0;     // nominal intensity at normal incidence, 0..255
  double mean_free_path_m = 0.0;  // 0 = solid; > 0 = porous with this mean penetration depth
};

// Where a ray enters and leaves a (convex) primitive, with the outward surface normal at entry (world).
struct Span {
  double t_in = 0.0;
  double t_out = 0.0;
  Vec3 normal;
};

// Entry and exit of the ray's line through the primitive, with t_out > 0 and t_in < tmax. A ray starting
// inside has t_in < 0. False if the ray misses.
[[nodiscard]] bool intersect(const Primitive& p, const Ray& ray, double tmax, Span& span);

// World-space bounds of the primitive.
[[nodiscard]] Aabb bounds(const Primitive& p);

// Builders. `yaw` turns the local x axis about world z (radians).
[[nodiscard]] Primitive make_box(Vec3 center, Vec3 half, double yaw = 0.0);
// A box given by its world min/max corners (axis-aligned).
[[nodiscard]] Primitive make_box_minmax(Vec3 min, Vec3 max);
[[nodiscard]] Primitive make_vertical_cylinder(Vec3 base, double radius, double height);
// A cylinder lying on its side: axis horizontal, at heading `yaw` (0 = along world x).
[[nodiscard]] Primitive make_lying_cylinder(Vec3 center, double radius, double half_length, double yaw);
[[nodiscard]] Primitive make_ellipsoid(Vec3 center, Vec3 semi_axes, double yaw = 0.0);
// Capsule between two world points.
[[nodiscard]] Primitive make_capsule(Vec3 a, Vec3 b, double radius);

}  // namespace fieldguard::sim
