#pragma once
// std::nth_element over floats as libstdc++ does it, element move for element move, with partitions that do not
// branch on the data. Private to the perception module.
//
// The zone ground's seed height is the float sum of a bin's lowest residuals in the order std::nth_element leaves
// them, so any other selection (same elements, other order) could change a seed by an ulp and with it a plane. But
// libstdc++'s Hoare partition branches on every comparison with the pivot, and on a bin's residuals (random about
// the pivot) each of those branches is a coin toss: about one mispredicted branch per residual and partition, nine
// in ten of the ground stage's (14,000 a shed 5 Hz rotation, some 40 us of its 0.3 ms). Its outcome does not
// need the branches: the left scan stops at the elements not below the pivot, the right scan at those not above
// it, and the i-th left stop is swapped with the i-th right stop for as long as the first lies left of the second;
// the scan then ends at the first left stop not left of its partner (or at the last right stop, if passed). Both
// lists of stops are written branch-free in one pass, and the swaps are then a loop that leaves once. The pivot
// (median of three, moved to the front), the ranges, the depth limit and the final insertion sort are libstdc++'s
// (std::__introselect). The perception tests hold it to the std::nth_element it is built with, element for element:
// a standard library that selects otherwise fails them (the ground's output would change with it anyway).

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>

#include "perception/simd.hpp"

