#include "fieldguard/perception/obstacle_box.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>

#include "perception/hull.hpp"
#include "perception/simd.hpp"

namespace fieldguard::perception {
namespace {

using hull_detail::d;
using hull_detail::hull_of;
using hull_detail::P2;
using hull_detail::Seen;

// How many of `pts` lie within `tol` of a side of the rectangle [u0, u1] x [v0, v1] along the axes (ux, uy)
// and (-uy, ux): two points at a time in double, lane by lane the operations of the one-point loop at the end
// (std::min as b < a ? b : a), so the same count.
std::size_t count_near_sides(std::span<const P2> pts, double ux, double uy, double u0, double u1, double v0, double v1,
                             double tol) {
  using f64x2 = double __attribute__((vector_size(16)));
  using i64x2 = std::int64_t __attribute__((vector_size(16)));
  using f32x2 = float __attribute__((vector_size(8)));
  const auto min2 = [](f64x2 a, f64x2 b) { return b < a ? b : a; };
  const f64x2 vux = {ux, ux}, vuy = {uy, uy}, vu0 = {u0, u0}, vu1 = {u1, u1}, vv0 = {v0, v0}, vv1 = {v1, v1};
  const f64x2 vtol = {tol, tol};
  i64x2 near = {0, 0};  // minus the count per lane (a true comparison is -1)
  const std::size_t n = pts.size();
  std::size_t i = 0;
  for (; i + 2 <= n; i += 2) {
    f32x2 xs = {pts[i][0], pts[i + 1][0]}, ys = {pts[i][1], pts[i + 1][1]};
    const f64x2 px = __builtin_convertvector(xs, f64x2), py = __builtin_convertvector(ys, f64x2);
    const f64x2 u = px * vux + py * vuy;
    const f64x2 v = -px * vuy + py * vux;
    const f64x2 edge = min2(min2(u - vu0, vu1 - u), min2(v - vv0, vv1 - v));
    near += edge <= vtol;
  }
  std::size_t score = static_cast<std::size_t>(-(near[0] + near[1]));
  for (; i < n; ++i) {
    const P2& p = pts[i];
    const double u = d(p[0]) * ux + d(p[1]) * uy;
    const double v = -d(p[0]) * uy + d(p[1]) * ux;
    const double edge = std::min(std::min(u - u0, u1 - u), std::min(v - v0, v1 - v));
    score += edge <= tol ? 1U : 0U;
  }
  return score;
}

struct Candidate {
  double ux, uy, u0, u1, v0, v1, area;
  // How near a side a point must be to count as on it.
  [[nodiscard]] double tol() const { return std::max(0.05, 0.02 * std::max(u1 - u0, v1 - v0)); }
  [[nodiscard]] std::size_t count(std::span<const P2> pts) const {
    return count_near_sides(pts, ux, uy, u0, u1, v0, v1, tol());
  }
};

// The points of `pts` that some of `cands` may not count (more than its tol() from each of its sides), into
// `maybe`; every point left out is counted by every one of them. Each rectangle's region of uncounted points
// (its inside shrunk by tol() on every side, grown by a slack far above the double error of count_near_sides'
// test) is mapped into the first rectangle's axes, and a point is kept when it falls in the box around all of
// them there, tested in float with a margin far above that test's float error. A footprint's points mostly
// lie on its faces, near the sides of every near-least rectangle: few are kept (a shed's three walls, 9,500
// points, keep 2). `reach`: the largest coordinate magnitude, at most kFilterReach; every point finite.
void maybe_uncounted(std::span<const P2> pts, std::span<const Candidate* const> cands, float reach,
                     std::vector<P2>& maybe) {
  maybe.clear();
  constexpr double kBig = std::numeric_limits<double>::max();
  const double ax = cands[0]->ux, ay = cands[0]->uy;
  double bu0 = kBig, bu1 = -kBig, bv0 = kBig, bv1 = -kBig;
  const double slack = 1e-9 * (static_cast<double>(reach) + 1.0);
  for (const Candidate* c : cands) {
    const double tol = c->tol();
    const double lu = c->u0 + tol - slack, hu = c->u1 - tol + slack;
    const double lv = c->v0 + tol - slack, hv = c->v1 - tol + slack;
    if (!(lu <= hu) || !(lv <= hv)) continue;  // narrower than 2 tol: every point near a side
    for (const double u : {lu, hu}) {
      for (const double v : {lv, hv}) {
        const double x = u * c->ux - v * c->uy, y = u * c->uy + v * c->ux;
        const double u1 = x * ax + y * ay, v1 = -x * ay + y * ax;
        bu0 = std::min(bu0, u1);
        bu1 = std::max(bu1, u1);
        bv0 = std::min(bv0, v1);
        bv1 = std::max(bv1, v1);
      }
    }
  }
  if (bu0 > bu1) return;
  const float margin = 1e-5F * (reach + 1.F);
  const simd::f32x4 fa = simd::splat(static_cast<float>(ax)), fb = simd::splat(static_cast<float>(ay));
  const simd::f32x4 lu = simd::splat(static_cast<float>(bu0) - margin),
                    hu = simd::splat(static_cast<float>(bu1) + margin);
  const simd::f32x4 lv = simd::splat(static_cast<float>(bv0) - margin),
                    hv = simd::splat(static_cast<float>(bv1) + margin);
  const std::size_t n = pts.size();
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    simd::f32x4 a, b;
    std::memcpy(&a, &pts[i], sizeof a);
    std::memcpy(&b, &pts[i + 2], sizeof b);
    const simd::f32x4 px = __builtin_shufflevector(a, b, 0, 2, 4, 6), py = __builtin_shufflevector(a, b, 1, 3, 5, 7);
    const simd::f32x4 u = px * fa + py * fb, v = py * fa - px * fb;
    const unsigned m = simd::mask_bits((u >= lu) & (u <= hu) & (v >= lv) & (v <= hv));
    if (m == 0U) continue;
    for (std::size_t j = 0; j < 4; ++j) {
      if ((m & (1U << j)) != 0U) maybe.push_back(pts[i + j]);
    }
  }
  for (; i < n; ++i) {
    const float u = pts[i][0] * fa[0] + pts[i][1] * fb[0], v = pts[i][1] * fa[0] - pts[i][0] * fb[0];
    if (u >= lu[0] && u <= hu[0] && v >= lv[0] && v <= hv[0]) maybe.push_back(pts[i]);
  }
}

}  // namespace

