#include "fieldguard/geo/frame_compensator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace fieldguard::geo {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr std::int64_t kT0 = 1'718'449'170'000'000'000;  // 2024-06-15 10:59:30 UTC
constexpr int kZone = 39;                                // 3-degree zone of CM 117 E (Beijing)
constexpr double kGeoidSep = -8.5;

Stamp at_s(double s) { return Stamp{kT0 + std::llround(s * 1e9)}; }

CompensationParams base_params() {
  CompensationParams p;
  p.lidar.x_m = 1.8;
  p.lidar.z_m = 2.2;
  p.lidar.pitch_deg = 1.0;
  p.scanner.x_m = 3.0;
  p.scanner.z_m = 0.6;
  p.antenna_m = Eigen::Vector3d(0.0, 0.0, 2.8);
  return p;
}

// The tractor's true pose in the plane (grid) frame: constant attitude, straight line at constant speed.
struct Truth {
  Eigen::Vector3d start{448688.0, 4418598.0, 45.0};  // reference point at t = 0; ~0.6 deg west of the CM
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double yaw_grid_deg = 30.0;
  double speed_mps = 0.0;
  [[nodiscard]] Eigen::Quaterniond q() const { return quaternion_of({roll_deg, pitch_deg, yaw_grid_deg}); }
  [[nodiscard]] Eigen::Vector3d p(double t) const {
    return start + speed_mps * t * Eigen::Vector3d(std::cos(yaw_grid_deg * kDeg), std::sin(yaw_grid_deg * kDeg), 0.0);
  }
  // A world (plane frame) point as the 3D LiDAR sees it at t.
  [[nodiscard]] LidarPoint seen(const Eigen::Vector3d& w, double t, const Mounting& lidar) const {
    const Eigen::Isometry3d tl = transform_of(lidar);
    const Eigen::Vector3d v = tl.inverse() * (q().conjugate() * (w - p(t)));
    LidarPoint lp;
    lp.x = static_cast<float>(v.x());
    lp.y = static_cast<float>(v.y());
    lp.z = static_cast<float>(v.z());
    lp.time_s = static_cast<float>(t);
    lp.range_m = static_cast<float>(v.norm());
    return lp;
  }
  // Where a world point should come out: the detection frame of t_ref.
  [[nodiscard]] Eigen::Vector3d expected(const Eigen::Vector3d& w, double t_ref, const Mounting& lidar) const {
    const double yaw = horizontal_yaw_rad(q());
    return Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()) * (w - p(t_ref)) -
           Eigen::Vector3d(lidar.x_m, lidar.y_m, lidar.z_m);
  }
};

double convergence_at(const Eigen::Vector3d& plane) {
  const GaussKrueger gk(ProjectionParams{});
  PlaneCoord pc;
  pc.easting_m = plane.x();
  pc.northing_m = plane.y();
  pc.up_m = plane.z();
  pc.zone = kZone;
  auto g = gk.reverse(pc);
  EXPECT_TRUE(g.has_value());
  return g ? gk.forward(*g)->convergence_deg : 0.0;
}

sync::TimedGnss gga_at(const Eigen::Vector3d& antenna_plane, double t, int quality) {
  const GaussKrueger gk(ProjectionParams{});
  PlaneCoord pc;
  pc.easting_m = antenna_plane.x();
  pc.northing_m = antenna_plane.y();
  pc.up_m = antenna_plane.z();
  pc.zone = kZone;
  const auto g = gk.reverse(pc);
  EXPECT_TRUE(g.has_value());
  nmea::Gga gga;
  gga.talker = "GN";
  gga.lat_deg = g->lat_deg;
  gga.lon_deg = g->lon_deg;
  gga.quality = quality;
  gga.alt_m = g->h_m - kGeoidSep;
  gga.geoid_sep_m = kGeoidSep;
  return sync::TimedGnss{at_s(t), at_s(t + 0.03), gga};
}

struct FrameOptions {
  bool gnss = true;
  bool ahrs = true;
  int gnss_quality = 4;
  xsens::CoordinateSystem ahrs_frame = xsens::CoordinateSystem::Enu;
  double ahrs_gap_from = 1e9;  // AHRS samples in [from, to] are lost
  double ahrs_gap_to = -1e9;
};

// A 0.2 s window (one 5 Hz rotation) with AHRS at 100 Hz and GNSS at 5 Hz around it, as sync assembles it.
sync::SyncedFrame make_frame(const Truth& truth, const CompensationParams& params, const FrameOptions& o = {}) {
  sync::SyncedFrame f;
  f.window_start = at_s(0.0);
  f.window_end = at_s(0.2);
  f.rotations = 1;
  if (o.ahrs) {
    const double conv = convergence_at(truth.start);
    for (int i = -1; i <= 21; ++i) {
      const double t = 0.01 * i;
      if (t >= o.ahrs_gap_from && t <= o.ahrs_gap_to) continue;
      // The AHRS references true north: its ENU yaw is the grid yaw minus the convergence.
      const EulerDeg enu{truth.roll_deg, truth.pitch_deg, truth.yaw_grid_deg - conv};
      xsens::MtData2 d;
      d.euler_frame = o.ahrs_frame;
      if (o.ahrs_frame == xsens::CoordinateSystem::Ned) {
        // Inverse of enu_from_ned: roll stays, pitch changes sign, yaw = 90 - yaw_enu.
        d.euler_deg = xsens::Vec3{enu.roll_deg, -enu.pitch_deg, 90.0 - enu.yaw_deg};
      } else {
        d.euler_deg = xsens::Vec3{enu.roll_deg, enu.pitch_deg, enu.yaw_deg};
      }
      f.ahrs.push_back(sync::TimedAttitude{at_s(t), at_s(t + 0.002), d});
    }
  }
  if (o.gnss) {
    for (const double t : {-0.1, 0.1, 0.3}) {
      f.gnss.push_back(gga_at(truth.p(t) + truth.q() * params.antenna_m, t, o.gnss_quality));
    }
  }
  return f;
}

