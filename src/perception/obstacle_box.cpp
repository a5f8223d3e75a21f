#include "fieldguard/perception/obstacle_box.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
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

void convex_hull(std::span<const P2> all, std::vector<P2>& hull, HullScratch& hs) {
  hull.clear();
  std::vector<P2>& scratch = hs.points;
  if (all.size() > 64) {
    // Akl-Toussaint: the points extreme along x, x + y, y, y - x (both ways) span an octagon inside the hull;
    // points strictly inside it cannot be hull vertices. A wall of thousands of points keeps a few dozen.
    std::array<std::size_t, 8> ext{};
    std::array<float, 8> best{};
    best.fill(-std::numeric_limits<float>::max());
    for (std::size_t i = 0; i < all.size(); ++i) {
      const float x = all[i][0], y = all[i][1];
      const float key[8] = {-x, -x - y, -y, x - y, x, x + y, y, y - x};  // counter-clockwise from min x
      for (std::size_t k = 0; k < 8; ++k) {
        if (key[k] > best[k]) {
          best[k] = key[k];
          ext[k] = i;
        }
      }
    }
    scratch.clear();
    for (const P2& p : all) {
      bool inside = true;
      for (std::size_t k = 0; k < 8 && inside; ++k) inside = cross(all[ext[k]], all[ext[(k + 1) % 8]], p) > 0.0;
      if (!inside) scratch.push_back(p);  // on or outside an edge: may be on the hull (corners are kept)
    }
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
  for (std::size_t k = 0; k < count && scored < 4; ++k) {  // (a circle-like hull ties everywhere: 4 suffice)
    const Candidate& c = cand[k];
    if (c.area > best_area * 1.01 + 1e-12) continue;
    ++scored;
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
