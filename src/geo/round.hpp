#pragma once
// std::llround without the library call, for per-point loops (deskew turned every point's time into nanoseconds
// with it, a tenth of its time): half away from zero, the same value wherever the result fits in 63 bits, since
// x - trunc(x) is exact in double; the library's own answer beyond.

#include <cmath>
#include <cstdint>

namespace fieldguard::geo {

inline std::int64_t round_half_away(double x) {
  if (!(std::fabs(x) < 9.0e18)) return std::llround(x);
  auto r = static_cast<std::int64_t>(x);
  const double f = x - static_cast<double>(r);
  r += static_cast<std::int64_t>(f >= 0.5) - static_cast<std::int64_t>(f <= -0.5);
  return r;
}

}  // namespace fieldguard::geo