// Points on a ring of posts around the tractor, seen at times spread over the window.
std::vector<Eigen::Vector3d> world_points(const Truth& truth, int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> az(-std::numbers::pi, std::numbers::pi);
  std::uniform_real_distribution<double> r(4.0, 40.0);
  std::uniform_real_distribution<double> h(0.0, 3.0);
  std::vector<Eigen::Vector3d> w;
  for (int i = 0; i < n; ++i) {
    const double a = az(rng);
    const double d = r(rng);
    w.push_back(truth.start + Eigen::Vector3d(d * std::cos(a), d * std::sin(a), h(rng)));
  }
  return w;
}

double z_spread(const std::vector<LidarPoint>& pts) {
  float lo = std::numeric_limits<float>::max();
  float hi = std::numeric_limits<float>::lowest();
  for (const auto& p : pts) {
    lo = std::min(lo, p.z);
    hi = std::max(hi, p.z);
  }
  return static_cast<double>(hi - lo);
}

Eigen::Vector3d xyz(const LidarPoint& p) {
  return {static_cast<double>(p.x), static_cast<double>(p.y), static_cast<double>(p.z)};
}

TEST(FrameCompensator, LevelStillVehicleGivesBackTheMountedPoints) {
  const CompensationParams params = base_params();
  const FrameCompensator comp(params);
  const Truth truth;
  sync::SyncedFrame f = make_frame(truth, params);
  const Eigen::Isometry3d tl = transform_of(params.lidar);
  const auto w = world_points(truth, 200);
  for (std::size_t i = 0; i < w.size(); ++i) {
    f.points.push_back(truth.seen(w[i], 0.2 * static_cast<double>(i) / static_cast<double>(w.size()), params.lidar));
    f.points.back().ring = static_cast<std::uint16_t>(i % 32);
    f.points.back().azimuth_cdeg = static_cast<std::uint16_t>(i * 7);
    f.points.back().return_type = i % 2 == 0 ? ReturnType::Strongest : ReturnType::Last;
  }
  CompensatedFrame out;
  comp.compensate(f, out);
  EXPECT_EQ(out.levelling, Levelling::Full);
  EXPECT_EQ(out.t_ref, f.window_end);
  EXPECT_EQ(out.stats.gnss_used, 3U);
  EXPECT_EQ(out.stats.ahrs_used, 23U);
  ASSERT_EQ(out.points.size(), f.points.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    const LidarPoint& in = f.points[i];
    const LidarPoint& o = out.points[i];
    // Level and still: the detection frame is the sensor frame turned by the mounting only.
    const Eigen::Vector3d mounted = tl.linear() * xyz(in);
    worst = std::max(worst, (xyz(o) - mounted).norm());
    EXPECT_EQ(o.source, static_cast<std::uint8_t>(PointSource::Lidar3d));
    EXPECT_EQ(o.ring, in.ring);
    EXPECT_EQ(o.azimuth_cdeg, in.azimuth_cdeg);
    EXPECT_EQ(o.return_type, in.return_type);
    EXPECT_FLOAT_EQ(o.time_s, in.time_s);
    EXPECT_NEAR(static_cast<double>(o.range_m), mounted.norm(), 2e-3);
  }
  EXPECT_LT(worst, 2e-3);
  ASSERT_TRUE(out.attitude.has_value());
  EXPECT_NEAR(out.attitude->roll_deg, 0.0, 1e-6);
  EXPECT_NEAR(out.attitude->yaw_deg, 30.0, 1e-6);
}

// Flat ground (plane frame z = start.z) sampled all round, seen by the tilted tractor.
std::vector<LidarPoint> ground_seen(const Truth& truth, const Mounting& lidar) {
  std::vector<LidarPoint> pts;
  for (int i = 0; i < 360; i += 3) {
    for (const double d : {5.0, 10.0, 20.0}) {
      const Eigen::Vector3d w = truth.start + Eigen::Vector3d(d * std::cos(i * kDeg), d * std::sin(i * kDeg), 0.0);
      pts.push_back(truth.seen(w, 0.001 * i / 2.0, lidar));
    }
  }
  return pts;
}

