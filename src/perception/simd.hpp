#pragma once
// Four-wide float and int vectors through the GCC/Clang vector extensions: SSE2 on x86-64, NEON on AArch64,
// plain code elsewhere, one source. For the loops the compiler does not vectorise at -O2 by itself (voxel
// keys, box tests). Private to the perception module.

#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "fieldguard/core/vec4.hpp"

namespace fieldguard::perception::simd {

using vec4::f32x4;
using vec4::i32x4;

inline f32x4 load(const float* p) {
  f32x4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline f32x4 splat(float s) { return f32x4{s, s, s, s}; }
inline i32x4 splat(std::int32_t s) { return i32x4{s, s, s, s}; }

// Bit k set where lane k of a comparison result is true (all ones).
inline unsigned mask_bits(i32x4 m) {
#if defined(__SSE2__)
  __m128i v;
  std::memcpy(&v, &m, sizeof v);
  return static_cast<unsigned>(_mm_movemask_ps(_mm_castsi128_ps(v)));
#else
  return (m[0] != 0 ? 1U : 0U) | (m[1] != 0 ? 2U : 0U) | (m[2] != 0 ? 4U : 0U) | (m[3] != 0 ? 8U : 0U);
#endif
}

// v > lo ? v : lo and v < hi ? v : hi, lane by lane (NaN gives the bound): SSE2's maxps and minps exactly.
// g++ does not always find them in the vector-extension form (a compare and three logic operations).
inline f32x4 max_or_bound(f32x4 v, f32x4 lo) {
#if defined(__SSE2__)
  return _mm_max_ps(v, lo);
#else
  return v > lo ? v : lo;
#endif
}
inline f32x4 min_or_bound(f32x4 v, f32x4 hi) {
#if defined(__SSE2__)
  return _mm_min_ps(v, hi);
#else
  return v < hi ? v : hi;
#endif
}

// floor(v) as int, v first clamped to [lo, hi] (NaN to lo): conversion never sees a value an int cannot
// hold. As std::floor for every float in range: truncate, then one less where that rounded up. The clamps
// are strict comparisons (maxps, minps): they differ from >= and <= only where v equals the bound, a value
// (and a floor) both return.
inline i32x4 floor_clamped(f32x4 v, f32x4 lo, f32x4 hi) {
  v = min_or_bound(max_or_bound(v, lo), hi);
  const i32x4 t = __builtin_convertvector(v, i32x4);
  return t + (v < __builtin_convertvector(t, f32x4));  // a true lane is -1
}

using vec4::transpose4;

}  // namespace fieldguard::perception::simd
