#include "fieldguard/core/latency_stats.hpp"

#include <gtest/gtest.h>

namespace fieldguard {
namespace {

constexpr std::int64_t kUs = 1'000;

TEST(LatencyStats, EmptyIsZero) {
  const LatencyStats s;
  EXPECT_EQ(s.count(), 0U);
  EXPECT_EQ(s.max_ns(), 0);
  EXPECT_EQ(s.quantile_ns(0.5), 0);
}

TEST(LatencyStats, QuantilesToTheBucketEdgeAndTheExactMaximum) {
  LatencyStats s;
  for (int i = 1; i <= 100; ++i) s.add(i * 100 * kUs);  // 0.1 .. 10 ms
  EXPECT_EQ(s.count(), 100U);
  EXPECT_EQ(s.max_ns(), 10'000 * kUs);
  EXPECT_EQ(s.quantile_ns(0.5), 5'010 * kUs);   // the 50th value, 5.0 ms, is in the bucket [5.00, 5.01) ms
  EXPECT_EQ(s.quantile_ns(0.99), 9'910 * kUs);  // the 99th, 9.9 ms
  EXPECT_EQ(s.quantile_ns(1.0), 10'000 * kUs);  // never past the maximum
}

TEST(LatencyStats, LongAndNegativeDurationsStayCounted) {
  LatencyStats s;
  s.add(-5);               // a clock step: counted as 0
  s.add(3'000'000 * kUs);  // 3 s: past the last bucket, still the maximum
  EXPECT_EQ(s.count(), 2U);
  EXPECT_EQ(s.max_ns(), 3'000'000 * kUs);
  EXPECT_EQ(s.quantile_ns(0.5), LatencyStats::kBucketNs);
  EXPECT_EQ(s.quantile_ns(1.0), 3'000'000 * kUs);
}

}  // namespace
}  // namespace fieldguard