TEST(FrameCompensator, KnownRollAndPitchMakeTiltedGroundLevel) {
  const CompensationParams params = base_params();
  const FrameCompensator comp(params);
  Truth truth;
  truth.roll_deg = 5.0;
  truth.pitch_deg = -3.0;
  sync::SyncedFrame f = make_frame(truth, params);
  f.points = ground_seen(truth, params.lidar);
  // As mounted (no levelling) the ground tilts: the height spread is metres at 20 m.
  std::vector<LidarPoint> mounted = f.points;
  const Eigen::Matrix3d r = transform_of(params.lidar).linear();
  for (auto& p : mounted) {
    const Eigen::Vector3d v = r * xyz(p);
    p.z = static_cast<float>(v.z());
  }
  const double before = z_spread(mounted);
  EXPECT_GT(before, 2.0);
  CompensatedFrame out;
  comp.compensate(f, out);
  ASSERT_EQ(out.levelling, Levelling::Full);
  ASSERT_EQ(out.points.size(), f.points.size());
  const double after = z_spread(out.points);
  EXPECT_LT(after, 5e-3) << "before " << before;
  // Ground under a level tractor lies at -sensor height in the detection frame.
  for (const auto& p : out.points) EXPECT_NEAR(static_cast<double>(p.z), -params.lidar.z_m, 5e-3);
  ASSERT_TRUE(out.attitude.has_value());
  EXPECT_NEAR(out.attitude->roll_deg, 5.0, 1e-6);
  EXPECT_NEAR(out.attitude->pitch_deg, -3.0, 1e-6);
}

TEST(FrameCompensator, MovingVehicleSeesAFixedPointInOnePlaceWhateverItsTime) {
  const CompensationParams params = base_params();
  const FrameCompensator comp(params);
  Truth truth;
  truth.speed_mps = 3.0;
  truth.yaw_grid_deg = 20.0;
  truth.roll_deg = 3.0;
  sync::SyncedFrame f = make_frame(truth, params);
  const Eigen::Vector3d post = truth.start + Eigen::Vector3d(8.0, 12.0, 1.0);
  for (int i = 0; i <= 40; ++i) f.points.push_back(truth.seen(post, 0.005 * i, params.lidar));
  CompensatedFrame out;
  comp.compensate(f, out);
  ASSERT_EQ(out.levelling, Levelling::Full);
  ASSERT_EQ(out.points.size(), f.points.size());
  const Eigen::Vector3d want = truth.expected(post, 0.2, params.lidar);
  for (const auto& p : out.points) {
    EXPECT_NEAR((xyz(p) - want).norm(), 0.0, 3e-3) << "time_s " << p.time_s;
  }
  // Without positions the 0.6 m of travel stays in the cloud: the test can tell the difference.
  const double smear = (xyz(out.points.front()) - xyz(out.points.back())).norm();
  EXPECT_LT(smear, 3e-3);
  // The reference point at t_ref, lever arm removed.
  ASSERT_TRUE(out.reference.has_value());
  EXPECT_NEAR(out.reference->easting_m, truth.p(0.2).x(), 1e-3);
  EXPECT_NEAR(out.reference->northing_m, truth.p(0.2).y(), 1e-3);
  EXPECT_NEAR(out.reference->up_m, truth.p(0.2).z(), 1e-3);
  EXPECT_EQ(out.reference->zone, kZone);
}

TEST(FrameCompensator, FirstAndLastFixOutsideTheAhrsSamplesUseTheNearestAttitude) {
  const CompensationParams params = base_params();
  const FrameCompensator comp(params);
  const Truth truth;
  sync::SyncedFrame f = make_frame(truth, params);
  CompensatedFrame out;
  comp.compensate(f, out);
  EXPECT_EQ(out.stats.gnss_used, 3U);
  EXPECT_EQ(out.stats.gnss_lever_nearest, 2U);  // -0.1 s and 0.3 s: 90 ms from the AHRS samples
  // A fix farther than max_position_gap_s from every AHRS sample is refused.
  f.gnss.push_back(gga_at(truth.p(0.9) + truth.q() * params.antenna_m, 0.9, 4));
  comp.compensate(f, out);
  EXPECT_EQ(out.stats.gnss_used, 3U);
  EXPECT_EQ(out.stats.gnss_rejected, 1U);
}

TEST(FrameCompensator, ScanAppearsInFrontMarkedLidar2d) {
  const CompensationParams params = base_params();
  const FrameCompensator comp(params);
  const Truth truth;
  sync::SyncedFrame f = make_frame(truth, params);
  f.points.push_back(truth.seen(truth.start + Eigen::Vector3d(5.0, 0.0, 1.0), 0.1, params.lidar));
  sync::TimedScan s;
  s.time = at_s(0.05);
  s.scan.first_step = 0;
  s.scan.last_step = 1080;
  s.scan.ranges_mm.assign(1081, 1);  // no echo (error code)
  s.scan.ranges_mm[540] = 5000;      // straight ahead
  s.scan.ranges_mm[900] = 2000;      // 90 deg left
  f.scan2d = s;
  CompensatedFrame out;
  comp.compensate(f, out);
  ASSERT_EQ(out.levelling, Levelling::Full);
  EXPECT_EQ(out.stats.lift.lifted, 2U);
  EXPECT_EQ(out.stats.lift.out_of_range, 1079U);
  ASSERT_EQ(out.points.size(), 3U);
  EXPECT_EQ(out.points[0].source, static_cast<std::uint8_t>(PointSource::Lidar3d));
  const LidarPoint& front = out.points[1];
  const LidarPoint& left = out.points[2];
  EXPECT_EQ(front.source, static_cast<std::uint8_t>(PointSource::Lidar2d));
  EXPECT_EQ(left.source, static_cast<std::uint8_t>(PointSource::Lidar2d));
  EXPECT_EQ(front.ring, 540);
  EXPECT_EQ(left.ring, 900);
  EXPECT_EQ(front.azimuth_cdeg, 0);
  EXPECT_EQ(left.azimuth_cdeg, 27000);  // 90 deg counter-clockwise = 270 deg clockwise
  // Scanner at (3.0, 0, 0.6) on the vehicle; the detection frame's origin at the LiDAR (1.8, 0, 2.2).
  EXPECT_NEAR((xyz(front) - Eigen::Vector3d(8.0 - 1.8, 0.0, 0.6 - 2.2)).norm(), 0.0, 1e-3);
  EXPECT_NEAR((xyz(left) - Eigen::Vector3d(3.0 - 1.8, 2.0, 0.6 - 2.2)).norm(), 0.0, 1e-3);
  EXPECT_NEAR(static_cast<double>(front.range_m), Eigen::Vector3d(6.2, 0.0, -1.6).norm(), 1e-3);
  EXPECT_NEAR(static_cast<double>(front.time_s), 0.05 + 540 * 0.025 / 1440.0, 1e-6);
}

