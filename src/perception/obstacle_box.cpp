#include "fieldguard/perception/obstacle_box.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>

#include "perception/simd.hpp"

namespace fieldguard::perception {
namespace {

using P2 = std::array<float, 2>;

double d(float v) { return static_cast<double>(v); }

double cross(const P2& o, const P2& a, const P2& b) {
  return (d(a[0]) - d(o[0])) * (d(b[1]) - d(o[1])) - (d(a[1]) - d(o[1])) * (d(b[0]) - d(o[0]));
}

}  // namespace

std::string_view to_string(SizeClass c) { return c == SizeClass::Small ? "small" : "large"; }

// A float's bits as an unsigned integer in the same order (negatives flipped): (x, y) then sorts as one
// 64-bit integer, and the mapping is one to one, so sorting the integers sorts the points exactly.
std::uint64_t ordered_bits(float v) {
  std::uint32_t u = 0;
  std::memcpy(&u, &v, sizeof u);
  return (u & 0x80000000U) != 0U ? ~u : (u | 0x80000000U);
}
float from_ordered_bits(std::uint64_t o) {
  auto u = static_cast<std::uint32_t>(o);
  u = (u & 0x80000000U) != 0U ? (u & 0x7FFFFFFFU) : ~u;
  float v = 0.F;
  std::memcpy(&v, &u, sizeof v);
  return v;
}

// Sorts points by (x, y): std::sort when few, else an LSD radix sort of their 64-bit keys (six 11-bit
// passes: linear in the count, where a comparison sort of a wall's thousands of points is not).
void sort_points(std::vector<P2>& pts, HullScratch& s) {
  const std::size_t n = pts.size();
  if (n <= 256) {
    std::sort(pts.begin(), pts.end());
    return;
  }
  s.keys.resize(n);
  s.keys_tmp.resize(n);
  for (std::size_t i = 0; i < n; ++i) s.keys[i] = (ordered_bits(pts[i][0]) << 32U) | ordered_bits(pts[i][1]);
  constexpr unsigned kBits = 11;  // six passes over 2048 counters
  constexpr std::uint64_t kMask = (std::uint64_t{1} << kBits) - 1;
  std::vector<std::uint32_t>& count = s.counts;
  count.resize(std::size_t{1} << kBits);
  for (unsigned shift = 0; shift < 64; shift += kBits) {
    std::fill(count.begin(), count.end(), 0U);
    for (const std::uint64_t k : s.keys) ++count[(k >> shift) & kMask];
    std::uint32_t sum = 0;
    for (auto& c : count) {
      const std::uint32_t v = c;
      c = sum;
      sum += v;
    }
    for (const std::uint64_t k : s.keys) s.keys_tmp[count[(k >> shift) & kMask]++] = k;
    s.keys.swap(s.keys_tmp);
  }
  for (std::size_t i = 0; i < n; ++i) pts[i] = P2{from_ordered_bits(s.keys[i] >> 32U), from_ordered_bits(s.keys[i])};
}

namespace {

// Directions of the extreme points that span the pre-filter's polygon: 16, counter-clockwise from -x.
constexpr std::size_t kHullDirs = 16;
struct HullDirs {
  std::array<float, kHullDirs> x{}, y{};
  HullDirs() {
    for (std::size_t k = 0; k < kHullDirs; ++k) {
      const double a = std::numbers::pi + 2.0 * std::numbers::pi * static_cast<double>(k) / kHullDirs;
      x[k] = static_cast<float>(std::cos(a));
      y[k] = static_cast<float>(std::sin(a));
    }
  }
};

// Leaves out of `all` the points that cannot be hull vertices, into `kept` (input order): the points extreme
// along 16 directions span a polygon inside the hull, and a point strictly inside every edge of it is no hull
// vertex (strictly left of every edge of a closed chain of input points means inside their hull, whatever
// their order). The test is in float, so a point is left out only when it is inside by a margin far above the
// float error of the test; points on or near an edge are kept and the exact hull below decides.
// Most of a dense footprint (a wall of thousands of points) is left out.
void drop_interior(std::span<const P2> all, std::vector<P2>& kept) {
  static const HullDirs dirs;
  const std::size_t n = all.size();
  // Extreme points four at a time: per direction and lane the best value and the first index reaching it,
  // then the lanes reduced (greatest value, then smallest index: the first of equals, deterministic).
  std::array<simd::f32x4, kHullDirs> best_v{};
  std::array<simd::i32x4, kHullDirs> best_i{};
  best_v.fill(simd::splat(-std::numeric_limits<float>::infinity()));
  best_i.fill(simd::splat(std::int32_t{0}));
  simd::f32x4 lo_x = simd::splat(all[0][0]), hi_x = lo_x, lo_y = simd::splat(all[0][1]), hi_y = lo_y;
  const auto load4 = [&](std::size_t i, simd::f32x4& px, simd::f32x4& py) {
    simd::f32x4 a, b;
    std::memcpy(&a, &all[i], sizeof a);
    std::memcpy(&b, &all[i + 2], sizeof b);
    px = __builtin_shufflevector(a, b, 0, 2, 4, 6);
    py = __builtin_shufflevector(a, b, 1, 3, 5, 7);
  };
  const std::size_t n4 = n - n % 4;
  simd::i32x4 idx{0, 1, 2, 3};
  for (std::size_t i = 0; i < n4; i += 4, idx += 4) {
    simd::f32x4 px, py;
    load4(i, px, py);
    lo_x = px < lo_x ? px : lo_x;
    hi_x = px > hi_x ? px : hi_x;
    lo_y = py < lo_y ? py : lo_y;
    hi_y = py > hi_y ? py : hi_y;
    for (std::size_t k = 0; k < kHullDirs; ++k) {
      const simd::f32x4 v = simd::splat(dirs.x[k]) * px + simd::splat(dirs.y[k]) * py;
      const simd::i32x4 better = v > best_v[k];
      best_v[k] = better ? v : best_v[k];
      best_i[k] = better ? idx : best_i[k];
    }
  }
  std::array<std::size_t, kHullDirs> ext{};
  std::array<float, kHullDirs> best{};
  best.fill(-std::numeric_limits<float>::infinity());
  for (std::size_t k = 0; k < kHullDirs; ++k) {
    for (std::size_t j = 0; j < 4 && n4 > 0; ++j) {
      const auto at = static_cast<std::size_t>(best_i[k][j]);
      if (best_v[k][j] > best[k] || (best_v[k][j] == best[k] && at < ext[k])) {
        best[k] = best_v[k][j];
        ext[k] = at;
      }
    }
  }
  float min_x = std::min(std::min(lo_x[0], lo_x[1]), std::min(lo_x[2], lo_x[3]));
  float max_x = std::max(std::max(hi_x[0], hi_x[1]), std::max(hi_x[2], hi_x[3]));
  float min_y = std::min(std::min(lo_y[0], lo_y[1]), std::min(lo_y[2], lo_y[3]));
  float max_y = std::max(std::max(hi_y[0], hi_y[1]), std::max(hi_y[2], hi_y[3]));
  for (std::size_t i = n4; i < n; ++i) {  // the last few, one by one (after every earlier index)
    const float x = all[i][0], y = all[i][1];
    min_x = std::min(min_x, x);
    max_x = std::max(max_x, x);
    min_y = std::min(min_y, y);
    max_y = std::max(max_y, y);
    for (std::size_t k = 0; k < kHullDirs; ++k) {
      const float v = dirs.x[k] * x + dirs.y[k] * y;
      if (v > best[k]) {
        best[k] = v;
        ext[k] = i;
      }
    }
  }
  // The polygon's edges without repeated corners (a corner extreme along several directions), as lines.
  std::array<simd::f32x4, kHullDirs> ax{}, ay{}, ex{}, ey{}, tol{};
  std::size_t edges = 0;
  const float span = std::max(max_x - min_x, max_y - min_y);
  for (std::size_t k = 0; k < kHullDirs; ++k) {
    const P2& a = all[ext[k]];
    const P2& b = all[ext[(k + 1) % kHullDirs]];
    if (a == b) continue;
    const float dx = b[0] - a[0], dy = b[1] - a[1];
    ax[edges] = simd::splat(a[0]);
    ay[edges] = simd::splat(a[1]);
    ex[edges] = simd::splat(dx);
    ey[edges] = simd::splat(dy);
    // |dx * (py - ay) - dy * (px - ax)| <= (|dx| + |dy|) * span; float rounds each of its four operations by
    // 2^-24 relative at most: 1e-5 of that bound is some fifty times the worst error.
    tol[edges] = simd::splat(1e-5F * (std::fabs(dx) + std::fabs(dy)) * (span + 1.F));
    ++edges;
  }
  kept.clear();
  if (edges < 3) {  // all points on one line, or nearly: nothing to leave out safely
    kept.assign(all.begin(), all.end());
    return;
  }
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    simd::f32x4 px, py;
    load4(i, px, py);
    simd::i32x4 inside = simd::splat(std::int32_t{-1});
    for (std::size_t k = 0; k < edges; ++k) {
      inside &= (ex[k] * (py - ay[k]) - ey[k] * (px - ax[k])) > tol[k];
    }
    const unsigned m = simd::mask_bits(inside);
    if (m == 0xFU) continue;
    for (std::size_t j = 0; j < 4; ++j) {
      if ((m & (1U << j)) == 0U) kept.push_back(all[i + j]);
    }
  }
  for (; i < n; ++i) {
    bool inside = true;
    for (std::size_t k = 0; k < edges; ++k) {
      inside = inside && (ex[k][0] * (all[i][1] - ay[k][0]) - ey[k][0] * (all[i][0] - ax[k][0])) > tol[k][0];
    }
    if (!inside) kept.push_back(all[i]);
  }
}

}  // namespace

