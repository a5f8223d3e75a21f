#pragma once
// Private to the Euclidean clusterer (euclidean_cluster.cpp, euclidean_cluster_grid.cpp): the radii its k-d tree
// and grid paths both take, inlined into their hot loops.

#include <algorithm>

#include "fieldguard/perception/euclidean_cluster.hpp"

namespace fieldguard::perception {

// A radius that grows with range: `t` up close, `growth` per metre of range farther out, at most `cap`.
inline float grow(float t, float growth, float cap, float range_m) {
  return std::min(cap, std::max(t, growth * range_m));
}

// The adaptive and anisotropic radii at a 3D range, as every pair test takes them. A local copy of the
// clusterer's parameters because the hot loops need these inlined, which a member function is not in a
// position-independent build (it could be interposed).
struct EuclideanClusterer::RadiusModel {
  float t;        // the smallest radius
  float base_r2;  // its square as PCL rounds it
  float gv, cap_v, gh, cap_h;
  bool aniso;
  [[nodiscard]] float v(float range_m) const { return grow(t, gv, cap_v, range_m); }
  [[nodiscard]] float h(float range_m) const { return aniso ? grow(t, gh, cap_h, range_m) : v(range_m); }
  [[nodiscard]] float squared(float radius) const { return radius == t ? base_r2 : radius * radius; }
};

}  // namespace fieldguard::perception
