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

// Points i .. i + 3 of `all` as four x and four y (two unaligned loads, two shuffles); i + 4 <= all.size().
inline void load4(std::span<const P2> all, std::size_t i, simd::f32x4& px, simd::f32x4& py) {
  simd::f32x4 a, b;
  std::memcpy(&a, &all[i], sizeof a);
  std::memcpy(&b, &all[i + 2], sizeof b);
  px = __builtin_shufflevector(a, b, 0, 2, 4, 6);
  py = __builtin_shufflevector(a, b, 1, 3, 5, 7);
}

}  // namespace

std::string_view to_string(SizeClass c) { return c == SizeClass::Small ? "small" : "large"; }

void sort_obstacles(std::vector<Obstacle>& obstacles) {
  std::sort(obstacles.begin(), obstacles.end(), [](const Obstacle& a, const Obstacle& b) {
    if (a.distance_m != b.distance_m) return a.distance_m < b.distance_m;
    if (a.bearing_deg != b.bearing_deg) return a.bearing_deg < b.bearing_deg;
    return a.min < b.min;
  });
}

namespace {

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

// Sorts points by (x, y): std::sort when few; else by their 64-bit keys, with std::sort up to a few thousand
// and above that an LSD radix sort (six 11-bit passes: linear in the count, but each pass clears and sums 2048
// counters, which costs more than a comparison sort of the hundreds of points a pre-filtered wall leaves).
// Both key sorts give the one order of the keys, so the same points whichever runs.
void sort_points(std::vector<P2>& pts, HullScratch& s) {
  const std::size_t n = pts.size();
  if (n <= 256) {
    std::sort(pts.begin(), pts.end());
    return;
  }
  s.keys.resize(n);
  for (std::size_t i = 0; i < n; ++i) s.keys[i] = (ordered_bits(pts[i][0]) << 32U) | ordered_bits(pts[i][1]);
  if (n <= 4096) {
    std::sort(s.keys.begin(), s.keys.end());
  } else {
    s.keys_tmp.resize(n);
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
  }
  for (std::size_t i = 0; i < n; ++i) pts[i] = P2{from_ordered_bits(s.keys[i] >> 32U), from_ordered_bits(s.keys[i])};
}

// Beyond this coordinate magnitude the octagon pre-filter and the shared count of points on the sides are not
// used: their float tests could overflow (a footprint never comes near it).
constexpr float kFilterReach = 1e18F;

// What drop_interior() saw of the points: all finite and within kFilterReach (else drop_interior_16() filtered
// them), and the largest coordinate magnitude.
struct Seen {
  bool tame = false;
  float reach = 0.F;
};

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
// hull vertices, into `kept` (input order): the points extreme along 16 directions span a polygon inside the hull, and a point strictly inside every edge of it is no hull
// vertex (strictly left of every edge of a closed chain of input points means inside their hull, whatever
// their order). The test is in float, so a point is left out only when it is inside by a margin far above the
// float error of the test; points on or near an edge are kept and the exact hull below decides.
// Most of a dense footprint (a wall of thousands of points) is left out.
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
    const EdgeLine l = k < c ? edge_line(chain[k], chain[(k + 1) % c], ox, oy, span) : edge_line(chain[0], chain[1], ox, oy, span);
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
    const simd::f32x4 qx = __builtin_shufflevector(a, b, 0, 2, 4, 6) - vox, qy = __builtin_shufflevector(a, b, 1, 3, 5, 7) - voy;
    const auto left = [&](std::size_t k) { return (ex[k] * qy - ey[k] * qx) > limit[k]; };
    const simd::i32x4 inside = ((left(0) & left(1)) & (left(2) & left(3))) & ((left(4) & left(5)) & (left(6) & left(7))) &
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
  const float reach = std::max(std::max(std::fabs(min_x), std::fabs(max_x)), std::max(std::fabs(min_y), std::fabs(max_y)));
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

namespace {

// convex_hull(), telling what the pre-filter saw (nothing when it did not run: 64 points or fewer).
Seen hull_of(std::span<const P2> all, std::vector<P2>& hull, HullScratch& hs) {
  hull.clear();
  std::vector<P2>& scratch = hs.points;
  Seen seen;
  if (all.size() > 64) {
    seen = drop_interior(all, scratch, hs.marks);
  } else {
    scratch.assign(all.begin(), all.end());
  }
  sort_points(scratch, hs);
  std::span<P2> pts(scratch);
  const std::size_t n = pts.size();
  if (n <= 1) {
    hull.assign(pts.begin(), pts.end());
    return seen;
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
  return seen;
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
  const simd::f32x4 lu = simd::splat(static_cast<float>(bu0) - margin), hu = simd::splat(static_cast<float>(bu1) + margin);
  const simd::f32x4 lv = simd::splat(static_cast<float>(bv0) - margin), hv = simd::splat(static_cast<float>(bv1) + margin);
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

void convex_hull(std::span<const P2> all, std::vector<P2>& hull, HullScratch& hs) {
  static_cast<void>(hull_of(all, hull, hs));
}

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