TEST(FrameCompensator, ScanOfAMovingVehicleIsDeskewedWithEachStepsTime) {
  CompensationParams params = base_params();
  params.scanner.pitch_deg = 0.0;
  const FrameCompensator comp(params);
  Truth truth;
  truth.speed_mps = 10.0;
  truth.yaw_grid_deg = -40.0;
  sync::SyncedFrame f = make_frame(truth, params);
  // A scan of steps 100..1000: its stamp marks step 0, so step 540 is measured 540 step times after it.
  const double stamp_s = 0.05;
  const double step_s = 0.025 / 1440.0;
  const double t540 = stamp_s + 540 * step_s;
  const Eigen::Vector3d scanner_at = truth.p(t540) + truth.q() * Eigen::Vector3d(3.0, 0.0, 0.6);
  const Eigen::Vector3d post = scanner_at + truth.q() * Eigen::Vector3d(6.0, 0.0, 0.0);
  sync::TimedScan s;
  s.time = at_s(stamp_s);
  s.scan.first_step = 100;
  s.scan.last_step = 1000;
  s.scan.ranges_mm.assign(901, 1);
  s.scan.ranges_mm[540 - 100] = 6000;
  f.scan2d = s;
  CompensatedFrame out;
  comp.compensate(f, out);
  ASSERT_EQ(out.levelling, Levelling::Full);
  ASSERT_EQ(out.points.size(), 1U);
  EXPECT_NEAR(static_cast<double>(out.points[0].time_s), t540, 1e-6);
  // 10 m/s: 100 steps of 17.4 us misplaced would be 17 mm.
  EXPECT_NEAR((xyz(out.points[0]) - truth.expected(post, 0.2, params.lidar)).norm(), 0.0, 3e-3);
}

TEST(FrameCompensator, LeverArmPutsTheReferencePointRight) {
  CompensationParams params = base_params();
  params.antenna_m = Eigen::Vector3d(0.0, 0.0, 2.8);
  const FrameCompensator comp(params);
  Truth truth;
  truth.roll_deg = 5.0;  // right side down: the antenna leans 0.24 m to the right
  const sync::SyncedFrame f = make_frame(truth, params);
  CompensatedFrame out;
  comp.compensate(f, out);
  ASSERT_EQ(out.levelling, Levelling::Full);
  ASSERT_TRUE(out.reference.has_value());
  EXPECT_NEAR(out.reference->easting_m, truth.start.x(), 1e-3);
  EXPECT_NEAR(out.reference->northing_m, truth.start.y(), 1e-3);
  EXPECT_NEAR(out.reference->up_m, truth.start.z(), 1e-3);
  // The antenna itself is 2.8 sin 5deg = 0.244 m off horizontally: the check above can tell.
  const Eigen::Vector3d antenna = truth.start + truth.q() * params.antenna_m;
  EXPECT_GT((antenna - truth.start).head<2>().norm(), 0.2);
}

TEST(FrameCompensator, NoUsableGnssLevelsWithAttitudeOnly) {
  const CompensationParams params = base_params();
  const FrameCompensator comp(params);
  Truth truth;
  truth.roll_deg = -4.0;
  truth.pitch_deg = 2.0;
  FrameOptions o;
  o.gnss_quality = 0;  // GGA without a fix
  sync::SyncedFrame f = make_frame(truth, params, o);
  f.points = ground_seen(truth, params.lidar);
  CompensatedFrame out;
  comp.compensate(f, out);
  EXPECT_EQ(out.levelling, Levelling::AttitudeOnly);
  EXPECT_EQ(out.stats.gnss_rejected, 3U);
  EXPECT_EQ(out.stats.gnss_used, 0U);
  EXPECT_FALSE(out.reference.has_value());
  ASSERT_TRUE(out.attitude.has_value());
  ASSERT_EQ(out.points.size(), f.points.size());
  EXPECT_LT(z_spread(out.points), 5e-3);
  for (const auto& p : out.points) EXPECT_NEAR(static_cast<double>(p.z), -params.lidar.z_m, 5e-3);
  // plane output needs positions
  CompensationParams pp = params;
  pp.plane_points = true;
  FrameCompensator(pp).compensate(f, out);
  EXPECT_TRUE(out.plane.empty());
}

