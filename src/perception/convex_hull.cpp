// The convex hull of a footprint: Andrew's monotone chain over the points the pre-filter keeps, sorted.
#include <algorithm>
#include <cstdint>
#include <cstring>

#include "fieldguard/perception/obstacle_box.hpp"
#include "perception/hull.hpp"

namespace fieldguard::perception {
namespace hull_detail {
namespace {

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

}  // namespace

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

}  // namespace hull_detail

namespace {

using hull_detail::hull_of;
using hull_detail::P2;

}  // namespace

void convex_hull(std::span<const P2> all, std::vector<P2>& hull, HullScratch& hs) {
  static_cast<void>(hull_of(all, hull, hs));
}

}  // namespace fieldguard::perception
