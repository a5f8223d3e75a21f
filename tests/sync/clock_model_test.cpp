// Counter unwrapping and the lower-envelope clock fit on synthetic streams with drift, offset and one-sided
// exponential delay jitter.

#include "fieldguard/sync/clock_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace fieldguard::sync {
namespace {

TEST(WrapUnwrapper, VelodyneMicrosecondsPastTheHourRollOver) {
  WrapUnwrapper u(kVelodyneMicrosPastHour);
  u.seed_base(1'000 * 3'600'000'000LL);               // hour 1000 since the epoch
  const std::int64_t a = u.unwrap_ns(3'599'900'000);  // 0.1 s before the top of the hour
  const std::int64_t b = u.unwrap_ns(100'000);        // 0.1 s after it
  EXPECT_EQ(b - a, 200'000'000);
  EXPECT_EQ(a, (1'000 * 3'600'000'000LL + 3'599'900'000) * 1'000);
  EXPECT_EQ(u.wraps(), 1U);
  EXPECT_EQ(u.steps_back(), 0U);
}

TEST(WrapUnwrapper, XsensSampleTimeFineRollOver) {
  WrapUnwrapper u(kXsensSampleTimeFine);
  const std::int64_t a = u.unwrap_ns(0xFFFF'FFFFULL - 49);  // 5 ms before the wrap
  const std::int64_t b = u.unwrap_ns(50);                   // 5 ms after it
  EXPECT_EQ(b - a, 10'000'000);
  EXPECT_EQ(u.wraps(), 1U);
}

TEST(WrapUnwrapper, ScipTwentyFourBitMillisecondsRollOver) {
  WrapUnwrapper u(kScipMillis);
  const std::int64_t a = u.unwrap_ns((1U << 24) - 10);
  const std::int64_t b = u.unwrap_ns(15);
  EXPECT_EQ(b - a, 25'000'000);
  EXPECT_EQ(u.wraps(), 1U);
}

TEST(WrapUnwrapper, NmeaTimeOfDayRollsOverAtMidnight) {
  WrapUnwrapper u(kNmeaNanosOfDay);
  const std::int64_t a = u.unwrap_ns(86'399'900'000'000ULL);  // 23:59:59.9
  const std::int64_t b = u.unwrap_ns(100'000'000ULL);         // 00:00:00.1 next day
  EXPECT_EQ(b - a, 200'000'000);
  EXPECT_EQ(u.wraps(), 1U);
}

TEST(WrapUnwrapper, SmallStepBackIsNotAWrapAndOutOfRangeIsCounted) {
  WrapUnwrapper u(kScipMillis);
  EXPECT_EQ(u.unwrap(1000), 1000);
  EXPECT_EQ(u.unwrap(990), 990);  // a repeated or late sample: back, not 4.66 h forward
  EXPECT_EQ(u.steps_back(), 1U);
  EXPECT_EQ(u.wraps(), 0U);
  EXPECT_EQ(u.unwrap((1U << 24) + 1000), 1000);  // wider than 24 bits: reduced and counted
  EXPECT_EQ(u.out_of_range(), 1U);
}

TEST(WrapUnwrapper, SeveralWrapsAccumulate) {
  WrapUnwrapper u(kScipMillis);
  std::uint64_t raw = 0;
  std::int64_t last = u.unwrap(raw);
  for (int i = 0; i < 4 * 100; ++i) {  // 4 wraps in steps of a quarter of the period minus a bit
    raw = (raw + (1U << 22) - 7) % (1U << 24);
    const std::int64_t v = u.unwrap(raw);
    ASSERT_EQ(v - last, (1 << 22) - 7);
    last = v;
  }
  EXPECT_GE(u.wraps(), 99U);
}

TEST(ClockParams, RejectsNonsense) {
  ClockParams p;
  EXPECT_TRUE(p.validate().empty());
  p.bucket_s = 0.0;
  EXPECT_FALSE(p.validate().empty());
  EXPECT_THROW(ClockModel{p}, std::invalid_argument);
  p = {};
  p.jump_confirm = 0;
  EXPECT_THROW(ClockModel{p}, std::invalid_argument);
}

// The synthetic sensor: true host time of a sample taken at sensor time s is offset + s * (1 + skew); it is
// received `delay` later, delay ~ Exp(mean tau).
struct Stream {
  double offset_s = 0.0;
  double skew = 0.0;
  double tau_s = 0.0;
  std::int64_t host_epoch_ns = 1'718'449'170'000'000'000LL;
  [[nodiscard]] std::int64_t truth_ns(std::int64_t sensor_ns) const {
    const double s = static_cast<double>(sensor_ns) * 1e-9;
    return host_epoch_ns + static_cast<std::int64_t>(std::llround((offset_s + s * skew) * 1e9)) + sensor_ns;
  }
};

struct FitResult {
  double max_abs_err_s = 0.0;
  double mean_err_s = 0.0;
  double skew = 0.0;
  double naive_mean_err_s = 0.0;  // host receive time taken as the sample time
};

FitResult run_fit(const Stream& st, double rate_hz, double seconds, double warmup_s, std::uint32_t seed,
                  const ClockParams& params = {}) {
  std::mt19937_64 rng(seed);
  std::exponential_distribution<double> delay(1.0 / st.tau_s);
  ClockModel m(params);
  FitResult r;
  double sum = 0.0;
  double naive = 0.0;
  int n = 0;
  const auto step = static_cast<std::int64_t>(std::llround(1e9 / rate_hz));
  for (std::int64_t s = 5'000'000'000; s < static_cast<std::int64_t>(seconds * 1e9); s += step) {
    const std::int64_t truth = st.truth_ns(s);
    const Stamp rx{truth + static_cast<std::int64_t>(std::llround(delay(rng) * 1e9))};
    const Mapping mp = m.observe(s, rx);
    EXPECT_FALSE(mp.suspect);
    if (static_cast<double>(s) * 1e-9 < warmup_s) continue;
    const double err = static_cast<double>(mp.mapped.ns - truth) * 1e-9;
    r.max_abs_err_s = std::max(r.max_abs_err_s, std::abs(err));
    sum += err;
    naive += static_cast<double>(rx.ns - truth) * 1e-9;
    ++n;
  }
  r.mean_err_s = sum / n;
  r.naive_mean_err_s = naive / n;
  r.skew = m.skew();
  EXPECT_EQ(m.jumps(), 0U);
  return r;
}

// Bound, AHRS-like stream (100 Hz, tau = 2 ms, 0.5 s buckets of m = 50 pairs, 40 buckets in the 20 s window).
// A bucket's minimum delay is Exp(tau/m); the lowest of them (the hull's vertices) are within
// dv = tau/m * ln(40) = 0.15 ms of the truth. The fitted line touches two vertices at least half the window
// apart (the edge over the window's mean), so its slope is off by at most 2 dv / 10 s, and the newest sample,
// up to 10 s past that edge, by at most dv + 2 dv = 0.45 ms. Receive times themselves are off by tau = 2 ms on
// average.
TEST(ClockModel, DriftOffsetAndExponentialJitterAhrsRate) {
  for (std::uint32_t seed : {1U, 2U, 3U, 4U}) {
    Stream st{0.75, 50e-6, 2e-3};
    const FitResult r = run_fit(st, 100.0, 120.0, 25.0, seed);
    SCOPED_TRACE(seed);
    EXPECT_LT(r.max_abs_err_s, 0.45e-3);
    EXPECT_LT(std::abs(r.mean_err_s), 0.15e-3);
    EXPECT_NEAR(r.skew, 50e-6, 10e-6);
    EXPECT_GT(r.naive_mean_err_s, 1.8e-3);  // what the receive time alone would give
    std::printf("seed %u: 100 Hz, tau 2 ms: max |err| %.3f ms, mean %.3f ms, skew %.2f ppm (naive mean %.3f ms)\n",
                seed, r.max_abs_err_s * 1e3, r.mean_err_s * 1e3, r.skew * 1e6, r.naive_mean_err_s * 1e3);
  }
}

// GNSS-like: 10 Hz, tau = 30 ms (serial NMEA after the epoch), m = 5 a bucket: dv = 30 ms / 5 * ln 40 = 22 ms,
// bound 3 dv = 66 ms; the receive time alone is off by 30 ms on average, the fit's mean must be well below.
TEST(ClockModel, DriftOffsetAndExponentialJitterGnssRate) {
  ClockParams p;
  p.jump_threshold_s = 0.5;
  for (std::uint32_t seed : {1U, 2U, 3U}) {
    Stream st{-3.2, -50e-6, 30e-3};
    const FitResult r = run_fit(st, 10.0, 200.0, 25.0, seed, p);
    SCOPED_TRACE(seed);
    EXPECT_LT(r.max_abs_err_s, 66e-3);
    EXPECT_LT(std::abs(r.mean_err_s), 10e-3);
    EXPECT_GT(r.naive_mean_err_s, 25e-3);
    std::printf("seed %u: 10 Hz, tau 30 ms: max |err| %.2f ms, mean %.2f ms, skew %.1f ppm\n", seed,
                r.max_abs_err_s * 1e3, r.mean_err_s * 1e3, r.skew * 1e6);
  }
}

TEST(ClockModel, OffsetOnlyUntilTheSpanAllowsASkew) {
  ClockModel m;
  EXPECT_FALSE(m.has_model());
  const Mapping first = m.observe(1'000'000'000, Stamp{5'000'000'000});
  EXPECT_FALSE(first.fitted);
  EXPECT_EQ(first.mapped.ns, 5'000'000'000);
  // A later pair with less delay lowers the envelope.
  const Mapping second = m.observe(1'100'000'000, Stamp{5'099'000'000});
  EXPECT_TRUE(second.fitted);
  EXPECT_EQ(second.mapped.ns, 5'099'000'000);
  EXPECT_EQ(m.map(1'000'000'000).ns, 4'999'000'000);
  EXPECT_DOUBLE_EQ(m.skew(), 0.0);
}

TEST(ClockModel, KnownLatencyIsSubtracted) {
  ClockParams p;
  p.latency_ns = 3'000'000;
  ClockModel m(p);
  const Mapping a = m.observe(0, Stamp{1'000'000'000});
  EXPECT_EQ(a.mapped.ns, 997'000'000);
  const Mapping b = m.observe(10'000'000, Stamp{1'010'000'000});
  EXPECT_FALSE(b.suspect);
  EXPECT_EQ(b.mapped.ns, 1'007'000'000);
}

// A GPS time correction: sensor time steps 1 s ahead at t = 40 s. Detected after jump_confirm samples, model
// re-seeded and counted; the samples in between are flagged and mapped from their receive time.
TEST(ClockModel, JumpIsDetectedAndTheModelReseeded) {
  std::mt19937_64 rng(7);
  std::exponential_distribution<double> delay(1.0 / 1e-3);
  ClockModel m;
  const Stream st{2.0, 50e-6, 1e-3};
  int suspects = 0;
  int jumped_at = -1;
  double worst_after = 0.0;
  for (int i = 0; i < 800; ++i) {  // 10 Hz, 80 s
    const std::int64_t s_true = 5'000'000'000LL + i * 100'000'000LL;
    const std::int64_t s_reported = s_true + (i >= 400 ? 1'000'000'000LL : 0);
    const std::int64_t truth = st.truth_ns(s_true);
    const Stamp rx{truth + static_cast<std::int64_t>(std::llround(delay(rng) * 1e9))};
    const Mapping mp = m.observe(s_reported, rx);
    if (mp.suspect) ++suspects;
    if (mp.jumped) jumped_at = i;
    if (i >= 420) worst_after = std::max(worst_after, std::abs(static_cast<double>(mp.mapped.ns - truth)) * 1e-9);
  }
  EXPECT_EQ(m.jumps(), 1U);
  EXPECT_EQ(jumped_at, 402);  // the third sample after the step confirms it
  EXPECT_EQ(suspects, 2);
  EXPECT_LT(worst_after, 1e-3);  // back to the truth (tau = 1 ms) after the re-seed
}

// One sample delayed by a host stall is suspect but does not move the model.
TEST(ClockModel, LoneHostStallIsNotAJump) {
  ClockModel m;
  for (int i = 0; i < 100; ++i) {
    const std::int64_t s = i * 10'000'000LL;
    const std::int64_t extra = i == 60 ? 200'000'000 : 0;
    const Mapping mp = m.observe(s, Stamp{1'000'000'000'000 + s + 500'000 + extra});
    EXPECT_EQ(mp.suspect, i == 60) << i;
    if (!mp.suspect) {
      EXPECT_EQ(mp.mapped.ns, 1'000'000'000'000 + s + 500'000) << i;
    }
  }
  EXPECT_EQ(m.jumps(), 0U);
}

// An Xsens reset: SampleTimeFine restarts from 0 while the host time goes on.
TEST(SensorClock, XsensCounterResetIsAJump) {
  SensorClock c(kXsensSampleTimeFine);
  std::uint64_t stf = 123'456'789;
  std::int64_t host = 2'000'000'000'000;
  for (int i = 0; i < 300; ++i, stf += 100, host += 10'000'000) {  // 100 Hz
    EXPECT_FALSE(c.observe_raw(stf, Stamp{host}).suspect);
  }
  stf = 0;
  int jumped = 0;
  for (int i = 0; i < 300; ++i, stf += 100, host += 10'000'000) {
    const Mapping mp = c.observe_raw(stf, Stamp{host});
    if (mp.jumped) ++jumped;
    if (i >= 3) {
      EXPECT_NEAR(static_cast<double>(mp.mapped.ns - host), 0.0, 1e3) << i;
    }
  }
  EXPECT_EQ(jumped, 1);
  EXPECT_EQ(c.model().jumps(), 1U);
}

// The Xsens counter wrapping while the stream runs is no jump: the mapping stays continuous.
TEST(SensorClock, XsensCounterWrapIsSeamless) {
  SensorClock c(kXsensSampleTimeFine);
  std::uint64_t stf = (1ULL << 32) - 100 * 3000;  // 30 s before the wrap
  std::int64_t host = 2'000'000'000'000;
  std::int64_t last = 0;
  for (int i = 0; i < 6000; ++i, host += 10'000'000) {  // 60 s at 100 Hz
    const Mapping mp = c.observe_raw(stf, Stamp{host + (i % 7) * 100'000});
    ASSERT_FALSE(mp.suspect) << i;
    if (i > 0) {
      EXPECT_NEAR(static_cast<double>(mp.mapped.ns - last), 1e7, 2e5) << i;
    }
    last = mp.mapped.ns;
    stf = (stf + 100) % (1ULL << 32);
  }
  EXPECT_EQ(c.unwrapper().wraps(), 1U);
  EXPECT_EQ(c.model().jumps(), 0U);
}

}  // namespace
}  // namespace fieldguard::sync