// GGA quality codes are not ordered by precision: 5 (RTK float) is worse than 4 (RTK fixed), and 6..8 are
// no measurement at all.
TEST(FrameCompensator, GnssQualityIsRankedByPrecisionNotByCode) {
  CompensationParams rtk = base_params();
  rtk.min_gnss_quality = 4;
  const FrameCompensator fixed_only(rtk);
  rtk.min_gnss_quality = 5;
  const FrameCompensator float_or_fixed(rtk);
  const FrameCompensator any(base_params());
  const Truth truth;
  FrameOptions o;
  CompensatedFrame out;
  struct Case {
    int quality;
    bool fixed_only, float_or_fixed, any;
  };
  for (const Case c :
       {Case{1, false, false, true}, Case{2, false, false, true}, Case{4, true, true, true}, Case{5, false, true, true},
        Case{6, false, false, false}, Case{7, false, false, false}, Case{8, false, false, false}}) {
    o.gnss_quality = c.quality;
    const sync::SyncedFrame f = make_frame(truth, rtk, o);
    fixed_only.compensate(f, out);
    EXPECT_EQ(out.levelling, c.fixed_only ? Levelling::Full : Levelling::AttitudeOnly) << c.quality;
    EXPECT_EQ(out.stats.gnss_rejected, c.fixed_only ? 0U : 3U) << c.quality;
    float_or_fixed.compensate(f, out);
    EXPECT_EQ(out.levelling, c.float_or_fixed ? Levelling::Full : Levelling::AttitudeOnly) << c.quality;
    any.compensate(f, out);
    EXPECT_EQ(out.levelling, c.any ? Levelling::Full : Levelling::AttitudeOnly) << c.quality;
  }
  // A GGA with an empty quality field is no fix either; one without an altitude is (a position-only receiver).
  sync::SyncedFrame f = make_frame(truth, rtk);
  std::get<nmea::Gga>(f.gnss[0].sentence).quality.reset();
  std::get<nmea::Gga>(f.gnss[1].sentence).alt_m.reset();
  any.compensate(f, out);
  EXPECT_EQ(out.stats.gnss_rejected, 1U);
  EXPECT_EQ(out.stats.gnss_used, 2U);
  EXPECT_EQ(out.stats.gnss_without_height, 1U);
}

// A DGPS receiver that reports position only (GGA with satellites, HDOP, altitude and geoid separation empty)
// still places and deskews the frame: the plane position needs no height. With no height in the frame at all
// the reference stays at height 0 (no vertical motion); with one, the others take it.
TEST(FrameCompensator, PositionOnlyFixesPlaceAndDeskewTheFrame) {
  const CompensationParams params = base_params();
  const FrameCompensator comp(params);
  Truth truth;
  truth.speed_mps = 3.0;
  truth.yaw_grid_deg = 20.0;
  sync::SyncedFrame f = make_frame(truth, params);
  for (sync::TimedGnss& g : f.gnss) {
    auto& gga = std::get<nmea::Gga>(g.sentence);
    gga.satellites.reset();
    gga.hdop.reset();
    gga.alt_m.reset();
    gga.geoid_sep_m.reset();
  }
  const Eigen::Vector3d post = truth.start + Eigen::Vector3d(8.0, 12.0, 1.0);
  for (int i = 0; i <= 40; ++i) f.points.push_back(truth.seen(post, 0.005 * i, params.lidar));
  CompensatedFrame out;
  comp.compensate(f, out);
  ASSERT_EQ(out.levelling, Levelling::Full);
  EXPECT_EQ(out.stats.gnss_used, f.gnss.size());
  EXPECT_EQ(out.stats.gnss_without_height, f.gnss.size());
  const Eigen::Vector3d want = truth.expected(post, 0.2, params.lidar);
  for (const auto& p : out.points) {
    // Horizontally where the full fixes put it; the frame's height is the vehicle's at 0 instead of its own.
    EXPECT_NEAR((xyz(p) - want).head<2>().norm(), 0.0, 3e-3) << "time_s " << p.time_s;
  }
  ASSERT_TRUE(out.reference.has_value());
  EXPECT_NEAR(out.reference->easting_m, truth.p(0.2).x(), 1e-3);
  EXPECT_NEAR(out.reference->northing_m, truth.p(0.2).y(), 1e-3);

  // One fix with its altitude: the others take its height.
  std::get<nmea::Gga>(f.gnss[0].sentence).alt_m = std::get<nmea::Gga>(make_frame(truth, params).gnss[0].sentence).alt_m;
  std::get<nmea::Gga>(f.gnss[0].sentence).geoid_sep_m = kGeoidSep;
  comp.compensate(f, out);
  EXPECT_EQ(out.stats.gnss_without_height, f.gnss.size() - 1);
  ASSERT_TRUE(out.reference.has_value());
  EXPECT_NEAR(out.reference->up_m, truth.p(0.0).z(), 0.05);
}