namespace fieldguard::perception {

namespace nth_detail {

inline std::uint32_t pick(bool take_x, std::uint32_t x, std::uint32_t y) {
  return y ^ ((x ^ y) & (0U - static_cast<std::uint32_t>(take_x)));
}

// v[first] = the median of v[a], v[b], v[c] by swapping, as std::__move_median_to_first. Its three comparisons
// all made (none has a side effect) and the index picked without branches.
inline void move_median_to_first(float* v, std::uint32_t first, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  const bool ab = v[a] < v[b], bc = v[b] < v[c], ac = v[a] < v[c];
  const std::uint32_t m = pick(ab, pick(bc, b, pick(ac, c, a)), pick(ac, a, pick(bc, c, b)));
  std::swap(v[first], v[m]);
}

inline simd::i32x4 load_lanes(const std::int32_t* p) {
  simd::i32x4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// Bit k set where !(a[k] < b[k]) (NaN on either side included): SSE2's cmpnltps, where the vector extensions
// would compare and then invert.
inline unsigned not_less_bits(simd::f32x4 a, simd::f32x4 b) {
#if defined(__SSE2__)
  __m128 av, bv;
  std::memcpy(&av, &a, sizeof av);
  std::memcpy(&bv, &b, sizeof bv);
  return static_cast<unsigned>(_mm_movemask_ps(_mm_cmpnlt_ps(av, bv)));
#else
  return simd::mask_bits(~(a < b));
#endif
}

// Per four-bit mask: the set bits' lane numbers in ascending order (the rest 0), and how many are set.
struct Compaction {
  alignas(16) std::int32_t lanes[16][4];
  std::uint32_t count[16];
};
constexpr Compaction make_compaction() {
  Compaction t{};
  for (std::uint32_t m = 0; m < 16; ++m) {
    std::uint32_t k = 0;
    for (std::uint32_t l = 0; l < 4; ++l) {
      if ((m >> l) & 1U) t.lanes[m][k++] = static_cast<std::int32_t>(l);
    }
    t.count[m] = k;
  }
  return t;
}
inline constexpr Compaction kCompaction = make_compaction();

// std::__unguarded_partition(v + first + 1, v + last, v + first): the same swaps, and where it returns.
// left and right hold last - first + 1 positions each.
inline std::uint32_t partition(float* v, std::uint32_t first, std::uint32_t last, std::uint32_t* left,
                               std::uint32_t* right) {
  const float p = v[first];
  // left: the left scan's stops, ascending. right[1 ..]: the right scan's, ascending (the scan meets them from the
  // top); right[0] = first stands for "none left" (below every left stop), right[count + 1] = last for "none yet".
  std::uint32_t nl = 0, nr = 1;
  right[0] = first;
  std::uint32_t j = first + 1;
  // Four at a time: each lane that stops a scan adds its position to that scan's list, compacted by table.
  const simd::f32x4 pv = simd::splat(p);
  simd::i32x4 base = simd::splat(static_cast<std::int32_t>(j));
  for (; j + 4 <= last; j += 4, base += simd::splat(4)) {
    const simd::f32x4 x = simd::load(v + j);
    const unsigned ml = not_less_bits(x, pv), mr = not_less_bits(pv, x);
    const simd::i32x4 l = base + load_lanes(kCompaction.lanes[ml]);
    const simd::i32x4 r = base + load_lanes(kCompaction.lanes[mr]);
    std::memcpy(left + nl, &l, sizeof l);
    std::memcpy(right + nr, &r, sizeof r);
    nl += kCompaction.count[ml];
    nr += kCompaction.count[mr];
  }
  for (; j < last; ++j) {
    const float x = v[j];
    left[nl] = j;
    right[nr] = j;
    nl += !(x < p) ? 1U : 0U;
    nr += !(p < x) ? 1U : 0U;
  }
  left[nl] = last;  // no stop left: past every right stop, the loop below ends
  right[nr] = last;
  --nr;  // right[nr]: the first right stop; right[nr - i]: the i-th
  std::uint32_t i = 0;
  for (;; ++i) {
    const std::uint32_t a = left[i], b = right[nr - i];
    if (!(a < b)) break;
    std::swap(v[a], v[b]);
  }
  // The i-th left scan stops at its own stop or at the (i-1)-th right stop, which now holds a left stop's element.
  const std::uint32_t own = left[i], passed = right[nr - i + 1];
  return own < passed ? own : passed;
}

// std::__insertion_sort over v[first, last).
inline void insertion_sort(float* v, std::uint32_t first, std::uint32_t last) {
  if (first == last) return;
  for (std::uint32_t i = first + 1; i != last; ++i) {
    const float val = v[i];
    if (val < v[first]) {
      for (std::uint32_t k = i; k != first; --k) v[k] = v[k - 1];
      v[first] = val;
    } else {
      std::uint32_t k = i;
      while (val < v[k - 1]) {
        v[k] = v[k - 1];
        --k;
      }
      v[k] = val;
    }
  }
}

}  // namespace nth_detail

// Positions go through int lanes.
inline constexpr std::uint32_t kMaxElements = 0x7FFFFFF0U;

// std::nth_element(v, v + nth, v + n) with operator<, as libstdc++ leaves the elements. scratch: 2 n + 2 positions.
// False where libstdc++ gives up partitioning (2 log2 n partitions that left more than three elements around nth,
// for adversarial input) and heap-selects, and for n > kMaxElements: v is then partly partitioned, and the caller
// runs std::nth_element on the original values.
inline bool nth_element_branchfree(float* v, std::uint32_t n, std::uint32_t nth, std::uint32_t* scratch) {
  if (n == 0 || nth >= n) return true;
  if (n > kMaxElements) return false;
  std::uint32_t first = 0, last = n;
  int depth = 0;  // std::__lg(n) * 2
  for (std::uint32_t m = n; m > 1; m >>= 1U) depth += 2;
  std::uint32_t* const left = scratch;
  std::uint32_t* const right = scratch + n + 1;
  while (last - first > 3) {
    if (depth == 0) return false;
    --depth;
    const std::uint32_t mid = first + (last - first) / 2;
    nth_detail::move_median_to_first(v, first, first + 1, mid, last - 1);
    const std::uint32_t cut = nth_detail::partition(v, first, last, left, right);
    if (cut <= nth) {
      first = cut;
    } else {
      last = cut;
    }
  }
  nth_detail::insertion_sort(v, first, last);
  return true;
}

}  // namespace fieldguard::perception
