// The oriented boxes as they were before the octagon pre-filter and the shared count of points on the sides
// (commit 05648ae, src/perception/obstacle_box.cpp, verbatim but for this namespace): the reference the current
// convex_hull() and min_area_rect() must match bit for bit, on random and degenerate footprints.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

#include "fieldguard/perception/obstacle_box.hpp"
#include "perception/simd.hpp"
#include "test_clouds.hpp"

namespace fieldguard::perception {
namespace reference {
namespace {

using P2 = std::array<float, 2>;

double d(float v) { return static_cast<double>(v); }

double cross(const P2& o, const P2& a, const P2& b) {
  return (d(a[0]) - d(o[0])) * (d(b[1]) - d(o[1])) - (d(a[1]) - d(o[1])) * (d(b[0]) - d(o[0]));
}

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
  reference::convex_hull(pts, hull, scratch);
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

}  // namespace
}  // namespace reference

namespace {

using P2 = std::array<float, 2>;
using testing::TestRng;

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// The hull and the rectangle of `pts` from the current code and from the reference, bit for bit (-0 is not +0,
// a NaN is the same NaN).
void expect_as_reference(const std::vector<P2>& pts, const char* what, int trial) {
  std::vector<P2> hull, ref_hull;
  HullScratch scratch, ref_scratch;
  convex_hull(pts, hull, scratch);
  reference::convex_hull(pts, ref_hull, ref_scratch);
  ASSERT_EQ(hull.size(), ref_hull.size()) << what << " " << trial << " (" << pts.size() << " points)";
  for (std::size_t k = 0; k < hull.size(); ++k) {
    ASSERT_TRUE(same_bits(hull[k][0], ref_hull[k][0]) && same_bits(hull[k][1], ref_hull[k][1]))
        << what << " " << trial << " vertex " << k;
  }
  const OrientedRect r = min_area_rect(pts, hull, scratch);
  const OrientedRect q = reference::min_area_rect(pts, ref_hull, ref_scratch);
  EXPECT_TRUE(same_bits(r.center[0], q.center[0]) && same_bits(r.center[1], q.center[1]) &&
              same_bits(r.length_m, q.length_m) && same_bits(r.width_m, q.width_m) && same_bits(r.yaw_rad, q.yaw_rad))
      << what << " " << trial << " (" << pts.size() << " points): " << r.center[0] << ", " << r.center[1] << " "
      << r.length_m << " x " << r.width_m << " at " << r.yaw_rad << " vs " << q.center[0] << ", " << q.center[1] << " "
      << q.length_m << " x " << q.width_m << " at " << q.yaw_rad;
}

// Sizes around every threshold of the code (64: pre-filter; 256 and 4096: sorts) and beyond.
constexpr std::array<std::size_t, 14> kSizes{1, 2, 3, 4, 5, 17, 64, 65, 67, 200, 257, 1000, 4097, 12000};

// Footprints as the pipeline makes them: faces of boxes (one, two or three walls of a shed, a vehicle seen at a
// corner), a porous crown, a person, at any yaw and distance, with range noise.
std::vector<P2> faces(TestRng& rng, std::size_t n) {
  const float yaw = rng.uniform(-3.2F, 3.2F), c = std::cos(yaw), s = std::sin(yaw);
  const float cx = rng.uniform(-60.F, 60.F), cy = rng.uniform(-60.F, 60.F);
  const float len = rng.uniform(0.3F, 30.F), wid = rng.uniform(0.2F, 20.F), noise = rng.uniform(0.F, 0.1F);
  const auto walls = static_cast<unsigned>(rng.next() % 5);  // 0: filled; 1-3 walls; 4: all four
  std::vector<P2> pts;
  for (std::size_t i = 0; i < n; ++i) {
    float u = rng.uniform(-0.5F, 0.5F) * len, v = rng.uniform(-0.5F, 0.5F) * wid;
    const auto side = static_cast<unsigned>(rng.next() % 4);
    if (walls != 0 && side < walls) {
      if (side == 0) v = -0.5F * wid;
      if (side == 1) u = 0.5F * len;
      if (side == 2) v = 0.5F * wid;
      if (side == 3) u = -0.5F * len;
    }
    u += rng.uniform(-noise, noise);
    v += rng.uniform(-noise, noise);
    pts.push_back({cx + c * u - s * v, cy + s * u + c * v});
  }
  return pts;
}

TEST(ObstacleBoxReference, FacesAsThePipelineSeesThem) {
  TestRng rng(11);
  for (int trial = 0; trial < 300; ++trial) {
    expect_as_reference(faces(rng, kSizes[static_cast<std::size_t>(trial) % kSizes.size()]), "faces", trial);
  }
}

// The pre-filter finds the first point reaching each of its eight extremes in the block of 64 where its running
// value first reached it, or among the last few points (past a multiple of four): an extreme put at the first
// point, either side of a block's end, in the last block or in the last few, alone or repeated in a later block.
TEST(ObstacleBoxReference, ExtremesAnywhereInTheFootprint) {
  TestRng rng(17);
  constexpr std::array<float, 16> kDirs{1.F,  0.F, 1.F,  1.F,  0.F, 1.F,  -1.F, 1.F,
                                        -1.F, 0.F, -1.F, -1.F, 0.F, -1.F, 1.F,  -1.F};
  constexpr std::array<std::size_t, 5> kCounts{65, 67, 130, 255, 1001};
  int trial = 0;
  for (const std::size_t n : kCounts) {
    for (const std::size_t at : {std::size_t{0}, std::size_t{63}, std::size_t{64}, n / 2, n - 5, n - 1}) {
      for (std::size_t dir = 0; dir < 8; ++dir, ++trial) {
        std::vector<P2> pts = faces(rng, n);
        const float reach = 200.F;
        pts[at] = {pts[at][0] + reach * kDirs[2 * dir], pts[at][1] + reach * kDirs[2 * dir + 1]};
        expect_as_reference(pts, "extreme", trial);
        if (at + 70 < n) {  // the same point again a block later: the first is the corner
          pts[at + 70] = pts[at];
          expect_as_reference(pts, "repeated extreme", trial);
        }
      }
    }
  }
}

// Points snapped to a coarse lattice: many duplicates, many collinear, equal areas and equal counts everywhere,
// so which of equal candidates wins is tested; some points on the axes (x or y exactly -0 or +0).
TEST(ObstacleBoxReference, LatticesDuplicatesAndSignedZeros) {
  TestRng rng(12);
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = kSizes[static_cast<std::size_t>(trial) % kSizes.size()];
    const float step = trial % 3 == 0 ? 0.5F : (trial % 3 == 1 ? 0.125F : 1.F);
    const auto cells = static_cast<float>(1 + trial % 9);
    std::vector<P2> pts;
    for (std::size_t i = 0; i < n; ++i) {
      float x = step * std::round(rng.uniform(-cells, cells)), y = step * std::round(rng.uniform(-cells, cells));
      if (trial % 4 == 1) y = 0.5F * x;                                             // all on one line
      if (trial % 4 == 2) x = std::copysign(std::fabs(x), rng.uniform(-1.F, 1.F));  // +-0 when zero
      pts.push_back({x, y});
    }
    expect_as_reference(pts, "lattice", trial);
  }
}

// Collinear and nearly collinear, repeated points, one to three distinct points.
TEST(ObstacleBoxReference, DegenerateFootprints) {
  TestRng rng(13);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t n = kSizes[static_cast<std::size_t>(trial) % kSizes.size()];
    const float ox = rng.uniform(-50.F, 50.F), oy = rng.uniform(-50.F, 50.F);
    const float dx = rng.uniform(-1.F, 1.F), dy = rng.uniform(-1.F, 1.F);
    const auto distinct = 1 + static_cast<std::size_t>(rng.next() % 3);
    std::vector<P2> pts;
    for (std::size_t i = 0; i < n; ++i) {
      switch (trial % 4) {
        case 0: {  // on a line
          const float t = rng.uniform(-10.F, 10.F);
          pts.push_back({ox + t * dx, oy + t * dy});
          break;
        }
        case 1: {  // within a micrometre of a line
          const float t = rng.uniform(-10.F, 10.F), e = rng.uniform(-1e-6F, 1e-6F);
          pts.push_back({ox + t * dx - e * dy, oy + t * dy + e * dx});
          break;
        }
        case 2:  // a few distinct points, repeated
          pts.push_back({ox + static_cast<float>(i % distinct) * dx, oy + static_cast<float>(i % distinct) * dy});
          break;
        default:  // all one point
          pts.push_back({ox, oy});
      }
    }
    expect_as_reference(pts, "degenerate", trial);
  }
}