TEST(FrameCompensator, NoAhrsLeavesPointsAsMounted) {
  const CompensationParams params = base_params();
  const FrameCompensator comp(params);
  Truth truth;
  truth.roll_deg = 4.0;
  FrameOptions o;
  o.ahrs = false;
  sync::SyncedFrame f = make_frame(truth, params, o);
  f.points = ground_seen(truth, params.lidar);
  sync::TimedScan s;
  s.time = at_s(0.05);
  s.scan.first_step = 0;
  s.scan.last_step = 1080;
  s.scan.ranges_mm.assign(1081, 1);
  s.scan.ranges_mm[540] = 5000;
  f.scan2d = s;
  CompensatedFrame out;
  comp.compensate(f, out);
  EXPECT_EQ(out.levelling, Levelling::None);
  EXPECT_FALSE(out.attitude.has_value());
  EXPECT_FALSE(out.reference.has_value());
  ASSERT_EQ(out.points.size(), f.points.size() + 1);
  const Eigen::Matrix3d r = transform_of(params.lidar).linear();
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    EXPECT_NEAR((xyz(out.points[i]) - r * xyz(f.points[i])).norm(), 0.0, 1e-5);
  }
  // Still tilted: nothing levelled it.
  EXPECT_GT(z_spread(std::vector<LidarPoint>(out.points.begin(), out.points.end() - 1)), 2.0);
  const LidarPoint& front = out.points.back();
  EXPECT_EQ(front.source, static_cast<std::uint8_t>(PointSource::Lidar2d));
  EXPECT_NEAR((xyz(front) - Eigen::Vector3d(8.0 - 1.8, 0.0, 0.6 - 2.2)).norm(), 0.0, 1e-4);
}

TEST(FrameCompensator, NoAttitudeAtTheWindowsEndLeavesPointsAsMounted) {
  const CompensationParams params = base_params();
  Truth truth;
  truth.roll_deg = 4.0;
  FrameOptions o;
  o.ahrs_gap_from = 0.125;  // the AHRS stops 75 ms before the window's end (holding is allowed for 20 ms)
  o.ahrs_gap_to = 1.0;
  sync::SyncedFrame f = make_frame(truth, params, o);
  f.points = ground_seen(truth, params.lidar);
  CompensatedFrame out;
  FrameCompensator(params).compensate(f, out);
  EXPECT_EQ(out.levelling, Levelling::None);
  EXPECT_FALSE(out.attitude.has_value());
  ASSERT_EQ(out.points.size(), f.points.size());
  const Eigen::Matrix3d r = transform_of(params.lidar).linear();
  EXPECT_NEAR((xyz(out.points[5]) - r * xyz(f.points[5])).norm(), 0.0, 1e-5);
}

TEST(FrameCompensator, AttitudeGapDropsAndCountsItsPoints) {
  const CompensationParams params = base_params();
  const FrameCompensator comp(params);
  const Truth truth;
  FrameOptions o;
  o.ahrs_gap_from = 0.075;  // samples 0.08 .. 0.15 lost: 0.07 -> 0.16 is 90 ms, a gap (limit 50 ms)
  o.ahrs_gap_to = 0.155;
  sync::SyncedFrame f = make_frame(truth, params, o);
  const Eigen::Vector3d post = truth.start + Eigen::Vector3d(8.0, 12.0, 1.0);
  std::size_t in_gap = 0;
  for (int i = 0; i < 100; ++i) {
    const double t = 0.002 * i + 0.0005;
    f.points.push_back(truth.seen(post, t, params.lidar));
    if (t > 0.07 && t < 0.16) ++in_gap;
  }
  CompensatedFrame out;
  comp.compensate(f, out);
  ASSERT_EQ(out.levelling, Levelling::Full);
  EXPECT_EQ(out.stats.lidar.dropped_gap, in_gap);
  EXPECT_GT(in_gap, 0U);
  EXPECT_EQ(out.points.size(), f.points.size() - in_gap);
  EXPECT_EQ(out.stats.lidar.points_out, out.points.size());
  // The survivors keep their order and their own times.
  for (const auto& p : out.points) {
    EXPECT_TRUE(p.time_s < 0.07F || p.time_s > 0.16F) << p.time_s;
  }
  // A non-finite point is dropped and counted too, without upsetting the pairing of the others.
  f.points[3].x = std::numeric_limits<float>::quiet_NaN();
  f.points[3].return_type = ReturnType::Last;
  f.points[4].return_type = ReturnType::SecondStrongest;
  comp.compensate(f, out);
  EXPECT_EQ(out.stats.lidar.dropped_not_finite, 1U);
  ASSERT_GE(out.points.size(), 4U);
  EXPECT_FLOAT_EQ(out.points[3].time_s, f.points[4].time_s);
  EXPECT_EQ(out.points[3].return_type, ReturnType::SecondStrongest);
}

TEST(FrameCompensator, NedAhrsOutputGivesTheSameCloudAsEnu) {
  const CompensationParams params = base_params();
  Truth truth;
  truth.roll_deg = 3.0;
  truth.pitch_deg = -2.0;
  truth.yaw_grid_deg = 75.0;
  truth.speed_mps = 2.0;
  const auto w = world_points(truth, 100);
  FrameOptions ned;
  ned.ahrs_frame = xsens::CoordinateSystem::Ned;
  sync::SyncedFrame fe = make_frame(truth, params);
  sync::SyncedFrame fn = make_frame(truth, params, ned);
  for (std::size_t i = 0; i < w.size(); ++i) {
    fe.points.push_back(truth.seen(w[i], 0.002 * static_cast<double>(i), params.lidar));
  }
  fn.points = fe.points;
  CompensatedFrame oe;
  CompensatedFrame on;
  FrameCompensator(params).compensate(fe, oe);
  FrameCompensator(params).compensate(fn, on);  // configured ENU, data id says NED: the data id wins
  ASSERT_EQ(on.levelling, Levelling::Full);
  EXPECT_EQ(on.stats.ahrs_frame_mismatch, on.stats.ahrs_used);
  EXPECT_EQ(oe.stats.ahrs_frame_mismatch, 0U);
  ASSERT_EQ(on.points.size(), oe.points.size());
  for (std::size_t i = 0; i < on.points.size(); ++i) {
    EXPECT_NEAR((xyz(on.points[i]) - xyz(oe.points[i])).norm(), 0.0, 1e-4);
    EXPECT_NEAR((xyz(on.points[i]) - truth.expected(w[i], 0.2, params.lidar)).norm(), 0.0, 3e-3);
  }
  CompensationParams pn = params;
  pn.ahrs.frame = AhrsFrame::Ned;
  FrameCompensator(pn).compensate(fn, on);
  EXPECT_EQ(on.stats.ahrs_frame_mismatch, 0U);
  // The reserved coordinate system cannot be interpreted: every sample rejected, no levelling.
  for (auto& a : fn.ahrs) a.data.euler_frame = xsens::CoordinateSystem::Reserved;
  FrameCompensator(pn).compensate(fn, on);
  EXPECT_EQ(on.levelling, Levelling::None);
  EXPECT_EQ(on.stats.ahrs_rejected, fn.ahrs.size());
}

