// The `safety:` section of the configuration (the stop decision).

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "app/config_issues.hpp"
#include "fieldguard/config/config.hpp"

namespace fieldguard::app {
namespace {

using output::safety::Sensor;

using testing::dump;
using testing::has_issue;

TEST(ConfigSafety, ReadsEveryKey) {
  const auto r = load_config_text(R"(
ahrs: {enabled: true, device: /dev/ttyUSB1}
safety:
  zone:
    front_x_m: 0.6
    rear_x_m: -4.5
    half_width_m: 3.1
    margin_m: 1.5
    min_length_m: 4
    full_speed_kmh: 25
    friction: 0.45
    reaction_time_s: 0.7
  clear_frames: 5
  pipeline_deadline_s: 0.25
  max_frame_interval_s: 0.8
  sensors:
    lidar: {required: true, timeout_s: 0.4}
    scan2d: {required: false, timeout_s: 0.15}
    gnss: {timeout_s: 2.5}
    ahrs: {required: true, timeout_s: 0.05}
  gnss:
    accepted_fix: [2, 4, 5]
    min_satellites: 7
    max_hdop: 2.5
    max_speed_mps: 12
  ahrs:
    max_roll_deg: 20
    max_pitch_deg: 25
    max_rate_deg_s: 90
)",
                                  "s.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& s = r.config.safety;
  EXPECT_DOUBLE_EQ(s.zone.front_x_m, 0.6);
  EXPECT_DOUBLE_EQ(s.zone.rear_x_m, -4.5);
  EXPECT_DOUBLE_EQ(s.zone.half_width_m, 3.1);
  EXPECT_DOUBLE_EQ(s.zone.margin_m, 1.5);
  EXPECT_DOUBLE_EQ(s.zone.min_length_m, 4.0);
  EXPECT_DOUBLE_EQ(s.zone.full_speed_kmh, 25.0);
  EXPECT_DOUBLE_EQ(s.zone.friction, 0.45);
  EXPECT_DOUBLE_EQ(s.zone.reaction_time_s, 0.7);
  EXPECT_EQ(s.clear_frames, 5);
  EXPECT_DOUBLE_EQ(s.pipeline_deadline_s, 0.25);
  EXPECT_DOUBLE_EQ(s.max_frame_interval_s, 0.8);
  EXPECT_TRUE(s.sensor(Sensor::Lidar).required);
  EXPECT_DOUBLE_EQ(s.sensor(Sensor::Lidar).timeout_s, 0.4);
  EXPECT_FALSE(s.sensor(Sensor::Scan2d).required);
  EXPECT_DOUBLE_EQ(s.sensor(Sensor::Scan2d).timeout_s, 0.15);
  EXPECT_FALSE(s.sensor(Sensor::Gnss).required);
  EXPECT_DOUBLE_EQ(s.sensor(Sensor::Gnss).timeout_s, 2.5);
  EXPECT_TRUE(s.sensor(Sensor::Ahrs).required);
  EXPECT_DOUBLE_EQ(s.sensor(Sensor::Ahrs).timeout_s, 0.05);
  EXPECT_EQ(s.gnss.accepted_fix_mask, (1U << 2U) | (1U << 4U) | (1U << 5U));
  EXPECT_EQ(s.gnss.min_satellites, 7);
  EXPECT_DOUBLE_EQ(s.gnss.max_hdop, 2.5);
  EXPECT_DOUBLE_EQ(s.gnss.max_speed_mps, 12.0);
  EXPECT_DOUBLE_EQ(s.ahrs.max_roll_deg, 20.0);
  EXPECT_DOUBLE_EQ(s.ahrs.max_pitch_deg, 25.0);
  EXPECT_DOUBLE_EQ(s.ahrs.max_rate_deg_s, 90.0);
}

TEST(ConfigSafety, LeftOutKeysKeepTheDefaults) {
  const auto r = load_config_text("safety:\n  clear_frames: 4\n", "s.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  output::safety::Params expected;
  expected.clear_frames = 4;
  EXPECT_DOUBLE_EQ(r.config.safety.zone.half_width_m, expected.zone.half_width_m);
  EXPECT_EQ(r.config.safety.required_mask(), expected.required_mask());
  EXPECT_EQ(r.config.safety.clear_frames, 4);
}

TEST(ConfigSafety, ShippedFilesAreTheDefaultsAndThePublishedSizing) {
  const auto ours = load_config_file(std::string(FIELDGUARD_SOURCE_DIR) + "/config/fieldguard.yaml");
  ASSERT_TRUE(ours.ok()) << dump(ours);
  const output::safety::Params d;
  const auto& s = ours.config.safety;
  EXPECT_EQ(s.zone.front_x_m, d.zone.front_x_m);
  EXPECT_EQ(s.zone.rear_x_m, d.zone.rear_x_m);
  EXPECT_EQ(s.zone.half_width_m, d.zone.half_width_m);
  EXPECT_EQ(s.zone.margin_m, d.zone.margin_m);
  EXPECT_EQ(s.zone.min_length_m, d.zone.min_length_m);
  EXPECT_EQ(s.zone.full_speed_kmh, d.zone.full_speed_kmh);
  EXPECT_EQ(s.zone.friction, d.zone.friction);
  EXPECT_EQ(s.zone.reaction_time_s, d.zone.reaction_time_s);
  EXPECT_EQ(s.clear_frames, d.clear_frames);
  EXPECT_EQ(s.pipeline_deadline_s, d.pipeline_deadline_s);
  EXPECT_EQ(s.max_frame_interval_s, d.max_frame_interval_s);
  for (std::size_t i = 0; i < output::safety::kSensorCount; ++i) {
    EXPECT_EQ(s.sensors[i].required, d.sensors[i].required) << i;
    EXPECT_EQ(s.sensors[i].timeout_s, d.sensors[i].timeout_s) << i;
  }
  EXPECT_EQ(s.gnss.accepted_fix_mask, d.gnss.accepted_fix_mask);
  EXPECT_EQ(s.gnss.min_satellites, d.gnss.min_satellites);
  EXPECT_EQ(s.gnss.max_hdop, d.gnss.max_hdop);
  EXPECT_EQ(s.gnss.max_speed_mps, d.gnss.max_speed_mps);
  EXPECT_EQ(s.ahrs.max_roll_deg, d.ahrs.max_roll_deg);
  EXPECT_EQ(s.ahrs.max_pitch_deg, d.ahrs.max_pitch_deg);
  EXPECT_EQ(s.ahrs.max_rate_deg_s, d.ahrs.max_rate_deg_s);

  const auto pub = load_config_file(std::string(FIELDGUARD_SOURCE_DIR) + "/config/published.yaml");
  ASSERT_TRUE(pub.ok()) << dump(pub);
  const auto& z = pub.config.safety.zone;
  // 30 km/h on friction 0.3 brakes in 11.8 m; the zone is that plus the margin, ahead of the front.
  EXPECT_DOUBLE_EQ(z.full_speed_kmh, 30.0);
  EXPECT_DOUBLE_EQ(z.friction, 0.3);
  EXPECT_DOUBLE_EQ(z.reaction_time_s, 0.0);
  EXPECT_NEAR(output::safety::zone_length_m(z, std::nullopt) - z.margin_m, 11.8, 0.01);
}

TEST(ConfigSafety, ReportsEveryProblemWithLineAndKey) {
  const std::string text =
      "safety:\n"                        // 1
      "  zone:\n"                        // 2
      "    front_x_m: 0.4\n"             // 3
      "    rear_x_m: 2.0\n"              // 4  ahead of the front
      "    half_width_m: -1\n"           // 5  out of range
      "    friction: lots\n"             // 6  not a number
      "    colour: red\n"                // 7  unknown key
      "  clear_frames: 0\n"              // 8  out of range
      "  pipeline_deadline_s: 20\n"      // 9  out of range
      "  sensors:\n"                     // 10
      "    lidar: {required: false}\n"   // 11 no LiDAR required
      "    gnss:\n"                      // 12
      "      required: true\n"           // 13 gnss.enabled is false
      "      timeout_s: 0\n"             // 14 out of range
      "    radar: {required: true}\n"    // 15 unknown sensor
      "  gnss:\n"                        // 16
      "    accepted_fix: [4, 0, RTK]\n"  // 17 two bad items
      "    min_satellites: 2.5\n"        // 18 not whole
      "  ahrs:\n"                        // 19
      "    max_rate_deg_s: -5\n"         // 20 out of range
      "    max_roll_deg: [1]\n";         // 21 not a number
  const auto r = load_config_text(text, "bad.yaml");
  EXPECT_TRUE(has_issue(r, "safety.zone.rear_x_m", "must not be ahead of zone.front_x_m", 4)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.zone.half_width_m", "out of range", 5)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.zone.friction", "expected a number", 6)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.zone.colour", "unknown key", 7)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.clear_frames", "out of range", 8)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.pipeline_deadline_s", "out of range", 9)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.sensors.lidar.required", "no LiDAR is required", 11)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.sensors.gnss.required", "gnss.enabled is false", 13)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.sensors.gnss.timeout_s", "out of range", 14)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.sensors.radar", "unknown key", 15)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.gnss.accepted_fix[1]", "not a GGA fix quality", 17)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.gnss.accepted_fix[2]", "not a GGA fix quality", 17)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.gnss.min_satellites", "whole number", 18)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.ahrs.max_rate_deg_s", "out of range", 20)) << dump(r);
  EXPECT_TRUE(has_issue(r, "safety.ahrs.max_roll_deg", "expected a number", 21)) << dump(r);
  EXPECT_EQ(r.issues.size(), 15U) << dump(r);
}

TEST(ConfigSafety, AcceptedFixMustBeAList) {
  const auto r = load_config_text("safety:\n  gnss:\n    accepted_fix: 4\n", "s.yaml");
  EXPECT_TRUE(has_issue(r, "safety.gnss.accepted_fix", "expected a list", 3)) << dump(r);
  const auto e = load_config_text("safety:\n  gnss:\n    accepted_fix: []\n", "s.yaml");
  EXPECT_TRUE(has_issue(e, "safety.gnss.accepted_fix", "expected a list", 3)) << dump(e);
}

TEST(ConfigSafety, SectionMustBeAMapping) {
  const auto r = load_config_text("safety: 3\n", "s.yaml");
  EXPECT_TRUE(has_issue(r, "safety", "expected a mapping", 1)) << dump(r);
}

TEST(ConfigSafety, RequiredSensorThatIsEnabledIsFine) {
  const auto r = load_config_text(
      "scan2d: {enabled: true}\n"
      "safety:\n  sensors:\n    scan2d: {required: true}\n",
      "s.yaml");
  EXPECT_TRUE(r.ok()) << dump(r);
  EXPECT_TRUE(r.config.safety.sensor(Sensor::Scan2d).required);
}

}  // namespace
}  // namespace fieldguard::app