// Far from the origin, tiny and huge spans: the float tests' margins scale with the coordinates.
TEST(ObstacleBoxReference, HugeAndTinyCoordinates) {
  TestRng rng(14);
  for (int trial = 0; trial < 240; ++trial) {
    // At most 4097 points: an offset that overflows to infinity makes every point a hull vertex (the chain's
    // tests turn NaN), and the rectangle search is quadratic in those.
    const std::size_t n = std::min<std::size_t>(4097, kSizes[static_cast<std::size_t>(trial) % kSizes.size()]);
    const std::array<float, 8> scales{1e-30F, 1e-6F, 1e3F, 1e6F, 1e12F, 1e20F, 1e30F, 1e37F};
    const std::array<float, 4> offsets{0.F, 1e4F, 1e7F, -3e8F};
    const float scale = scales[static_cast<std::size_t>(trial) % scales.size()];
    const float off = offsets[static_cast<std::size_t>(trial / 8) % offsets.size()] * (scale > 1.F ? scale : 1.F);
    std::vector<P2> pts = faces(rng, n);
    for (P2& p : pts) p = {off + (p[0] - 0.F) * scale, p[1] * scale};
    expect_as_reference(pts, "scaled", trial);
  }
}

// Not finite: no caller passes NaN or infinity (the crop and the near-field zone reject them); such a footprint
// still gets the box it got before. Compared where the reference is defined: its float sort (256 points or
// fewer) is undefined with NaN, so footprints of thousands of points with a long outline, which its pre-filter
// leaves over 256.
TEST(ObstacleBoxReference, NotFinite) {
  TestRng rng(15);
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN(), kInf = std::numeric_limits<float>::infinity();
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<P2> pts = faces(rng, 4097 + static_cast<std::size_t>(trial));
    // Keep it over 256 points after the reference's pre-filter: a hollow outline with points all along.
    for (int k = 0; k < 300; ++k) {
      const float a = 0.021F * static_cast<float>(k);
      pts.push_back({500.F * std::cos(a), 500.F * std::sin(a)});
    }
    const std::array<P2, 4> bad{P2{kNaN, 1.F}, P2{2.F, kNaN}, P2{kInf, 0.F}, P2{-kInf, kInf}};
    pts[rng.next() % pts.size()] = bad[static_cast<std::size_t>(trial) % bad.size()];
    expect_as_reference(pts, "not finite", trial);
  }
}

}  // namespace
}  // namespace fieldguard::perception