TEST(FrameCompensator, NwuAhrsOutputIsTurnedToEnu) {
  const CompensationParams params = base_params();
  Truth truth;
  truth.yaw_grid_deg = 75.0;
  truth.roll_deg = 2.0;
  sync::SyncedFrame f = make_frame(truth, params);
  for (auto& a : f.ahrs) {
    a.data.euler_frame = xsens::CoordinateSystem::Nwu;
    a.data.euler_deg->z -= 90.0;  // NWU yaw counts from north
  }
  CompensatedFrame out;
  FrameCompensator(params).compensate(f, out);
  ASSERT_TRUE(out.attitude.has_value());
  EXPECT_NEAR(out.attitude->yaw_deg, 75.0, 1e-6);
  EXPECT_NEAR(out.attitude->roll_deg, 2.0, 1e-6);
}

TEST(FrameCompensator, PlaneOutputOnRequest) {
  CompensationParams params = base_params();
  params.plane_points = true;
  const FrameCompensator comp(params);
  Truth truth;
  truth.speed_mps = 2.5;
  truth.pitch_deg = 2.0;
  sync::SyncedFrame f = make_frame(truth, params);
  const auto w = world_points(truth, 50);
  for (std::size_t i = 0; i < w.size(); ++i)
    f.points.push_back(truth.seen(w[i], 0.004 * static_cast<double>(i), params.lidar));
  sync::TimedScan s;
  s.time = at_s(0.05);
  s.scan.first_step = 0;
  s.scan.last_step = 1080;
  s.scan.ranges_mm.assign(1081, 3000);
  f.scan2d = s;
  CompensatedFrame out;
  comp.compensate(f, out);
  ASSERT_EQ(out.levelling, Levelling::Full);
  ASSERT_EQ(out.plane.size(), out.points.size());
  EXPECT_EQ(out.plane.size(), w.size() + 1081);
  for (std::size_t i = 0; i < w.size(); ++i) {
    EXPECT_NEAR((out.plane[i].enu - w[i]).norm(), 0.0, 2e-3);
    EXPECT_EQ(out.plane[i].source, PointSource::Lidar3d);
  }
  EXPECT_EQ(out.plane.back().source, PointSource::Lidar2d);
  // Off by default: detection does not pay for it.
  CompensationParams off = params;
  off.plane_points = false;
  FrameCompensator(off).compensate(f, out);
  EXPECT_TRUE(out.plane.empty());
}

TEST(FrameCompensator, OutputIsClearedAndReused) {
  const CompensationParams params = base_params();
  const FrameCompensator comp(params);
  const Truth truth;
  sync::SyncedFrame f = make_frame(truth, params);
  f.points = ground_seen(truth, params.lidar);
  CompensatedFrame out;
  comp.compensate(f, out);
  const std::size_t n = out.points.size();
  comp.compensate(f, out);
  EXPECT_EQ(out.points.size(), n);
  FrameOptions none;
  none.ahrs = false;
  none.gnss = false;
  comp.compensate(make_frame(truth, params, none), out);
  EXPECT_TRUE(out.points.empty());
  EXPECT_FALSE(out.reference.has_value());
  EXPECT_FALSE(out.attitude.has_value());
  EXPECT_EQ(out.stats.gnss_used, 0U);
}

// The output's room follows the frames: a frame twice as big (as when a sensor comes back and a window holds more
// rotations) does not leave every later frame in a buffer of its size, and a steady stream keeps its buffer (no
// reallocation from frame to frame).
TEST(FrameCompensator, OutputRoomShrinksBackAfterAnOverlongFrame) {
  const CompensationParams params = base_params();
  const FrameCompensator comp(params);
  const Truth truth;
  sync::SyncedFrame f = make_frame(truth, params);
  f.points = ground_seen(truth, params.lidar);
  sync::SyncedFrame big = f;
  big.points.insert(big.points.end(), f.points.begin(), f.points.end());
  CompensatedFrame out;
  comp.compensate(f, out);
  const std::size_t n = out.points.size();
  const LidarPoint* steady = out.points.data();
  comp.compensate(f, out);
  EXPECT_EQ(out.points.data(), steady) << "a steady stream reallocated";
  comp.compensate(big, out);
  EXPECT_GE(out.points.capacity(), 2 * n);
  comp.compensate(f, out);
  EXPECT_EQ(out.points.size(), n);
  EXPECT_LE(2 * out.points.capacity(), 3 * n + 3) << "the overlong frame's room kept";
  steady = out.points.data();
  comp.compensate(f, out);
  EXPECT_EQ(out.points.data(), steady);
}

