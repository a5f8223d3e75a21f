#include "fieldguard/perception/obstacle_box.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace fieldguard::perception {
namespace {

using P2 = std::array<float, 2>;

double d(float v) { return static_cast<double>(v); }

double cross(const P2& o, const P2& a, const P2& b) {
  return (d(a[0]) - d(o[0])) * (d(b[1]) - d(o[1])) - (d(a[1]) - d(o[1])) * (d(b[0]) - d(o[0]));
}

}  // namespace

std::string_view to_string(SizeClass c) { return c == SizeClass::Small ? "small" : "large"; }

void convex_hull(std::span<const P2> all, std::vector<P2>& hull, std::vector<P2>& scratch) {
  hull.clear();
  scratch.assign(all.begin(), all.end());
  std::span<P2> pts(scratch);
  const std::size_t n = pts.size();
  std::sort(pts.begin(), pts.end());
  if (n <= 1) {
    hull.assign(pts.begin(), pts.end());
    return;
  }
  hull.resize(2 * n);
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {  // lower hull
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0.0) --k;
    hull[k++] = pts[i];
  }
  for (std::size_t i = n - 1, t = k + 1; i > 0; --i) {  // upper hull
    while (k >= t && cross(hull[k - 2], hull[k - 1], pts[i - 1]) <= 0.0) --k;
    hull[k++] = pts[i - 1];
  }
  hull.resize(k - 1);  // the last point is the first
  if (hull.size() == 2 && hull[0] == hull[1]) hull.resize(1);
}

OrientedRect min_area_rect(std::span<const P2> pts, std::vector<P2>& hull, std::vector<P2>& scratch) {
  OrientedRect r;
  if (pts.empty()) return r;
  convex_hull(pts, hull, scratch);
  const std::size_t h = hull.size();
  if (h == 1) {
    r.center = hull[0];
    return r;
  }
  struct Candidate {
    double ux, uy, u0, u1, v0, v1, area;
  };
  // Every hull edge as a side (a segment: its own direction only).
  std::array<Candidate, 64> small{};
  std::vector<Candidate> large;
  const std::size_t edges = h == 2 ? 1 : h;
  Candidate* cand = small.data();
  if (edges > small.size()) {
    large.resize(edges);
    cand = large.data();
  }
  std::size_t count = 0;
  double best_area = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < edges; ++i) {
    const P2& a = hull[i];
    const P2& b = hull[(i + 1) % h];
    double ux = d(b[0]) - d(a[0]), uy = d(b[1]) - d(a[1]);
    const double len = std::sqrt(ux * ux + uy * uy);
    if (len <= 0.0) continue;
    ux /= len;
    uy /= len;
    Candidate c{ux,
                uy,
                std::numeric_limits<double>::max(),
                -std::numeric_limits<double>::max(),
                std::numeric_limits<double>::max(),
                -std::numeric_limits<double>::max(),
                0.0};
    for (const P2& p : hull) {
      const double u = d(p[0]) * ux + d(p[1]) * uy;
      const double v = -d(p[0]) * uy + d(p[1]) * ux;
      c.u0 = std::min(c.u0, u);
      c.u1 = std::max(c.u1, u);
      c.v0 = std::min(c.v0, v);
      c.v1 = std::max(c.v1, v);
    }
    c.area = (c.u1 - c.u0) * (c.v1 - c.v0);
    best_area = std::min(best_area, c.area);
    cand[count++] = c;
  }
  // Rectangles within 1 % of the least area are equally small (a right triangle's hull, the footprint of two
  // faces seen at a corner, has the same area on a leg and on the hypotenuse): of those, the one whose sides
  // carry the most points, i.e. the faces the sensor saw. Ties keep the first (deterministic).
  const Candidate* best = nullptr;
  std::size_t best_score = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const Candidate& c = cand[k];
    if (c.area > best_area * 1.01 + 1e-12) continue;
    const double tol = std::max(0.05, 0.02 * std::max(c.u1 - c.u0, c.v1 - c.v0));
    std::size_t score = 0;
    for (const P2& p : pts) {
      const double u = d(p[0]) * c.ux + d(p[1]) * c.uy;
      const double v = -d(p[0]) * c.uy + d(p[1]) * c.ux;
      const double edge = std::min(std::min(u - c.u0, c.u1 - u), std::min(v - c.v0, c.v1 - v));
      score += edge <= tol ? 1U : 0U;
    }
    if (best == nullptr || score > best_score) {
      best = &c;
      best_score = score;
    }
  }
  if (best == nullptr) {  // every hull edge of zero length: cannot happen after convex_hull, but be safe
    r.center = hull[0];
    return r;
  }
  const double cu = 0.5 * (best->u0 + best->u1), cv = 0.5 * (best->v0 + best->v1);
  r.center = {static_cast<float>(cu * best->ux - cv * best->uy), static_cast<float>(cu * best->uy + cv * best->ux)};
  double lu = best->u1 - best->u0, lv = best->v1 - best->v0;
  double yaw = std::atan2(best->uy, best->ux);
  if (lv > lu) {
    std::swap(lu, lv);
    yaw += std::numbers::pi / 2.0;
  }
  // Into (-pi/2, pi/2]: a rectangle's axis has no direction.
  while (yaw > std::numbers::pi / 2.0) yaw -= std::numbers::pi;
  while (yaw <= -std::numbers::pi / 2.0) yaw += std::numbers::pi;
  r.length_m = static_cast<float>(lu);
  r.width_m = static_cast<float>(lv);
  r.yaw_rad = static_cast<float>(yaw);
  return r;
}

SizeClass size_class(float length_m, float width_m, float height_m) {
  const bool small = std::max(length_m, width_m) <= kSmallFootprint_m &&
                     std::min(length_m, width_m) <= kSmallFootprint_m && height_m <= kSmallHeight_m;
  return small ? SizeClass::Small : SizeClass::Large;
}

}  // namespace fieldguard::perception