OrientedRect min_area_rect(std::span<const P2> pts, std::vector<P2>& hull, HullScratch& scratch) {
  OrientedRect r;
  if (pts.empty()) return r;
  const Seen seen = hull_of(pts, hull, scratch);
  const std::size_t h = hull.size();
  if (h == 1) {
    r.center = hull[0];
    return r;
  }
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
  // carry the most points, i.e. the faces the sensor saw. Ties keep the first (deterministic). Only the first
  // four are scored (a circle-like hull ties everywhere: 4 suffice).
  const auto ties = [&](const Candidate& c) { return !(c.area > best_area * 1.01 + 1e-12); };
  std::array<const Candidate*, 4> scored{};
  std::size_t n_scored = 0, n_ties = 0;
  for (std::size_t k = 0; k < count; ++k) {
    if (!ties(cand[k])) continue;
    ++n_ties;
    if (n_scored < scored.size()) scored[n_scored++] = &cand[k];
  }
  const Candidate* best = n_scored > 0 ? scored[0] : nullptr;
  // One rectangle within 1 %: it wins whatever its score, so the points need not be counted.
  if (n_ties > 1) {
    // Points counted by every scored rectangle add the same to each score: only those some may not count are
    // looked at one by one, when the pre-filter vouched for the points (finite, float-safe).
    std::span<const P2> looked = pts;
    std::size_t common = 0;
    if (seen.tame) {
      maybe_uncounted(pts, {scored.data(), n_scored}, seen.reach, scratch.points);
      looked = scratch.points;
      common = pts.size() - looked.size();
    }
    std::size_t best_score = 0;
    for (std::size_t k = 0; k < n_scored; ++k) {
      const std::size_t score = common + scored[k]->count(looked);
      if (k == 0 || score > best_score) {
        best = scored[k];
        best_score = score;
      }
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