// The working storage travels with the output (a worker reuses both): nothing of one frame, nor of another
// compensator's track limits, leaks into the next: bit for bit what a fresh output gives.
TEST(FrameCompensator, ReusedWorkGivesWhatAFreshOutputGives) {
  const CompensationParams params = base_params();
  CompensationParams strict = params;
  strict.track.max_attitude_gap_s = 0.005;  // every AHRS gap a dropout: points dropped
  const FrameCompensator comp(params);
  const FrameCompensator other(strict);
  const Truth truth;
  sync::SyncedFrame f = make_frame(truth, params);
  f.points = ground_seen(truth, params.lidar);
  FrameOptions gap;
  gap.ahrs_gap_from = 0.05;
  gap.ahrs_gap_to = 0.12;
  sync::SyncedFrame g = make_frame(truth, params, gap);
  g.points = f.points;
  const auto same = [](const CompensatedFrame& a, const CompensatedFrame& b) {
    ASSERT_EQ(a.levelling, b.levelling);
    ASSERT_EQ(a.points.size(), b.points.size());
    for (std::size_t i = 0; i < a.points.size(); ++i) {
      ASSERT_EQ(a.points[i].x, b.points[i].x);
      ASSERT_EQ(a.points[i].y, b.points[i].y);
      ASSERT_EQ(a.points[i].z, b.points[i].z);
    }
    EXPECT_EQ(a.stats.gnss_used, b.stats.gnss_used);
    EXPECT_EQ(a.stats.ahrs_used, b.stats.ahrs_used);
    EXPECT_EQ(a.stats.lidar.points_out, b.stats.lidar.points_out);
  };
  CompensatedFrame fresh_f;
  CompensatedFrame fresh_g;
  CompensatedFrame fresh_other;
  comp.compensate(f, fresh_f);
  comp.compensate(g, fresh_g);
  other.compensate(f, fresh_other);
  ASSERT_NE(fresh_f.stats.lidar.points_out, fresh_other.stats.lidar.points_out) << "the limits make a difference";
  CompensatedFrame reused;
  comp.compensate(g, reused);
  comp.compensate(f, reused);
  same(reused, fresh_f);
  comp.compensate(g, reused);
  same(reused, fresh_g);
  other.compensate(f, reused);
  same(reused, fresh_other);
  comp.compensate(f, reused);
  same(reused, fresh_f);
}

TEST(FrameCompensator, ValidateRejectsBadParameters) {
  EXPECT_TRUE(base_params().validate().empty());
  EXPECT_NO_THROW(FrameCompensator{base_params()});
  struct Case {
    const char* key;
    void (*spoil)(CompensationParams&);
  };
  const Case cases[] = {
      {"min_gnss_quality", [](CompensationParams& p) { p.min_gnss_quality = 0; }},
      {"min_gnss_quality", [](CompensationParams& p) { p.min_gnss_quality = 6; }},
      {"antenna_m", [](CompensationParams& p) { p.antenna_m.x() = std::numeric_limits<double>::quiet_NaN(); }},
      {"antenna_m", [](CompensationParams& p) { p.antenna_m.z() = 50.0; }},
      {"lidar mounting", [](CompensationParams& p) { p.lidar.z_m = std::numeric_limits<double>::infinity(); }},
      {"scan2d mounting",
       [](CompensationParams& p) { p.scanner.pitch_deg = std::numeric_limits<double>::quiet_NaN(); }},
      {"pose_step_s", [](CompensationParams& p) { p.pose_step_s = -1.0; }},
      {"turn_period_s", [](CompensationParams& p) { p.scan_turn_period_s = 0.0; }},
      {"scan_geometry", [](CompensationParams& p) { p.scan_geometry.steps_per_turn = 0.0; }},
      {"scan_geometry", [](CompensationParams& p) { p.scan_geometry.dmin_mm = 70000; }},
      {"projection.", [](CompensationParams& p) { p.projection.fixed_zone = 999; }},
      {"ahrs.", [](CompensationParams& p) { p.ahrs.declination_deg = 400.0; }},
      {"track.", [](CompensationParams& p) { p.track.max_attitude_gap_s = -1.0; }},
  };
  for (const Case& c : cases) {
    CompensationParams p = base_params();
    c.spoil(p);
    const auto problems = p.validate();
    ASSERT_FALSE(problems.empty()) << c.key;
    EXPECT_TRUE(std::any_of(problems.begin(), problems.end(),
                            [&](const std::string& s) { return s.find(c.key) != std::string::npos; }))
        << c.key << ": " << problems.front();
    EXPECT_THROW(FrameCompensator{p}, std::invalid_argument) << c.key;
  }
}

TEST(FrameCompensator, LevellingNames) {
  EXPECT_STREQ(to_string(Levelling::Full), "full");
  EXPECT_STREQ(to_string(Levelling::AttitudeOnly), "attitude-only");
  EXPECT_STREQ(to_string(Levelling::None), "none");
}

}  // namespace
}  // namespace fieldguard::geo
