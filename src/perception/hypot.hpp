#pragma once
// std::hypot for floats without the library call, to the bit. Private to the perception module.

#include <cmath>

namespace fieldguard::perception {

// glibc's hypotf (2.35 on) is the square root of x^2 + y^2 in double, rounded to float: each square of a float is
// exact in double, so the sum rounds once, as here. Inlined, it is a few instructions where the call was a tenth of
// the ground stage. Non-finite inputs (NaN out) go to std::hypot, which answers infinity for an infinite one even
// beside a NaN. The perception tests hold it to std::hypot's bits over every exponent.
inline float hypot_f(float x, float y) {
  const double dx = static_cast<double>(x), dy = static_cast<double>(y);
  const auto r = static_cast<float>(std::sqrt(dx * dx + dy * dy));
  return r == r ? r : std::hypot(x, y);
}

}  // namespace fieldguard::perception
