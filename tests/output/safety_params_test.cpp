// Stop-zone sizing and parameter validation of the safety monitor.

#include "fieldguard/output/safety_params.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace fieldguard::output::safety {
namespace {

bool has_problem(const std::vector<ParamProblem>& ps, const std::string& key) {
  return std::any_of(ps.begin(), ps.end(), [&](const ParamProblem& p) { return p.key == key; });
}

TEST(SafetyZone, PublishedBrakingDistanceAt30KmhOnFriction03) {
  // v^2 / (2 mu g) = 8.33^2 / (2 * 0.3 * 9.81) = 11.8 m.
  EXPECT_NEAR(braking_distance_m(30.0 / 3.6, 0.3), 11.8, 0.01);
}

TEST(SafetyZone, UnknownSpeedUsesTheFullSpeedSize) {
  ZoneParams z;
  z.reaction_time_s = 0.0;
  z.margin_m = 1.0;
  z.full_speed_kmh = 30.0;
  EXPECT_NEAR(zone_length_m(z, std::nullopt), 12.8, 0.01);
  // A speed that is not a number is no speed: the full-speed zone, never a shorter one.
  EXPECT_NEAR(zone_length_m(z, std::numeric_limits<double>::quiet_NaN()), 12.8, 0.01);
  EXPECT_NEAR(zone_length_m(z, std::numeric_limits<double>::infinity()), 12.8, 0.01);
}

TEST(SafetyZone, ScalesWithSpeedWithReactionTimeAndAFloor) {
  ZoneParams z;
  z.reaction_time_s = 0.5;
  z.margin_m = 1.0;
  z.friction = 0.3;
  z.min_length_m = 3.0;
  const double v = 30.0 / 3.6;
  EXPECT_NEAR(zone_length_m(z, v), 0.5 * v + 11.8 + 1.0, 0.01);
  const double v10 = 10.0 / 3.6;  // 1.39 + 1.31 + 1.0 = 3.70 m
  EXPECT_NEAR(zone_length_m(z, v10), 0.5 * v10 + v10 * v10 / (2 * 0.3 * 9.81) + 1.0, 1e-9);
  EXPECT_GT(zone_length_m(z, v), zone_length_m(z, v10));
  EXPECT_DOUBLE_EQ(zone_length_m(z, 0.0), 3.0);  // standing: the floor, not the margin alone
  EXPECT_DOUBLE_EQ(zone_length_m(z, 0.5), 3.0);
  // Reversing does not shrink the zone ahead.
  EXPECT_DOUBLE_EQ(zone_length_m(z, -v), zone_length_m(z, v));
}

TEST(SafetyParams, DefaultsAreValid) { EXPECT_TRUE(validate(Params{}).empty()); }

TEST(SafetyParams, EveryProblemIsReported) {
  Params p;
  p.zone.half_width_m = -1.0;
  p.zone.margin_m = -0.1;
  p.zone.min_length_m = 0.0;
  p.zone.full_speed_kmh = 0.0;
  p.zone.friction = std::numeric_limits<double>::quiet_NaN();
  p.zone.reaction_time_s = -0.5;
  p.zone.rear_x_m = 1.0;  // ahead of front_x_m 0.4
  p.clear_frames = 0;
  p.pipeline_deadline_s = 0.0;
  p.max_frame_interval_s = -1.0;
  p.sensor(Sensor::Ahrs).timeout_s = 0.0;
  p.gnss.accepted_fix_mask = 1;  // quality 0 only
  p.gnss.min_satellites = -1;
  p.gnss.max_hdop = -2.0;
  p.gnss.max_speed_mps = 0.0;
  p.ahrs.max_roll_deg = 0.0;
  p.ahrs.max_pitch_deg = -3.0;
  p.ahrs.max_rate_deg_s = std::numeric_limits<double>::infinity();
  const auto ps = validate(p);
  for (const char* key :
       {"zone.half_width_m", "zone.margin_m", "zone.min_length_m", "zone.full_speed_kmh", "zone.friction",
        "zone.reaction_time_s", "zone.rear_x_m", "clear_frames", "pipeline_deadline_s", "max_frame_interval_s",
        "sensors.ahrs.timeout_s", "gnss.accepted_fix", "gnss.min_satellites", "gnss.max_hdop", "gnss.max_speed_mps",
        "ahrs.max_roll_deg", "ahrs.max_pitch_deg", "ahrs.max_rate_deg_s"}) {
    EXPECT_TRUE(has_problem(ps, key)) << key;
  }
  // Both accepted_fix problems: nothing from 1..9 accepted, and 0 listed.
  EXPECT_EQ(std::count_if(ps.begin(), ps.end(), [](const ParamProblem& q) { return q.key == "gnss.accepted_fix"; }), 2);
  EXPECT_EQ(ps.size(), 19U);
  for (const auto& q : ps) EXPECT_FALSE(q.message.empty()) << q.key;
}

TEST(SafetyParams, NoLidarRequiredIsAProblem) {
  Params p;
  p.sensor(Sensor::Lidar).required = false;
  EXPECT_TRUE(has_problem(validate(p), "sensors.lidar.required"));
  p.sensor(Sensor::Scan2d).required = true;  // the 2D LiDAR alone still sees
  EXPECT_TRUE(validate(p).empty());
}

TEST(SafetyParams, FrictionAboveAnyTyreIsAProblem) {
  Params p;
  p.zone.friction = 3.0;
  EXPECT_TRUE(has_problem(validate(p), "zone.friction"));
}

TEST(SafetyParams, RequiredMaskFollowsTheSensors) {
  Params p;
  EXPECT_EQ(p.required_mask(), bit(Sensor::Lidar));
  p.sensor(Sensor::Ahrs).required = true;
  EXPECT_EQ(p.required_mask(), bit(Sensor::Lidar) | bit(Sensor::Ahrs));
  EXPECT_EQ(to_string(Sensor::Scan2d), "scan2d");
}

}  // namespace
}  // namespace fieldguard::output::safety
