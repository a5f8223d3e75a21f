#include "fieldguard/geo/attitude.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>

namespace fieldguard::geo {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

void expect_near(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tol) {
  EXPECT_NEAR(a.x(), b.x(), tol) << a.transpose() << " vs " << b.transpose();
  EXPECT_NEAR(a.y(), b.y(), tol) << a.transpose() << " vs " << b.transpose();
  EXPECT_NEAR(a.z(), b.z(), tol) << a.transpose() << " vs " << b.transpose();
}

TEST(Attitude, RotationIsYawPitchRollAboutFixedAxesInThatOrder) {
  const double r = 0.1;
  const double p = -0.2;
  const double y = 0.7;
  Eigen::Matrix3d rx;
  rx << 1, 0, 0, 0, std::cos(r), -std::sin(r), 0, std::sin(r), std::cos(r);
  Eigen::Matrix3d ry;
  ry << std::cos(p), 0, std::sin(p), 0, 1, 0, -std::sin(p), 0, std::cos(p);
  Eigen::Matrix3d rz;
  rz << std::cos(y), -std::sin(y), 0, std::sin(y), std::cos(y), 0, 0, 0, 1;
  EXPECT_TRUE(rotation_rpy(r, p, y).isApprox(rz * ry * rx, 1e-12));
  EXPECT_TRUE(quaternion_of({r / kDeg, p / kDeg, y / kDeg}).toRotationMatrix().isApprox(rz * ry * rx, 1e-12));
}

TEST(Attitude, SignConventionsInTheVehicleFrame) {
  // Positive roll lowers the right side (-y): the left-pointing axis rises.
  expect_near(quaternion_of({10.0, 0.0, 0.0}) * Eigen::Vector3d::UnitY(),
              {0.0, std::cos(10 * kDeg), std::sin(10 * kDeg)}, 1e-12);
  // Positive pitch lowers the nose.
  expect_near(quaternion_of({0.0, 5.0, 0.0}) * Eigen::Vector3d::UnitX(), {std::cos(5 * kDeg), 0.0, -std::sin(5 * kDeg)},
              1e-12);
  // Xsens ENU: yaw 90 deg = x axis pointing north (MTi User Manual table "yaw value ... ENU ... 90 deg").
  expect_near(quaternion_of({0.0, 0.0, 90.0}) * Eigen::Vector3d::UnitX(), {0.0, 1.0, 0.0}, 1e-12);
  EXPECT_DOUBLE_EQ(yaw_from_heading_deg(0.0), 90.0);  // heading north
  EXPECT_DOUBLE_EQ(yaw_from_heading_deg(90.0), 0.0);  // heading east
  EXPECT_DOUBLE_EQ(yaw_from_heading_deg(180.0), -90.0);
}

TEST(Attitude, EulerRoundTrip) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-179.0, 179.0);
  std::uniform_real_distribution<double> pitch(-85.0, 85.0);
  for (int i = 0; i < 1000; ++i) {
    const EulerDeg e{angle(rng), pitch(rng), angle(rng)};
    const EulerDeg back = euler_of(quaternion_of(e));
    ASSERT_NEAR(back.roll_deg, e.roll_deg, 1e-9);
    ASSERT_NEAR(back.pitch_deg, e.pitch_deg, 1e-9);
    ASSERT_NEAR(back.yaw_deg, e.yaw_deg, 1e-9);
  }
}

TEST(Attitude, NedOutputConvertsToEnu) {
  // R_enu<-flu must equal T R_ned<-frd D with T the NED->ENU axis swap and D the FLU->FRD body flip.
  Eigen::Matrix3d t;
  t << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  const Eigen::Matrix3d d = Eigen::Vector3d(1, -1, -1).asDiagonal();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-170.0, 170.0);
  std::uniform_real_distribution<double> pitch(-80.0, 80.0);
  for (int i = 0; i < 200; ++i) {
    const EulerDeg ned{angle(rng), pitch(rng), angle(rng)};
    const Eigen::Matrix3d expected = t * quaternion_of(ned).toRotationMatrix() * d;
    ASSERT_TRUE(quaternion_of(enu_from_ned(ned)).toRotationMatrix().isApprox(expected, 1e-12));
  }
  // NED heading 30 deg (north-north-east), nose up 2 deg, right side down 3 deg:
  const EulerDeg enu = enu_from_ned({3.0, 2.0, 30.0});
  EXPECT_DOUBLE_EQ(enu.roll_deg, 3.0);
  EXPECT_DOUBLE_EQ(enu.pitch_deg, -2.0);
  EXPECT_DOUBLE_EQ(enu.yaw_deg, 60.0);
}

TEST(LeverArm, TwoMetreAntennaAtTenDegreesRollShiftsThirtyFiveCentimetres) {
  // Antenna 2 m above the reference point, vehicle heading north (yaw 90), right side 10 deg down: the
  // antenna leans 2 sin(10 deg) = 0.347 m to the right, i.e. east; the reference point is that far west of it
  // and 2 - 2 cos(10 deg) = 0.030 m less deep below it than when level.
  const Eigen::Quaterniond q = quaternion_of({10.0, 0.0, 90.0});
  const Eigen::Vector3d antenna(448688.0, 4418598.0, 52.0);
  const Eigen::Vector3d ref = reference_from_antenna(antenna, q, {0.0, 0.0, 2.0});
  const Eigen::Vector3d shift = antenna - ref;
  EXPECT_NEAR(shift.x(), 0.3473, 1e-4);
  EXPECT_NEAR(shift.y(), 0.0, 1e-9);
  EXPECT_NEAR(shift.z(), 1.9696, 1e-4);
  // Level, the lever arm is a plain vertical offset.
  expect_near(reference_from_antenna(antenna, quaternion_of({0.0, 0.0, 90.0}), {0.0, 0.0, 2.0}),
              antenna - Eigen::Vector3d(0.0, 0.0, 2.0), 1e-9);
}

