#pragma once
// The boxes of an obstacle: the minimum-area rectangle of a footprint (2D convex hull, then every hull edge
// as a side: the minimum-area enclosing rectangle has a side on the hull, Freeman & Shapira 1975), and the
// size class.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "fieldguard/perception/obstacle.hpp"

namespace fieldguard::perception {

// Person-sized: fits in kSmallFootprint_m x kSmallFootprint_m x kSmallHeight_m.
inline constexpr float kSmallFootprint_m = 1.2F;
inline constexpr float kSmallHeight_m = 2.2F;

struct OrientedRect {
  std::array<float, 2> center{};  // m
  float length_m = 0.F;           // the longer side, along yaw
  float width_m = 0.F;
  float yaw_rad = 0.F;  // of the length axis from x, counter-clockwise, in (-pi/2, pi/2]
};

// Working space of convex_hull() and min_area_rect(), reused across calls.
struct HullScratch {
  std::vector<std::array<float, 2>> points;
  std::vector<std::uint64_t> keys, keys_tmp;
  std::vector<std::uint32_t> counts;
  std::vector<float> marks;  // the hull pre-filter's running extremes, block by block
};

// Convex hull of `pts` counter-clockwise without collinear points, from the lowest-leftmost point (Andrew's
// monotone chain; of over 64 points, those inside the Akl-Toussaint octagon of the extremes along the axes and
// diagonals, then inside that octagon refined by the farthest point beyond each edge, left out first (which
// points are left out cannot change the hull); large sets sorted by radix).
void convex_hull(std::span<const std::array<float, 2>> pts, std::vector<std::array<float, 2>>& hull,
                 HullScratch& scratch);

// Minimum-area rectangle around `pts`; `hull` and `scratch` are working space. One point: a rectangle of size
// zero at it; collinear points: width zero. Among rectangles within 1 % of the least area, the one whose sides
// carry the most points (two faces seen at a corner make a right-triangle hull, whose leg- and
// hypotenuse-aligned rectangles have the same area); remaining ties keep the first hull edge (deterministic).
// Points no such rectangle can leave uncounted (most of a footprint: they lie on its faces) are counted once for
// all of them.
[[nodiscard]] OrientedRect min_area_rect(std::span<const std::array<float, 2>> pts,
                                         std::vector<std::array<float, 2>>& hull, HullScratch& scratch);

[[nodiscard]] SizeClass size_class(float length_m, float width_m, float height_m);

}  // namespace fieldguard::perception
