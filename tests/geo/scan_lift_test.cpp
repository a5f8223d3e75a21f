#include "fieldguard/geo/scan_lift.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "fieldguard/geo/attitude.hpp"

namespace fieldguard::geo {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A UTM-30LX-EW scan (steps 0..1080, 0.25 deg, front 540) of a vertical wall at vehicle x = wall_x, the
// scanner at `scanner` in the vehicle frame. Rays that never reach the wall read error code 1.
scip::Scan wall_scan(const Mounting& scanner, double wall_x) {
  const Eigen::Isometry3d ts = transform_of(scanner);
  scip::Scan scan;
  scan.command = scip::Command::ME;
  scan.first_step = 0;
  scan.last_step = 1080;
  for (int step = 0; step <= 1080; ++step) {
    const double a = (step - 540) * 0.25 * kDeg;
    const Eigen::Vector3d d = ts.linear() * Eigen::Vector3d(std::cos(a), std::sin(a), 0.0);
    std::uint32_t mm = 1;
    if (d.x() > 0.05) {
      const double r = (wall_x - ts.translation().x()) / d.x();
      if (r < 30.0) mm = static_cast<std::uint32_t>(std::lround(r * 1000.0));
    }
    scan.ranges_mm.push_back(mm);
    scan.intensities.push_back(static_cast<std::uint32_t>(step));
  }
  return scan;
}

TEST(ScanLift, WallOneMetreAheadOfATiltedScanner) {
  // Scanner on the front weight 2.0 m ahead of the rear axle, 0.6 m up, tilted 10 deg down; wall 1 m
  // ahead of it. Each ray meets the wall 1 m ahead, having dropped tan(10 deg) = 0.1763 m: the scan line
  // is horizontal at 0.6 - 0.1763 = 0.4237 m, whatever the step. Straight ahead the range is
  // 1 / cos(10 deg) = 1.0154 m.
  Mounting scanner;
  scanner.x_m = 2.0;
  scanner.z_m = 0.6;
  scanner.pitch_deg = 10.0;
  const scip::Scan scan = wall_scan(scanner, 3.0);
  EXPECT_EQ(scan.ranges_mm[540], 1015U);

  ScanLiftParams p;
  p.scanner = scanner;  // output in the vehicle frame: the 3D LiDAR at the origin, unrotated
  const ScanLifter lifter(p);
  std::vector<SourcedPoint> out;
  const ScanLiftStats s = lifter.lift(scan, scip::Geometry{}, 0.05F, out);
  EXPECT_EQ(s.values, 1081U);
  EXPECT_EQ(s.lifted + s.out_of_range, 1081U);
  EXPECT_GT(s.lifted, 600U);        // about +-80 deg of the 270 deg reach the wall within 30 m ...
  EXPECT_GT(s.out_of_range, 300U);  // ... the rest read error codes
  ASSERT_EQ(out.size(), s.lifted);
  for (const auto& pt : out) {
    // Ranges are whole millimetres: half a millimetre along the ray at most.
    ASSERT_NEAR(static_cast<double>(pt.x), 3.0, 1e-3) << "step " << pt.channel;
    ASSERT_NEAR(static_cast<double>(pt.z), 0.4237, 1e-3) << "step " << pt.channel;
    const double a = (pt.channel - 540) * 0.25 * kDeg;
    ASSERT_NEAR(static_cast<double>(pt.y), std::tan(a) / std::cos(10.0 * kDeg), 2e-3) << "step " << pt.channel;
    ASSERT_EQ(pt.source, PointSource::Lidar2d);
    ASSERT_EQ(pt.intensity, static_cast<float>(pt.channel));
    // 25 ms a turn of 1440 steps, after the scan's first step, plus the offset given.
    ASSERT_NEAR(static_cast<double>(pt.time_s), 0.05 + pt.channel * 0.025 / 1440.0, 1e-6);
  }
  // Straight ahead: (3.000, 0, 0.4237).
  const auto front = std::find_if(out.begin(), out.end(), [](const SourcedPoint& q) { return q.channel == 540; });
  ASSERT_NE(front, out.end());
  EXPECT_NEAR(static_cast<double>(front->y), 0.0, 1e-6);
}

TEST(ScanLift, IntoTheThreeDLidarFrame) {
  // Same wall; the output frame is now the 3D LiDAR's at (1.8, 0, 2.2) pitched 1 deg down. The front point
  // (3.000, 0, 0.4237) in the vehicle frame is (1.2, 0, -1.7763) from the LiDAR; undoing its 1 deg pitch
  // with Ry(1)^T: x = 1.2 cos1 + 1.7763 sin1 = 1.2308, z = 1.2 sin1 - 1.7763 cos1 = -1.7551.
  Mounting scanner;
  scanner.x_m = 2.0;
  scanner.z_m = 0.6;
  scanner.pitch_deg = 10.0;
  Mounting lidar;
  lidar.x_m = 1.8;
  lidar.z_m = 2.2;
  lidar.pitch_deg = 1.0;
  const scip::Scan scan = wall_scan(scanner, 3.0);
  ScanLiftParams p;
  p.scanner = scanner;
  p.lidar = lidar;
  std::vector<SourcedPoint> out;
  (void)ScanLifter(p).lift(scan, scip::Geometry{}, 0.0F, out);
  const auto front = std::find_if(out.begin(), out.end(), [](const SourcedPoint& q) { return q.channel == 540; });
  ASSERT_NE(front, out.end());
  EXPECT_NEAR(static_cast<double>(front->x), 1.2308, 1e-3);
  EXPECT_NEAR(static_cast<double>(front->y), 0.0, 1e-6);
  EXPECT_NEAR(static_cast<double>(front->z), -1.7551, 1e-3);
  // Every point, back in the vehicle frame, is on the wall.
  const Eigen::Isometry3d tl = transform_of(lidar);
  for (const auto& pt : out) {
    const Eigen::Vector3d v =
        tl * Eigen::Vector3d(static_cast<double>(pt.x), static_cast<double>(pt.y), static_cast<double>(pt.z));
    ASSERT_NEAR(v.x(), 3.0, 1e-3);
    ASSERT_NEAR(v.z(), 0.4237, 1e-3);
  }
}

TEST(ScanLift, ScannerTurnedAndClusteredSteps) {
  // A scanner facing left (yaw 90) with 3-step clusters: step_of(i) = first + 3 i and the angle follows.
  Mounting scanner;
  scanner.yaw_deg = 90.0;
  scip::Scan scan;
  scan.first_step = 540;
  scan.last_step = 545;
  scan.cluster = 3;
  scan.ranges_mm = {2000, 2000};
  ScanLiftParams p;
  p.scanner = scanner;
  std::vector<SourcedPoint> out;
  const ScanLiftStats s = ScanLifter(p).lift(scan, scip::Geometry{}, 0.0F, out);
  ASSERT_EQ(s.lifted, 2U);
  EXPECT_NEAR(static_cast<double>(out[0].x), 0.0, 1e-6);  // the scanner's front is the vehicle's left
  EXPECT_NEAR(static_cast<double>(out[0].y), 2.0, 1e-6);
  EXPECT_EQ(out[1].channel, 543);
  EXPECT_NEAR(static_cast<double>(out[1].x), -2.0 * std::sin(0.75 * kDeg), 1e-6);
  EXPECT_EQ(out[0].intensity, 0.F);  // MD scan: no intensities
}

TEST(ScanLift, ErrorCodesAndOverRangeAreNotPoints) {
  scip::Scan scan;
  scan.first_step = 0;
  scan.last_step = 3;
  scan.ranges_mm = {0, 22, 60001, 23};
  std::vector<SourcedPoint> out;
  const ScanLiftStats s = ScanLifter(ScanLiftParams{}).lift(scan, scip::Geometry{}, 0.0F, out);
  EXPECT_EQ(s.out_of_range, 3U);
  EXPECT_EQ(s.lifted, 1U);
}

TEST(ScanLift, InvalidParameters) {
  ScanLiftParams p;
  p.turn_period_s = 0.0;
  p.scanner.roll_deg = std::numeric_limits<double>::quiet_NaN();
  p.lidar.z_m = std::numeric_limits<double>::infinity();
  EXPECT_EQ(p.validate().size(), 3U);
  EXPECT_THROW(ScanLifter{p}, std::invalid_argument);
  EXPECT_TRUE(ScanLiftParams{}.validate().empty());
}

}  // namespace
}  // namespace fieldguard::geo
