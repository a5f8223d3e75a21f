// The convex hull's pre-filter: leaves out the points of a footprint that cannot be hull vertices.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>

#include "perception/hull.hpp"
#include "perception/simd.hpp"

namespace fieldguard::perception::hull_detail {
namespace {

// Points i .. i + 3 of `all` as four x and four y (two unaligned loads, two shuffles); i + 4 <= all.size().
inline void load4(std::span<const P2> all, std::size_t i, simd::f32x4& px, simd::f32x4& py) {
  simd::f32x4 a, b;
  std::memcpy(&a, &all[i], sizeof a);
  std::memcpy(&b, &all[i + 2], sizeof b);
  px = __builtin_shufflevector(a, b, 0, 2, 4, 6);
  py = __builtin_shufflevector(a, b, 1, 3, 5, 7);
}

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

// The pre-filter for a footprint drop_interior() does not vouch for (a coordinate not finite or beyond
// kFilterReach), kept as it was before the octagon so that such a footprint's hull stays what it was: with NaN
// the monotone chain's result depends on which points it sees. It leaves out of `all` the points that cannot be
// hull vertices, into `kept` (input order): the points extreme along 16 directions span a polygon inside the hull, and
// a point strictly inside every edge of it is no hull vertex (strictly left of every edge of a closed chain of input
// points means inside their hull, whatever their order). The test is in float, so a point is left out only when it is
// inside by a margin far above the float error of the test; points on or near an edge are kept and the exact hull below
// decides. Most of a dense footprint (a wall of thousands of points) is left out.
void drop_interior_16(std::span<const P2> all, std::vector<P2>& kept) {
  static const HullDirs dirs;
  const std::size_t n = all.size();
  // Extreme points four at a time: per direction and lane the best value and the first index reaching it,
  // then the lanes reduced (greatest value, then smallest index: the first of equals, deterministic).
  std::array<simd::f32x4, kHullDirs> best_v{};
  std::array<simd::i32x4, kHullDirs> best_i{};
  best_v.fill(simd::splat(-std::numeric_limits<float>::infinity()));
  best_i.fill(simd::splat(std::int32_t{0}));
  simd::f32x4 lo_x = simd::splat(all[0][0]), hi_x = lo_x, lo_y = simd::splat(all[0][1]), hi_y = lo_y;
  const std::size_t n4 = n - n % 4;
  simd::i32x4 idx{0, 1, 2, 3};
  for (std::size_t i = 0; i < n4; i += 4, idx += 4) {
    simd::f32x4 px, py;
    load4(all, i, px, py);
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
    load4(all, i, px, py);
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

// The line of the edge from a along (dx, dy) for the in-polygon test of points q taken from the corner o:
// q is strictly left of it when dx * qy - dy * qx > dx * (ay - oy) - dy * (ax - ox), and is taken as inside only
// when it is so by tol more. |dx * qy - dy * qx| <= (|dx| + |dy|) * span, and each float operation of the test
// (the two differences from o, two products, one difference; the limit rounded to float) errs by 2^-24 of that
// at most: 1e-5 of the bound is some thirty times the worst error.
struct EdgeLine {
  float dx, dy, limit;
  float beyond;  // dx * qy - dy * qx below this: q is outside the line by the margin
};
EdgeLine edge_line(const P2& a, const P2& b, float ox, float oy, float span) {
  const float dx = b[0] - a[0], dy = b[1] - a[1];
  const double tol = 1e-5 * (std::fabs(d(dx)) + std::fabs(d(dy))) * (d(span) + 1.0);
  const double c = d(dx) * (d(a[1]) - d(oy)) - d(dy) * (d(a[0]) - d(ox));
  return {dx, dy, static_cast<float>(c + tol), static_cast<float>(c - tol)};
}

// A second round over the points the octagon kept (a wall's outer face: hundreds of points along each edge,
// outside it by their noise): each edge with kept points outside it gets the farthest of them as a corner
// between its ends (a hull vertex), and the kept points are tested again against that polygon of up to 16
// corners, in place, order kept. Whatever corners are chosen, the polygon is a closed chain of input points:
// the test stays exact. `corners`: the octagon's, counter-clockwise; o = (ox, oy) and span as drop_interior's.
void refine(std::vector<P2>& kept, std::span<const P2> corners, float ox, float oy, float span) {
  constexpr std::size_t kMax = 16;
  const std::size_t n = kept.size(), m = corners.size();
  if (n < 64 || m < 3 || m > kMax / 2) return;
  // The farthest outside each edge: the least dx * qy - dy * qx (in float; any choice keeps the test exact).
  std::array<float, kMax / 2> least{};
  std::array<std::size_t, kMax / 2> at{};
  std::array<EdgeLine, kMax / 2> line{};
  for (std::size_t e = 0; e < m; ++e) {
    line[e] = edge_line(corners[e], corners[(e + 1) % m], ox, oy, span);
    least[e] = line[e].beyond;
    at[e] = n;
  }
  {  // four at a time, per lane the least and its first index, then the lanes (the least, then the first)
    std::array<simd::f32x4, kMax / 2> lv{};
    std::array<simd::i32x4, kMax / 2> li{};
    for (std::size_t e = 0; e < m; ++e) {
      lv[e] = simd::splat(least[e]);
      li[e] = simd::splat(static_cast<std::int32_t>(n));
    }
    const simd::f32x4 vox = simd::splat(ox), voy = simd::splat(oy);
    simd::i32x4 idx{0, 1, 2, 3};
    const std::size_t n4 = n - n % 4;
    for (std::size_t i = 0; i < n4; i += 4, idx += 4) {
      simd::f32x4 a, b;
      std::memcpy(&a, &kept[i], sizeof a);
      std::memcpy(&b, &kept[i + 2], sizeof b);
      const simd::f32x4 qx = __builtin_shufflevector(a, b, 0, 2, 4, 6) - vox;
      const simd::f32x4 qy = __builtin_shufflevector(a, b, 1, 3, 5, 7) - voy;
      for (std::size_t e = 0; e < m; ++e) {
        const simd::f32x4 g = simd::splat(line[e].dx) * qy - simd::splat(line[e].dy) * qx;
        const simd::i32x4 lower = g < lv[e];
        lv[e] = simd::min_or_bound(g, lv[e]);
        li[e] = lower ? idx : li[e];
      }
    }
    for (std::size_t e = 0; e < m; ++e) {
      for (std::size_t j = 0; j < 4; ++j) {
        const auto i = static_cast<std::size_t>(li[e][j]);
        if (lv[e][j] < least[e] || (lv[e][j] == least[e] && i < at[e])) {
          least[e] = lv[e][j];
          at[e] = i;
        }
      }
    }
    for (std::size_t i = n4; i < n; ++i) {
      const float qx = kept[i][0] - ox, qy = kept[i][1] - oy;
      for (std::size_t e = 0; e < m; ++e) {
        const float g = line[e].dx * qy - line[e].dy * qx;
        if (g < least[e]) {
          least[e] = g;
          at[e] = i;
        }
      }
    }
  }
  std::array<P2, kMax> chain{};
  std::size_t c = 0;
  for (std::size_t e = 0; e < m; ++e) {
    chain[c++] = corners[e];
    if (at[e] < n) chain[c++] = kept[at[e]];
  }
  if (c == m) return;  // nothing outside any edge: the same polygon again
  std::array<simd::f32x4, kMax> ex{}, ey{}, limit{};
  for (std::size_t k = 0; k < kMax; ++k) {
    const EdgeLine l =
        k < c ? edge_line(chain[k], chain[(k + 1) % c], ox, oy, span) : edge_line(chain[0], chain[1], ox, oy, span);
    ex[k] = simd::splat(l.dx);
    ey[k] = simd::splat(l.dy);
    limit[k] = simd::splat(l.limit);
  }
  const simd::f32x4 vox = simd::splat(ox), voy = simd::splat(oy);
  std::size_t w = 0, i = 0;
  for (; i + 4 <= n; i += 4) {
    simd::f32x4 a, b;
    std::memcpy(&a, &kept[i], sizeof a);
    std::memcpy(&b, &kept[i + 2], sizeof b);
    const simd::f32x4 qx = __builtin_shufflevector(a, b, 0, 2, 4, 6) - vox,
                      qy = __builtin_shufflevector(a, b, 1, 3, 5, 7) - voy;
    const auto left = [&](std::size_t k) { return (ex[k] * qy - ey[k] * qx) > limit[k]; };
    const simd::i32x4 inside =
        ((left(0) & left(1)) & (left(2) & left(3))) & ((left(4) & left(5)) & (left(6) & left(7))) &
        ((left(8) & left(9)) & (left(10) & left(11))) & ((left(12) & left(13)) & (left(14) & left(15)));
    const unsigned mask = simd::mask_bits(inside);
    for (std::size_t j = 0; j < 4; ++j) {
      if ((mask & (1U << j)) == 0U) kept[w++] = kept[i + j];
    }
  }
  for (; i < n; ++i) {
    const float qx = kept[i][0] - ox, qy = kept[i][1] - oy;
    bool inside = true;
    for (std::size_t k = 0; k < kMax; ++k) inside = inside && (ex[k][0] * qy - ey[k][0] * qx) > limit[k][0];
    if (!inside) kept[w++] = kept[i];
  }
  kept.resize(w);
}

}  // namespace

// Leaves out of `all` the points that cannot be hull vertices, into `kept` (input order): the points extreme
// along 8 directions (along and across the axes: the x, y, x + y and x - y of each point, whose least and
// greatest need no multiplication) span a polygon inside the hull, and a point strictly inside every edge of it
// is no hull vertex (strictly left of every edge of a closed chain of input points means inside their hull,
// whatever their order). The test is in float, so a point is left out only when it is inside by a margin far
// above the float error of the test; points on or near an edge are kept and the exact hull below decides. Which
// points are left out does not change the hull (its vertices are all kept), only how many the sort sees. Most of
// a dense footprint is left out: of the 9,483 points of a shed's three walls the octagon keeps 827 (16 even
// directions kept 697 at twice the cost), refine() all but 62 of those. A point not finite, or one beyond
// kFilterReach: drop_interior_16() instead.
Seen drop_interior(std::span<const P2> all, std::vector<P2>& kept, std::vector<float>& marks) {
  const std::size_t n = all.size();
  // The least and greatest x, y, x + y and x - y, four lanes at a time, values only (the points reaching them are
  // found after: tracking indices too doubled this loop). After every block of kBlock points the eight running
  // extremes are noted in `marks` (as below, counter-clockwise), so that the first point reaching an extreme is
  // looked for in the one block where its running value first reached it: a scan for them from the start went
  // through most of a wall's points.
  constexpr float kInf = std::numeric_limits<float>::infinity();
  constexpr std::size_t kExt = 8, kBlock = 64;
  simd::f32x4 lo_x = simd::splat(kInf), lo_y = lo_x, lo_s = lo_x, lo_d = lo_x;
  simd::f32x4 hi_x = simd::splat(-kInf), hi_y = hi_x, hi_s = hi_x, hi_d = hi_x;
  simd::f32x4 wild = simd::splat(0.F);  // NaN from here on once a point is not finite (or x + y overflows)
  const std::size_t n4 = n - n % 4;
  const std::size_t blocks = (n4 + kBlock - 1) / kBlock;
  marks.resize(blocks * kExt * 4);
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t end = std::min(n4, (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; i += 4) {
      simd::f32x4 px, py;
      load4(all, i, px, py);
      const simd::f32x4 ps = px + py, pd = px - py;
      wild += ps - ps;  // x + y is not finite when x or y is not
      lo_x = simd::min_or_bound(px, lo_x);
      hi_x = simd::max_or_bound(px, hi_x);
      lo_y = simd::min_or_bound(py, lo_y);
      hi_y = simd::max_or_bound(py, hi_y);
      lo_s = simd::min_or_bound(ps, lo_s);
      hi_s = simd::max_or_bound(ps, hi_s);
      lo_d = simd::min_or_bound(pd, lo_d);
      hi_d = simd::max_or_bound(pd, hi_d);
    }
    float* const at = marks.data() + b * kExt * 4;
    const std::array<simd::f32x4, kExt> now{hi_x, hi_s, hi_y, lo_d, lo_x, lo_s, lo_y, hi_d};
    for (std::size_t k = 0; k < kExt; ++k) std::memcpy(at + 4 * k, &now[k], sizeof now[k]);
  }
  // Per extreme, counter-clockwise by direction: +x, +(x + y), +y, -(x - y), -x, -(x + y), -y, +(x - y); the
  // greatest of value * sign.
  const std::array<simd::f32x4, kExt> lanes{hi_x, hi_s, hi_y, lo_d, lo_x, lo_s, lo_y, hi_d};
  constexpr std::array<float, kExt> sign{1.F, 1.F, 1.F, -1.F, -1.F, -1.F, -1.F, 1.F};
  const auto project = [](float x, float y, std::size_t k) {
    const std::array<float, kExt> v{x, x + y, y, x - y, x, x + y, y, x - y};
    return v[k];
  };
  std::array<float, kExt> best{};
  bool finite = true;
  for (std::size_t k = 0; k < kExt; ++k) {
    best[k] = -kInf;
    for (std::size_t j = 0; j < 4 && n4 > 0; ++j) best[k] = std::max(best[k], sign[k] * lanes[k][j]);
  }
  for (std::size_t j = 0; j < 4 && n4 > 0; ++j) finite = finite && wild[j] == 0.F;
  for (std::size_t i = n4; i < n; ++i) {  // the last few, one by one
    finite = finite && std::isfinite(all[i][0] + all[i][1]);
    for (std::size_t k = 0; k < kExt; ++k) best[k] = std::max(best[k], sign[k] * project(all[i][0], all[i][1], k));
  }
  const float min_x = -best[4], max_x = best[0], min_y = -best[6], max_y = best[2];
  const float reach =
      std::max(std::max(std::fabs(min_x), std::fabs(max_x)), std::max(std::fabs(min_y), std::fabs(max_y)));
  if (!finite || !(reach <= kFilterReach)) {
    drop_interior_16(all, kept);
    return Seen{false, reach};
  }
  // The first point reaching each extreme (deterministic): in the first block whose noted running value reached
  // it (the value itself: sign * best[k] is exact), else among the last few. (None found cannot happen, a corner
  // of the polygon that is no extreme would leave the test exact anyway: every corner is an input point.)
  std::array<std::size_t, kExt> ext{};
  for (std::size_t k = 0; k < kExt; ++k) {
    const float target = sign[k] * best[k];
    const simd::f32x4 want = simd::splat(target);
    bool found = false;
    for (std::size_t b = 0; b < blocks && !found; ++b) {
      if (simd::mask_bits(simd::load(marks.data() + (b * kExt + k) * 4) == want) == 0U) continue;
      const std::size_t end = std::min(n4, (b + 1) * kBlock);
      for (std::size_t i = b * kBlock; i < end; i += 4) {
        simd::f32x4 px, py;
        load4(all, i, px, py);
        const std::size_t axis = k % 4;  // x, x + y, y, x - y
        const simd::f32x4 v = axis == 0 ? px : axis == 1 ? px + py : axis == 2 ? py : px - py;
        const unsigned hit = simd::mask_bits(v == want);
        if (hit != 0U) {
          ext[k] = i + static_cast<unsigned>(__builtin_ctz(hit));
          found = true;
          break;
        }
      }
    }
    for (std::size_t i = n4; i < n && !found; ++i) {
      if (project(all[i][0], all[i][1], k) == target) {
        ext[k] = i;
        found = true;
      }
    }
  }
  kept.clear();
  // The polygon's edges without repeated corners (a corner extreme along several directions), as lines.
  std::array<simd::f32x4, kExt> ex{}, ey{}, limit{};
  std::array<P2, kExt> corner{};  // where each edge starts (it ends where the next starts)
  std::size_t edges = 0;
  const float span = std::max(max_x - min_x, max_y - min_y);
  for (std::size_t k = 0; k < kExt; ++k) {
    const P2& a = all[ext[k]];
    const P2& b = all[ext[(k + 1) % kExt]];
    if (a == b) continue;
    const EdgeLine l = edge_line(a, b, min_x, min_y, span);
    corner[edges] = a;
    ex[edges] = simd::splat(l.dx);
    ey[edges] = simd::splat(l.dy);
    limit[edges] = simd::splat(l.limit);
    ++edges;
  }
  if (edges < 3) {  // all points on one line, or nearly: nothing to leave out safely
    kept.assign(all.begin(), all.end());
    return Seen{true, reach};
  }
  for (std::size_t k = edges; k < kExt; ++k) {  // padded with the first edge: the test runs over all eight
    ex[k] = ex[0];
    ey[k] = ey[0];
    limit[k] = limit[0];
  }
  const simd::f32x4 ox = simd::splat(min_x), oy = simd::splat(min_y);
  std::size_t i = 0;
  for (; i < n4; i += 4) {
    simd::f32x4 px, py;
    load4(all, i, px, py);
    const simd::f32x4 qx = px - ox, qy = py - oy;
    // Written out: g++ -O2 kept the loop over the edges, at twice the instructions.
    const auto left = [&](std::size_t k) { return (ex[k] * qy - ey[k] * qx) > limit[k]; };
    const simd::i32x4 inside = (left(0) & left(1)) & (left(2) & left(3)) & (left(4) & left(5)) & (left(6) & left(7));
    const unsigned m = simd::mask_bits(inside);
    if (m == 0xFU) continue;
    for (std::size_t j = 0; j < 4; ++j) {
      if ((m & (1U << j)) == 0U) kept.push_back(all[i + j]);
    }
  }
  for (; i < n; ++i) {
    const float qx = all[i][0] - min_x, qy = all[i][1] - min_y;
    bool inside = true;
    for (std::size_t k = 0; k < kExt; ++k) inside = inside && (ex[k][0] * qy - ey[k][0] * qx) > limit[k][0];
    if (!inside) kept.push_back(all[i]);
  }
  refine(kept, {corner.data(), edges}, min_x, min_y, span);
  return Seen{true, reach};
}

}  // namespace fieldguard::perception::hull_detail
