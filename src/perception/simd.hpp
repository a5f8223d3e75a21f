#pragma once
// Four-wide float and int vectors through the GCC/Clang vector extensions: SSE2 on x86-64, NEON on AArch64,
// plain code elsewhere, one source. For the loops the compiler does not vectorise at -O2 by itself (voxel
// keys, box tests). Private to the perception module.

#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace fieldguard::perception::simd {

using f32x4 = float __attribute__((vector_size(16)));
using i32x4 = std::int32_t __attribute__((vector_size(16)));

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

// floor(v) as int, v first clamped to [-limit, limit] (NaN to -limit): conversion never sees a value an int
// cannot hold. As std::floor for every float in range: truncate, then one less where that rounded up.
inline i32x4 floor_clamped(f32x4 v, float limit) {
  const f32x4 lo = splat(-limit), hi = splat(limit);
  v = v >= lo ? v : lo;
  v = v <= hi ? v : hi;
  const i32x4 t = __builtin_convertvector(v, i32x4);
  return t + (v < __builtin_convertvector(t, f32x4));  // a true lane is -1
}

// Transposes the 4 x 4 matrix whose rows are a, b, c, d (_MM_TRANSPOSE4_PS): four points' x, y, z, w into an
// x, a y, a z and a w vector, or back.
inline void transpose4(f32x4& a, f32x4& b, f32x4& c, f32x4& d) {
  const f32x4 t0 = __builtin_shufflevector(a, b, 0, 4, 1, 5);
  const f32x4 t1 = __builtin_shufflevector(a, b, 2, 6, 3, 7);
  const f32x4 t2 = __builtin_shufflevector(c, d, 0, 4, 1, 5);
  const f32x4 t3 = __builtin_shufflevector(c, d, 2, 6, 3, 7);
  a = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
  b = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
  c = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
  d = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
}

}  // namespace fieldguard::perception::simd
