#pragma once
// Four-lane float and int vectors (GCC and Clang vector extensions), for the few kernels that work on four
// points at a time: the Velodyne decoder's and perception's. Plain C++ otherwise; no intrinsics header, no
// target flags.

#include <cstdint>

namespace fieldguard::vec4 {

using f32x4 = float __attribute__((vector_size(16)));
using i32x4 = std::int32_t __attribute__((vector_size(16)));  // a comparison of two f32x4: -1 (true) or 0

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

}  // namespace fieldguard::vec4
