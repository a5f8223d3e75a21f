// The `sync:` and `geo:` sections of the configuration.

#include <gtest/gtest.h>

#include <string>

#include "app/config_issues.hpp"
#include "fieldguard/config/config.hpp"
#include "fieldguard/engine/fusion.hpp"

namespace fieldguard::app {
namespace {

using testing::dump;
using testing::has_issue;

TEST(ConfigFusion, DefaultsWithoutTheSections) {
  const auto r = load_config_text("lidar: {model: auto}\n", "d.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_DOUBLE_EQ(r.config.sync.rate_hz, 5.0);
  EXPECT_DOUBLE_EQ(r.config.sync.timeout_s, 0.5);
  EXPECT_EQ(r.config.geo.projection.ellipsoid, geo::Ellipsoid::Cgcs2000);
  EXPECT_EQ(r.config.geo.projection.zone_width, geo::ZoneWidth::Three);
  EXPECT_EQ(r.config.geo.projection.fixed_zone, 0);
  EXPECT_EQ(r.config.geo.ahrs_frame, geo::AhrsFrame::Enu);
  EXPECT_TRUE(compensation_params(r.config).validate().empty());
}

TEST(ConfigFusion, ReadsEveryKeyIntoTheCompensation) {
  const auto r = load_config_text(R"(
lidar:
  mounting: {x_m: 3.6, z_m: 1.8}
scan2d:
  mounting: {x_m: 3.95, z_m: 0.3, pitch_deg: 2.0}
ahrs:
  mounting: {yaw_deg: 90.0}
sync: {rate_hz: 10, timeout_s: 0.3, max_scan_offset_s: 0.05, max_pending: 4}
geo:
  ellipsoid: Krasovsky
  zone_width_deg: 6
  fixed_zone: 20
  zone_prefix: true
  antenna_m: [0.5, -0.2, 2.8]
  ahrs_frame: ned
  declination_deg: -5.5
  min_gnss_quality: 4
  max_attitude_gap_s: 0.1
  max_position_gap_s: 1.0
)",
                                  "f.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_DOUBLE_EQ(r.config.sync.rate_hz, 10.0);
  EXPECT_DOUBLE_EQ(r.config.sync.timeout_s, 0.3);
  EXPECT_DOUBLE_EQ(r.config.sync.max_scan_offset_s, 0.05);
  EXPECT_EQ(r.config.sync.max_pending, 4);
  const geo::CompensationParams p = compensation_params(r.config);
  EXPECT_EQ(p.projection.ellipsoid, geo::Ellipsoid::Krasovsky1940);
  EXPECT_EQ(p.projection.zone_width, geo::ZoneWidth::Six);
  EXPECT_EQ(p.projection.fixed_zone, 20);
  EXPECT_TRUE(p.projection.zone_prefix);
  EXPECT_DOUBLE_EQ(p.antenna_m.x(), 0.5);
  EXPECT_DOUBLE_EQ(p.antenna_m.y(), -0.2);
  EXPECT_DOUBLE_EQ(p.antenna_m.z(), 2.8);
  EXPECT_EQ(p.ahrs.frame, geo::AhrsFrame::Ned);
  EXPECT_DOUBLE_EQ(p.ahrs.declination_deg, -5.5);
  EXPECT_DOUBLE_EQ(p.ahrs.mounting.yaw_deg, 90.0);
  EXPECT_EQ(p.min_gnss_quality, 4);
  EXPECT_DOUBLE_EQ(p.lidar.z_m, 1.8);
  EXPECT_DOUBLE_EQ(p.scanner.pitch_deg, 2.0);
  EXPECT_DOUBLE_EQ(p.track.max_attitude_gap_s, 0.1);
  EXPECT_DOUBLE_EQ(p.track.max_position_gap_s, 1.0);
  EXPECT_TRUE(p.validate().empty());
}

TEST(ConfigFusion, ReportsEveryProblemWithLineAndKey) {
  const auto r = load_config_text(R"(sync:
  rate_hz: 0.1
  timeout_s: -1
  wait: 3
geo:
  ellipsoid: GRS80
  zone_width_deg: 4
  antenna_m: [0, 0]
  ahrs_frame: ecef
  min_gnss_quality: 0
)",
                                  "bad.yaml");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(has_issue(r, "sync.rate_hz", "", 2)) << dump(r);
  EXPECT_TRUE(has_issue(r, "sync.timeout_s", "", 3)) << dump(r);
  EXPECT_TRUE(has_issue(r, "sync.wait", "", 4)) << dump(r);
  EXPECT_TRUE(has_issue(r, "geo.ellipsoid", "", 6)) << dump(r);
  EXPECT_TRUE(has_issue(r, "geo.zone_width_deg", "", 7)) << dump(r);
  EXPECT_TRUE(has_issue(r, "geo.antenna_m", "3 numbers", 8)) << dump(r);
  EXPECT_TRUE(has_issue(r, "geo.ahrs_frame", "", 9)) << dump(r);
  EXPECT_TRUE(has_issue(r, "geo.min_gnss_quality", "", 10)) << dump(r);
}

TEST(ConfigFusion, AZoneOutsideItsWidthIsRefused) {
  const auto r = load_config_text("geo: {zone_width_deg: 6, fixed_zone: 61}\n", "z.yaml");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(has_issue(r, "geo.fixed_zone", "")) << dump(r);
  EXPECT_TRUE(load_config_text("geo: {zone_width_deg: 3, fixed_zone: 61}\n", "z3.yaml").ok());
}

}  // namespace
}  // namespace fieldguard::app
