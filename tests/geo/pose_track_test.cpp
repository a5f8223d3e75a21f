#include "fieldguard/geo/pose_track.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "fieldguard/geo/attitude.hpp"

namespace fieldguard::geo {
namespace {

constexpr std::int64_t kT0 = 1'718'449'170'000'000'000;  // 2024-06-15 10:59:30 UTC

Stamp at_ms(double ms) { return Stamp{kT0 + std::llround(ms * 1e6)}; }

TEST(PoseTrack, SlerpBetweenBracketingSamples) {
  PoseTrack track;
  ASSERT_TRUE(track.add_attitude(at_ms(0), quaternion_of({0.0, 0.0, 0.0})));
  ASSERT_TRUE(track.add_attitude(at_ms(10), quaternion_of({4.0, -2.0, 10.0})));
  ASSERT_TRUE(track.add_attitude(at_ms(20), quaternion_of({8.0, -4.0, 20.0})));
  // Halfway between two samples of a rotation about one fixed axis: exactly half the angle.
  const auto mid = track.attitude_at(at_ms(5));
  ASSERT_TRUE(mid.has_value());
  EXPECT_FALSE(mid->extrapolated);
  const Eigen::Quaterniond half = Eigen::Quaterniond::Identity().slerp(0.5, quaternion_of({4.0, -2.0, 10.0}));
  EXPECT_TRUE(mid->q.isApprox(half, 1e-12));
  // On a sample: the sample.
  const auto on = track.attitude_at(at_ms(10));
  ASSERT_TRUE(on.has_value());
  EXPECT_TRUE(on->q.isApprox(quaternion_of({4.0, -2.0, 10.0}), 1e-12));
  // A pure yaw sweep interpolates linearly in yaw.
  PoseTrack yaw;
  ASSERT_TRUE(yaw.add_attitude(at_ms(0), quaternion_of({0.0, 0.0, 170.0})));
  ASSERT_TRUE(yaw.add_attitude(at_ms(10), quaternion_of({0.0, 0.0, -170.0})));  // through 180, the short way
  const auto q = yaw.attitude_at(at_ms(2.5));
  ASSERT_TRUE(q.has_value());
  EXPECT_NEAR(euler_of(q->q).yaw_deg, 175.0, 1e-9);
}

TEST(PoseTrack, OutsideTheSamplesHeldThenRefused) {
  TrackParams p;
  p.max_attitude_extrapolation_s = 0.02;
  PoseTrack track(p);
  EXPECT_EQ(track.attitude_at(at_ms(0)).error(), TrackError::Empty);
  ASSERT_TRUE(track.add_attitude(at_ms(100), quaternion_of({1.0, 0.0, 0.0})));
  ASSERT_TRUE(track.add_attitude(at_ms(110), quaternion_of({2.0, 0.0, 0.0})));
  const auto before = track.attitude_at(at_ms(85));
  ASSERT_TRUE(before.has_value());
  EXPECT_TRUE(before->extrapolated);
  EXPECT_NEAR(euler_of(before->q).roll_deg, 1.0, 1e-9);
  EXPECT_EQ(track.attitude_at(at_ms(79)).error(), TrackError::BeforeStart);
  const auto after = track.attitude_at(at_ms(129));
  ASSERT_TRUE(after.has_value());
  EXPECT_TRUE(after->extrapolated);
  EXPECT_NEAR(euler_of(after->q).roll_deg, 2.0, 1e-9);
  EXPECT_EQ(track.attitude_at(at_ms(131)).error(), TrackError::AfterEnd);
}

TEST(PoseTrack, GapIsRefusedNotInterpolated) {
  PoseTrack track;  // max_attitude_gap_s 0.05
  ASSERT_TRUE(track.add_attitude(at_ms(0), quaternion_of({0.0, 0.0, 0.0})));
  ASSERT_TRUE(track.add_attitude(at_ms(50), quaternion_of({1.0, 0.0, 0.0})));   // exactly the limit: fine
  ASSERT_TRUE(track.add_attitude(at_ms(120), quaternion_of({9.0, 0.0, 0.0})));  // 70 ms later: a dropout
  EXPECT_TRUE(track.attitude_at(at_ms(25)).has_value());
  EXPECT_EQ(track.attitude_at(at_ms(60)).error(), TrackError::Gap);
  EXPECT_EQ(track.pose_at(at_ms(25)).error(), TrackError::Empty);  // no position yet
}

TEST(PoseTrack, RejectsOutOfOrderAndNonFiniteSamples) {
  PoseTrack track;
  ASSERT_TRUE(track.add_attitude(at_ms(10), Eigen::Quaterniond::Identity()));
  EXPECT_FALSE(track.add_attitude(at_ms(10), Eigen::Quaterniond::Identity()));  // duplicate time
  EXPECT_FALSE(track.add_attitude(at_ms(5), Eigen::Quaterniond::Identity()));
  EXPECT_FALSE(track.add_attitude(at_ms(20), Eigen::Quaterniond(std::numeric_limits<double>::quiet_NaN(), 0, 0, 0)));
  EXPECT_FALSE(track.add_attitude(at_ms(20), Eigen::Quaterniond(0, 0, 0, 0)));  // not a rotation
  ASSERT_TRUE(track.add_position(at_ms(10), {1.0, 2.0, 3.0}));
  EXPECT_FALSE(track.add_position(at_ms(9), {1.0, 2.0, 3.0}));
  EXPECT_FALSE(track.add_position(at_ms(20), {1.0, std::numeric_limits<double>::infinity(), 3.0}));
  EXPECT_EQ(track.rejected_out_of_order(), 3U);
  EXPECT_EQ(track.rejected_not_finite(), 3U);
  EXPECT_EQ(track.attitude_count(), 1U);
  EXPECT_EQ(track.position_count(), 1U);
  // A non-unit quaternion is normalised on the way in.
  ASSERT_TRUE(track.add_attitude(at_ms(20), Eigen::Quaterniond(2.0, 0.0, 0.0, 0.0)));
  EXPECT_NEAR(track.attitude_at(at_ms(20))->q.norm(), 1.0, 1e-15);
}

TEST(PoseTrack, PositionLinearAndContinuedAtTheLastVelocity) {
  PoseTrack track;  // position gap 0.5 s, extrapolation 0.25 s
  ASSERT_TRUE(track.add_position(at_ms(0), {100.0, 200.0, 10.0}));
  EXPECT_TRUE(track.position_at(at_ms(100))->extrapolated);  // one fix: held
  EXPECT_EQ(track.position_at(at_ms(100))->p, Eigen::Vector3d(100.0, 200.0, 10.0));
  ASSERT_TRUE(track.add_position(at_ms(200), {102.0, 201.0, 10.2}));  // 10 m/s east, 5 m/s north
  const auto mid = track.position_at(at_ms(50));
  ASSERT_TRUE(mid.has_value());
  EXPECT_FALSE(mid->extrapolated);
  EXPECT_NEAR((mid->p - Eigen::Vector3d(100.5, 200.25, 10.05)).norm(), 0.0, 1e-9);
  const auto ahead = track.position_at(at_ms(300));
  ASSERT_TRUE(ahead.has_value());
  EXPECT_TRUE(ahead->extrapolated);
  EXPECT_NEAR((ahead->p - Eigen::Vector3d(103.0, 201.5, 10.3)).norm(), 0.0, 1e-9);
  const auto behind = track.position_at(at_ms(-100));
  ASSERT_TRUE(behind.has_value());
  EXPECT_NEAR((behind->p - Eigen::Vector3d(99.0, 199.5, 9.9)).norm(), 0.0, 1e-9);
  EXPECT_EQ(track.position_at(at_ms(451)).error(), TrackError::AfterEnd);
  EXPECT_EQ(track.position_at(at_ms(-251)).error(), TrackError::BeforeStart);
  ASSERT_TRUE(track.add_position(at_ms(800), {110.0, 201.0, 10.0}));  // 600 ms later: a gap
  EXPECT_EQ(track.position_at(at_ms(500)).error(), TrackError::Gap);
}

TEST(PoseTrack, BoundedAndTrimmable) {
  TrackParams p;
  p.max_samples = 10;
  PoseTrack track(p);
  for (int i = 0; i < 25; ++i) ASSERT_TRUE(track.add_attitude(at_ms(10.0 * i), Eigen::Quaterniond::Identity()));
  EXPECT_EQ(track.attitude_count(), 10U);
  EXPECT_EQ(track.attitude_at(at_ms(100)).error(), TrackError::BeforeStart);  // the oldest went first
  track.drop_before(at_ms(205));
  EXPECT_EQ(track.attitude_count(), 5U);  // 200 (the one before 205) .. 240
  EXPECT_TRUE(track.attitude_at(at_ms(205)).has_value());
}

TEST(PoseTrack, InvalidParameters) {
  TrackParams p;
  p.max_attitude_gap_s = 0.0;
  p.max_position_extrapolation_s = -1.0;
  p.max_samples = 1;
  EXPECT_EQ(p.validate().size(), 3U);
  EXPECT_THROW(PoseTrack{p}, std::invalid_argument);
  EXPECT_TRUE(TrackParams{}.validate().empty());
  EXPECT_STREQ(to_string(TrackError::Gap), "gap");
}

}  // namespace
}  // namespace fieldguard::geo
