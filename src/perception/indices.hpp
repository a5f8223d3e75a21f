#pragma once
// Checks on the point indices a stage is handed. Private to the perception module.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>

#include "perception/simd.hpp"

namespace fieldguard::perception {

// Whether every index is below `n`, eight at a time (the compiler leaves the plain loop scalar, and a frame's
// clusters hold most of its points): unsigned comparisons as signed ones, both sides offset by 2^31.
inline bool all_below(std::span<const std::uint32_t> v, std::size_t n) {
  if (n > std::numeric_limits<std::uint32_t>::max()) return true;
  if (n == 0) return v.empty();
  constexpr std::uint32_t kSign = 0x80000000U;
  const simd::i32x4 limit = simd::splat(static_cast<std::int32_t>(static_cast<std::uint32_t>(n - 1) ^ kSign));
  const simd::i32x4 sign = simd::splat(static_cast<std::int32_t>(kSign));
  simd::i32x4 past = simd::splat(std::int32_t{0});
  std::size_t k = 0;
  for (; k + 8 <= v.size(); k += 8) {
    simd::i32x4 a, b;
    std::memcpy(&a, v.data() + k, sizeof a);
    std::memcpy(&b, v.data() + k + 4, sizeof b);
    past |= ((a ^ sign) > limit) | ((b ^ sign) > limit);
  }
  bool ok = simd::mask_bits(past) == 0U;
  for (; k < v.size(); ++k) ok = ok && v[k] < n;
  return ok;
}

// Whether p[0 .. 3] are p[0], p[0] + 1, p[0] + 2 and p[0] + 3: points whose coordinates load as vectors (one
// compare of four lanes, where three scalar ones took eleven instructions). The lanes subtract modulo 2^32, so
// p[0] must be below 2^32 - 3: true of any index below a size kRunSafe bounds.
inline constexpr std::size_t kRunSafe = 0x80000000U;
inline bool run_of_four(const std::uint32_t* p) {
  simd::i32x4 v;
  std::memcpy(&v, p, sizeof v);
  const simd::i32x4 d = v - __builtin_shufflevector(v, v, 0, 0, 0, 0);
  return simd::mask_bits(d == simd::i32x4{0, 1, 2, 3}) == 0xFU;
}

}  // namespace fieldguard::perception