TEST(LeverArm, AntennaForwardAndHighWhilePitchedAndTurned) {
  // Antenna 1.2 m ahead of the rear axle, 2.8 m up; nose 6 deg down, heading 30 deg east of north
  // (ENU yaw 60). Hand computation: pitched, the arm is (1.2 cos6 + 2.8 sin6, 0, -1.2 sin6 + 2.8 cos6) =
  // (1.4861, 0, 2.6593) in the level heading frame; turned to yaw 60: east 1.4861 cos60 = 0.7430,
  // north 1.4861 sin60 = 1.2870.
  const Eigen::Quaterniond q = quaternion_of({0.0, 6.0, 60.0});
  const Eigen::Vector3d arm = q * Eigen::Vector3d(1.2, 0.0, 2.8);
  EXPECT_NEAR(arm.x(), 0.7430, 1e-4);
  EXPECT_NEAR(arm.y(), 1.2870, 1e-4);
  EXPECT_NEAR(arm.z(), 2.6593, 1e-4);
}

TEST(AttitudeModel, MountingDeclinationAndConvergence) {
  // AHRS mounted backwards (yaw 180 on the vehicle): vehicle heading north with its right side 5 deg
  // down reads, on the AHRS, yaw 270 (its x points south) and roll -5.
  AhrsParams p;
  p.mounting.yaw_deg = 180.0;
  const AttitudeModel m(p);
  EulerDeg v = euler_of(m.vehicle_in_plane({-5.0, 0.0, -90.0}, 0.0));
  EXPECT_NEAR(v.roll_deg, 5.0, 1e-9);
  EXPECT_NEAR(v.pitch_deg, 0.0, 1e-9);
  EXPECT_NEAR(v.yaw_deg, 90.0, 1e-9);

  // Magnetic reference with 6 deg east declination and the grid at -0.385 deg convergence (west of the
  // central meridian): the AHRS says magnetic north (yaw 90). True heading 6 deg, grid heading 6.385 deg,
  // so grid ENU yaw 83.615 deg.
  AhrsParams d;
  d.declination_deg = 6.0;
  v = euler_of(AttitudeModel(d).vehicle_in_plane({0.0, 0.0, 90.0}, -0.385));
  EXPECT_NEAR(v.yaw_deg, 83.615, 1e-9);

  // An AHRS configured for NED output.
  AhrsParams n;
  n.frame = AhrsFrame::Ned;
  v = euler_of(AttitudeModel(n).vehicle_in_plane({3.0, 2.0, 30.0}, 0.0));
  EXPECT_NEAR(v.roll_deg, 3.0, 1e-9);
  EXPECT_NEAR(v.pitch_deg, -2.0, 1e-9);
  EXPECT_NEAR(v.yaw_deg, 60.0, 1e-9);
}

TEST(AttitudeModel, MountingTiltIsRemoved) {
  // AHRS bolted on with 2 deg pitch and -1 deg roll relative to the vehicle: a level vehicle reads that tilt.
  AhrsParams p;
  p.mounting.roll_deg = -1.0;
  p.mounting.pitch_deg = 2.0;
  const AttitudeModel m(p);
  const EulerDeg ahrs = euler_of(quaternion_of({0.0, 0.0, 40.0}) * quaternion_of({-1.0, 2.0, 0.0}));
  const EulerDeg v = euler_of(m.vehicle_in_plane(ahrs, 0.0));
  EXPECT_NEAR(v.roll_deg, 0.0, 1e-9);
  EXPECT_NEAR(v.pitch_deg, 0.0, 1e-9);
  EXPECT_NEAR(v.yaw_deg, 40.0, 1e-9);
}

TEST(AttitudeModel, InvalidParameters) {
  AhrsParams p;
  p.mounting.pitch_deg = 95.0;
  p.declination_deg = std::nan("");
  EXPECT_EQ(p.validate().size(), 2U);
  EXPECT_THROW(AttitudeModel{p}, std::invalid_argument);
  p = {};
  p.mounting.x_m = std::numeric_limits<double>::infinity();
  EXPECT_EQ(p.validate().size(), 1U);
  EXPECT_TRUE(AhrsParams{}.validate().empty());
}

TEST(Attitude, TransformOfMounting) {
  Mounting m;
  m.x_m = 1.0;
  m.z_m = 2.0;
  m.yaw_deg = 90.0;
  // The sensor's x axis points left on the vehicle.
  expect_near(transform_of(m) * Eigen::Vector3d(1.0, 0.0, 0.0), {1.0, 1.0, 2.0}, 1e-12);
  EXPECT_NEAR(horizontal_yaw_rad(quaternion_of({8.0, -7.0, 33.0})), 33.0 * kDeg, 1e-12);
}

}  // namespace
}  // namespace fieldguard::geo
