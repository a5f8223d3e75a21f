// GNSS and AHRS plausibility for the stop decision.

#include "fieldguard/output/plausibility.hpp"

#include <gtest/gtest.h>

#include <limits>

namespace fieldguard::output::safety {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kT0 = 1'718'449'170'000'000'000;

GnssFix rtk(std::int64_t t_ms, double lat = 52.0, double lon = 10.0) {
  GnssFix f;
  f.sensor = Stamp{kT0 + t_ms * kMs};
  f.quality = 4;
  f.satellites = 14;
  f.hdop = 0.8;
  f.lat_deg = lat;
  f.lon_deg = lon;
  return f;
}

Attitude att(std::int64_t t_ms, double roll, double pitch, double yaw) {
  return Attitude{Stamp{kT0 + t_ms * kMs}, roll, pitch, yaw};
}

TEST(GnssPlausibility, AGoodRtkFixPasses) {
  GnssCheck c(GnssLimits{});
  EXPECT_EQ(c.check(rtk(0)), Problem::None);
  EXPECT_EQ(c.check(rtk(100, 52.000001)), Problem::None);  // 0.11 m in 0.1 s
  EXPECT_EQ(c.take(), Problem::None);
}

TEST(GnssPlausibility, EachProblemIsNamed) {
  const GnssLimits lim;
  auto one = [&](GnssFix f) { return GnssCheck(lim).check(f); };
  GnssFix f = rtk(0);
  f.quality.reset();
  EXPECT_EQ(one(f), Problem::NoFix);
  f.quality = 0;
  EXPECT_EQ(one(f), Problem::NoFix);
  f.quality = 1;  // plain GPS is not accepted by the default [4, 5]
  EXPECT_EQ(one(f), Problem::FixNotAccepted);
  f.quality = 6;  // dead reckoning
  EXPECT_EQ(one(f), Problem::FixNotAccepted);
  f.quality = 5;
  EXPECT_EQ(one(f), Problem::None);
  f.satellites = 3;
  EXPECT_EQ(one(f), Problem::TooFewSatellites);
  f.satellites.reset();
  EXPECT_EQ(one(f), Problem::TooFewSatellites);
  f.satellites = 9;
  f.hdop = 7.5;
  EXPECT_EQ(one(f), Problem::HdopTooHigh);
  f.hdop = 1.0;
  f.lat_deg = 95.0;
  EXPECT_EQ(one(f), Problem::OutOfRange);
}

TEST(GnssPlausibility, NaNAnywhereIsNotFinite) {
  const GnssLimits lim;
  GnssFix f = rtk(0);
  f.lat_deg = kNaN;
  EXPECT_EQ(GnssCheck(lim).check(f), Problem::NotFinite);
  f = rtk(0);
  f.lon_deg = std::numeric_limits<double>::infinity();
  EXPECT_EQ(GnssCheck(lim).check(f), Problem::NotFinite);
  f = rtk(0);
  f.hdop = kNaN;
  EXPECT_EQ(GnssCheck(lim).check(f), Problem::NotFinite);
}

TEST(GnssPlausibility, AJumpFasterThanATractorIsReportedOnce) {
  GnssCheck c(GnssLimits{});  // 20 m/s
  EXPECT_EQ(c.check(rtk(0)), Problem::None);
  // 0.0001 degree of latitude is 11.1 m: in 0.1 s that is 111 m/s.
  EXPECT_EQ(c.check(rtk(100, 52.0001)), Problem::PositionJump);
  EXPECT_EQ(c.check(rtk(200, 52.0001)), Problem::None);  // compared with the jumped fix from now on
  // The same 11 m over a second is 11 m/s: a fast road run, plausible.
  EXPECT_EQ(c.check(rtk(1200, 52.0002)), Problem::None);
}

TEST(GnssPlausibility, TimeGoingBackIsAProblemAndARepeatIsNot) {
  GnssCheck c(GnssLimits{});
  EXPECT_EQ(c.check(rtk(1000)), Problem::None);
  EXPECT_EQ(c.check(rtk(1000)), Problem::None);
  EXPECT_EQ(c.check(rtk(900)), Problem::TimeWentBack);
  EXPECT_EQ(c.check(rtk(1100)), Problem::None);
}

TEST(GnssPlausibility, TakeKeepsTheFirstProblemUntilTaken) {
  GnssCheck c(GnssLimits{});
  GnssFix bad = rtk(0);
  bad.quality = 0;
  c.check(bad);
  c.check(rtk(100));
  bad.hdop = 9.0;
  bad.quality = 4;
  c.check(bad);
  EXPECT_EQ(c.take(), Problem::NoFix);  // a single bad fix between frames still reaches the monitor
  EXPECT_EQ(c.take(), Problem::None);
}

TEST(AhrsPlausibility, LevelAndSlowPasses) {
  AhrsCheck c(AhrsLimits{});
  EXPECT_EQ(c.check(att(0, 2.0, -3.0, 90.0)), Problem::None);
  EXPECT_EQ(c.check(att(10, 2.5, -3.1, 90.5)), Problem::None);  // 50 deg/s
}

TEST(AhrsPlausibility, BeyondLimitsAndNaN) {
  const AhrsLimits lim;  // 30 degrees
  EXPECT_EQ(AhrsCheck(lim).check(att(0, 31.0, 0.0, 0.0)), Problem::RollBeyondLimit);
  EXPECT_EQ(AhrsCheck(lim).check(att(0, -31.0, 0.0, 0.0)), Problem::RollBeyondLimit);
  EXPECT_EQ(AhrsCheck(lim).check(att(0, 0.0, 35.0, 0.0)), Problem::PitchBeyondLimit);
  EXPECT_EQ(AhrsCheck(lim).check(att(0, kNaN, 0.0, 0.0)), Problem::NotFinite);
  EXPECT_EQ(AhrsCheck(lim).check(att(0, 0.0, 0.0, kNaN)), Problem::NotFinite);
  EXPECT_EQ(AhrsCheck(lim).check(att(0, 0.0, 95.0, 0.0)), Problem::OutOfRange);
}

TEST(AhrsPlausibility, TurningFasterThanPhysicalIsAJump) {
  AhrsCheck c(AhrsLimits{});  // 180 deg/s
  EXPECT_EQ(c.check(att(0, 0.0, 0.0, 10.0)), Problem::None);
  EXPECT_EQ(c.check(att(10, 5.0, 0.0, 10.0)), Problem::AttitudeJump);  // 500 deg/s of roll
  EXPECT_EQ(c.check(att(20, 5.0, 0.0, 10.0)), Problem::None);
  EXPECT_EQ(c.check(att(30, 5.0, 0.0, 14.0)), Problem::AttitudeJump);  // 400 deg/s of yaw
}

TEST(AhrsPlausibility, YawAcrossPlusMinus180IsNoJump) {
  AhrsCheck c(AhrsLimits{});
  EXPECT_EQ(c.check(att(0, 0.0, 0.0, 179.5)), Problem::None);
  EXPECT_EQ(c.check(att(10, 0.0, 0.0, -179.5)), Problem::None);  // 1 degree in 10 ms = 100 deg/s
}

TEST(AhrsPlausibility, ANaNSampleDoesNotPoisonTheNextComparison) {
  AhrsCheck c(AhrsLimits{});
  EXPECT_EQ(c.check(att(0, 1.0, 1.0, 1.0)), Problem::None);
  EXPECT_EQ(c.check(att(10, kNaN, 1.0, 1.0)), Problem::NotFinite);
  EXPECT_EQ(c.check(att(20, 1.2, 1.0, 1.0)), Problem::None);
  EXPECT_EQ(c.take(), Problem::NotFinite);
  EXPECT_EQ(to_string(Problem::AttitudeJump), "attitude jump");
}

}  // namespace
}  // namespace fieldguard::output::safety
