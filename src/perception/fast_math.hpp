#pragma once
// Approximations the hot loops use where libm is slower than they need. Private to the perception module.

#include <cmath>
#include <cstring>
#include <numbers>

#include "perception/simd.hpp"

namespace fieldguard::perception {

// atan2 within 1e-5 rad (minimax polynomial for atan on [0, 1], then octant symmetry); result in [-pi, pi].
// Deterministic: the same bits for the same inputs. atan2(0, 0) = 0.
inline float fast_atan2(float y, float x) {
  const float ax = std::fabs(x);
  const float ay = std::fabs(y);
  const float hi = ax > ay ? ax : ay;
  const float lo = ax > ay ? ay : ax;
  const float t = hi > 0.F ? lo / hi : 0.F;
  const float s = t * t;
  float r = ((((0.0208351F * s - 0.085133F) * s + 0.180141F) * s - 0.3302995F) * s + 0.999866F) * t;
  if (ay > ax) r = std::numbers::pi_v<float> / 2.F - r;
  if (x < 0.F) r = std::numbers::pi_v<float> - r;
  return y < 0.F ? -r : r;
}

// The same, four at a time (the same polynomial and octant steps, lane by lane: the same bits, signed zeros and
// NaN lanes included).
inline simd::f32x4 fast_atan2(simd::f32x4 y, simd::f32x4 x) {
  using simd::f32x4;
  const f32x4 zero = simd::splat(0.F);
#if defined(__SSE2__)
  // The scalar's steps in one instruction each: fabs clears the sign bit (of -0 and NaN too), and
  // maxps(a, b) / minps(b, a) are a > b ? a : b / b < a ? b : a exactly, NaN lanes included.
  __m128 xv, yv;
  std::memcpy(&xv, &x, sizeof xv);
  std::memcpy(&yv, &y, sizeof yv);
  const __m128 sign_off = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
  const __m128 axv = _mm_and_ps(xv, sign_off), ayv = _mm_and_ps(yv, sign_off);
  const __m128 hiv = _mm_max_ps(axv, ayv), lov = _mm_min_ps(ayv, axv);
  f32x4 ax, ay, hi, lo;
  std::memcpy(&ax, &axv, sizeof ax);
  std::memcpy(&ay, &ayv, sizeof ay);
  std::memcpy(&hi, &hiv, sizeof hi);
  std::memcpy(&lo, &lov, sizeof lo);
#else
  const f32x4 ax = {std::fabs(x[0]), std::fabs(x[1]), std::fabs(x[2]), std::fabs(x[3])};
  const f32x4 ay = {std::fabs(y[0]), std::fabs(y[1]), std::fabs(y[2]), std::fabs(y[3])};
  const f32x4 hi = ax > ay ? ax : ay;
  const f32x4 lo = ax > ay ? ay : ax;
#endif
  const f32x4 t = hi > zero ? lo / (hi > zero ? hi : simd::splat(1.F)) : zero;
  const f32x4 s = t * t;
  f32x4 r = ((((simd::splat(0.0208351F) * s - simd::splat(0.085133F)) * s + simd::splat(0.180141F)) * s -
              simd::splat(0.3302995F)) *
                 s +
             simd::splat(0.999866F)) *
            t;
  r = ay > ax ? simd::splat(std::numbers::pi_v<float> / 2.F) - r : r;
  r = x < zero ? simd::splat(std::numbers::pi_v<float>) - r : r;
  return y < zero ? -r : r;
}

}  // namespace fieldguard::perception