namespace {

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

}  // namespace

void convex_hull(std::span<const P2> all, std::vector<P2>& hull, HullScratch& hs) {
  hull.clear();
  std::vector<P2>& scratch = hs.points;
  if (all.size() > 64) {
    drop_interior(all, scratch);
  } else {
    scratch.assign(all.begin(), all.end());
  }
  sort_points(scratch, hs);
  std::span<P2> pts(scratch);
  const std::size_t n = pts.size();
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

OrientedRect min_area_rect(std::span<const P2> pts, std::vector<P2>& hull, HullScratch& scratch) {
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
  std::size_t scored = 0;
  const auto ties = [&](const Candidate& c) { return !(c.area > best_area * 1.01 + 1e-12); };
  // One rectangle within 1 %: it wins whatever its score, so the points need not be counted.
  const bool alone = std::count_if(cand, cand + count, ties) == 1;
  for (std::size_t k = 0; k < count && scored < 4; ++k) {  // (a circle-like hull ties everywhere: 4 suffice)
    const Candidate& c = cand[k];
    if (!ties(c)) continue;
    ++scored;
    if (alone) {
      best = &c;
      break;
    }
    const double tol = std::max(0.05, 0.02 * std::max(c.u1 - c.u0, c.v1 - c.v0));
    const std::size_t score = count_near_sides(pts, c.ux, c.uy, c.u0, c.u1, c.v0, c.v1, tol);
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
