// round_half_away() (geo/round.hpp) against std::llround: halves both ways, the float times deskew rounds, the
// edges of its fast path.

#include "geo/round.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

namespace fieldguard::geo {
namespace {

TEST(RoundHalfAway, AgreesWithLlround) {
  for (const double x : {0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, -2.5, 0.49999999999999994, -0.49999999999999994,
                         976562.5, -976562.5, 4503599627370495.5, -4503599627370495.5, 4503599627370496.0,
                         8.9e18, -8.9e18, 9.1e18, -9.1e18}) {
    EXPECT_EQ(round_half_away(x), std::llround(x)) << x;
  }
  // Every float time a frame can hold (seconds, up to a few, with its 24-bit mantissa), in nanoseconds, as deskew
  // computes them: exact halves among them (a time of k / 1024 s is a half nanosecond times an odd number).
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> t(-1.0F, 4.0F);
  for (int i = 0; i < 200000; ++i) {
    const double x = static_cast<double>(t(rng)) * 1e9;
    ASSERT_EQ(round_half_away(x), std::llround(x)) << x;
  }
  for (int k = -4096; k <= 4096; ++k) {
    const double x = static_cast<double>(static_cast<float>(k) / 1024.0F) * 1e9;
    ASSERT_EQ(round_half_away(x), std::llround(x)) << x;
  }
}

}  // namespace
}  // namespace fieldguard::geo
