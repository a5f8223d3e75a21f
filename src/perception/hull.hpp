#pragma once
// Private to the footprint boxes: what the convex hull (convex_hull.cpp), its pre-filter (hull_prefilter.cpp) and
// the minimum-area rectangle (obstacle_box.cpp) share.

#include <array>
#include <span>
#include <vector>

#include "fieldguard/perception/obstacle_box.hpp"

namespace fieldguard::perception::hull_detail {

using P2 = std::array<float, 2>;

inline double d(float v) { return static_cast<double>(v); }

// Beyond this coordinate magnitude the octagon pre-filter and the shared count of points on the sides are not
// used: their float tests could overflow (a footprint never comes near it).
constexpr float kFilterReach = 1e18F;

// What drop_interior() saw of the points: all finite and within kFilterReach (else drop_interior_16() filtered
// them), and the largest coordinate magnitude.
struct Seen {
  bool tame = false;
  float reach = 0.F;
};

// Leaves out of `all` the points that cannot be hull vertices, into `kept` (hull_prefilter.cpp).
Seen drop_interior(std::span<const P2> all, std::vector<P2>& kept, std::vector<float>& marks);

// convex_hull(), telling what the pre-filter saw (convex_hull.cpp).
Seen hull_of(std::span<const P2> all, std::vector<P2>& hull, HullScratch& hs);

}  // namespace fieldguard::perception::hull_detail
