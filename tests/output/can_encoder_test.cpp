#include "fieldguard/output/can_encoder.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "fieldguard/output/crc8.hpp"

namespace fieldguard::output {
namespace {

using perception::Obstacle;

Obstacle obstacle(float x0, float x1, float y0, float y1, float distance, float bearing = 0.F) {
  Obstacle o;
  o.min = {x0, y0, -1.F};
  o.max = {x1, y1, 0.8F};
  o.distance_m = distance;
  o.bearing_deg = bearing;
  o.height_above_ground_m = 1.7F;
  o.points = 42;
  return o;
}

std::uint64_t raw(const CanFrame& f, MessageId m, std::size_t sig) { return get_raw(f.data, layout(m).signals[sig]); }
double phys(const CanFrame& f, MessageId m, std::size_t sig) { return get_physical(f.data, layout(m).signals[sig]); }

TEST(CanEncoder, IdsCarryPriorityPgnAndAddresses) {
  CanParams p;
  p.source_address = 0x80;
  p.controller_address = 0x26;
  CanEncoder e(p);
  EXPECT_EQ(e.id_of(MessageId::StopRequest), 0x0CEF2680U);  // Proprietary A to the controller, priority 3
  EXPECT_EQ(e.id_of(MessageId::ObstacleSummary), 0x18FF1080U);
  EXPECT_EQ(e.id_of(MessageId::Obstacle), 0x18FF1180U);
  EXPECT_EQ(e.id_of(MessageId::Heartbeat), 0x18FF1280U);
  p.source_address = 0x2A;
  p.controller_address = 0x13;
  p.priority[static_cast<std::size_t>(MessageId::StopRequest)] = 2;
  EXPECT_EQ(CanEncoder(p).id_of(MessageId::StopRequest), 0x08EF132AU);
}

TEST(CanEncoder, RejectsUnusableParametersWithEveryProblem) {
  CanParams p;
  p.source_address = 0xFF;
  p.controller_address = 0xFE;
  p.max_obstacles = 17;
  p.priority[0] = 8;
  const auto problems = validate(p);
  ASSERT_EQ(problems.size(), 4U);
  EXPECT_NE(problems[0].find("can.source_address"), std::string::npos);
  EXPECT_NE(problems[3].find("can.max_obstacles"), std::string::npos);
  EXPECT_THROW(CanEncoder{p}, std::invalid_argument);
  CanParams same;
  same.controller_address = same.source_address;
  EXPECT_EQ(validate(same).size(), 1U);
  EXPECT_TRUE(validate(CanParams{}).empty());
}

// protocols.md §7.5's illustrative frame: STOP, counter 5, CRC-8/SAE-J1850 over bytes 0-6 = 0x3E.
TEST(CanEncoder, StopRequestMatchesThePublishedExampleFrame) {
  CanEncoder e(CanParams{});
  StopRequest stop;
  stop.command = StopCommand::Stop;
  for (int i = 0; i < 5; ++i) (void)e.encode_stop(stop);
  const CanFrame f = e.encode_stop(stop);
  EXPECT_EQ(f.len, 8);
  EXPECT_EQ(f.data, (std::array<std::uint8_t, 8>{0x01, 0, 0, 0, 0, 0, 0x05, 0x3E}));
}

TEST(CanEncoder, StopRequestCarriesReasonsCounterAndCrc) {
  CanEncoder e(CanParams{});
  StopRequest r;
  r.command = StopCommand::Stop;
  r.reasons.sensor_fault = true;
  r.reasons.starting_up = true;
  std::uint64_t expected_counter = 0;
  for (int i = 0; i < 40; ++i) {
    const CanFrame f = e.encode_stop(r);
    EXPECT_EQ(raw(f, MessageId::StopRequest, stop_sig::Command), 1U);
    EXPECT_EQ(raw(f, MessageId::StopRequest, stop_sig::ReasonObstacle), 0U);
    EXPECT_EQ(raw(f, MessageId::StopRequest, stop_sig::ReasonSensorFault), 1U);
    EXPECT_EQ(raw(f, MessageId::StopRequest, stop_sig::ReasonStartingUp), 1U);
    EXPECT_EQ(raw(f, MessageId::StopRequest, stop_sig::AliveCounter), expected_counter);
    EXPECT_EQ(f.data[7], crc8<kCrc8SaeJ1850>(std::span<const std::uint8_t>(f.data.data(), 7)));
    expected_counter = (expected_counter + 1) % 16;  // 0..15, then 0 again
  }
  const CanFrame go = e.encode_stop(StopRequest{StopCommand::Go, {}});
  EXPECT_EQ(go.data[0], 0x00);
  EXPECT_EQ(go.data[1], 0x00);
}

TEST(CanEncoder, ObstaclesGoNearestFirstUpToTheConfiguredCount) {
  CanParams p;
  p.max_obstacles = 2;
  CanEncoder e(p);
  const std::vector<Obstacle> obs{obstacle(20, 21, -1, 1, 20.F, 0.F), obstacle(5, 5.5F, 1, 1.6F, 5.F, 12.5F),
                                  obstacle(9, 10, -3, -2, 9.F, -14.F)};
  std::vector<CanFrame> out;
  e.encode_frame(FrameReport{70000, FrameStatus::Ok, obs}, out);
  ASSERT_EQ(out.size(), 3U);
  const CanFrame& s = out[0];
  EXPECT_EQ(s.id, e.id_of(MessageId::ObstacleSummary));
  EXPECT_EQ(raw(s, MessageId::ObstacleSummary, summary_sig::ObstacleCount), 3U);
  EXPECT_NEAR(phys(s, MessageId::ObstacleSummary, summary_sig::NearestDistance), 5.0, 0.005);
  EXPECT_NEAR(phys(s, MessageId::ObstacleSummary, summary_sig::NearestBearing), 12.5, 0.005);
  EXPECT_EQ(raw(s, MessageId::ObstacleSummary, summary_sig::FrameCounter), 70000U % 65536U);
  EXPECT_EQ(raw(s, MessageId::ObstacleSummary, summary_sig::ListTruncated), 1U);
  EXPECT_EQ(raw(s, MessageId::ObstacleSummary, summary_sig::Saturated), 0U);
  EXPECT_EQ(out[1].id, e.id_of(MessageId::Obstacle));
  EXPECT_EQ(raw(out[1], MessageId::Obstacle, obstacle_sig::Index), 0U);
  EXPECT_NEAR(phys(out[1], MessageId::Obstacle, obstacle_sig::XMin), 5.0, 0.05);
  EXPECT_NEAR(phys(out[1], MessageId::Obstacle, obstacle_sig::YMax), 1.6, 0.05);
  EXPECT_EQ(raw(out[2], MessageId::Obstacle, obstacle_sig::Index), 1U);
  EXPECT_NEAR(phys(out[2], MessageId::Obstacle, obstacle_sig::XMin), 9.0, 0.05);
  EXPECT_NEAR(phys(out[2], MessageId::Obstacle, obstacle_sig::YMin), -3.0, 0.05);
  EXPECT_NEAR(phys(out[2], MessageId::Obstacle, obstacle_sig::Height), 1.7, 0.1 + 1e-6);  // half a 0.2 m step
  EXPECT_EQ(raw(out[2], MessageId::Obstacle, obstacle_sig::Points), 42U);
  EXPECT_EQ(e.saturated_values(), 0U);
}

TEST(CanEncoder, AnEmptyFrameSaysNoObstacle) {
  CanEncoder e(CanParams{});
  std::vector<CanFrame> out;
  e.encode_frame(FrameReport{1, FrameStatus::NotReady, {}}, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(raw(out[0], MessageId::ObstacleSummary, summary_sig::ObstacleCount), 0U);
  EXPECT_EQ(raw(out[0], MessageId::ObstacleSummary, summary_sig::NearestDistance), 0xFFFFU);
  EXPECT_EQ(raw(out[0], MessageId::ObstacleSummary, summary_sig::NearestBearing), 0xFFFFU);
  EXPECT_EQ(raw(out[0], MessageId::ObstacleSummary, summary_sig::Status), 3U);
  EXPECT_EQ(raw(out[0], MessageId::ObstacleSummary, summary_sig::ListTruncated), 0U);
}

TEST(CanEncoder, ZeroObstacleMessagesStillReportTheNearest) {
  CanParams p;
  p.max_obstacles = 0;
  CanEncoder e(p);
  const std::vector<Obstacle> obs{obstacle(8, 9, 0, 1, 8.F, 3.F), obstacle(3, 4, 0, 1, 3.F, 7.F)};
  std::vector<CanFrame> out;
  e.encode_frame(FrameReport{1, FrameStatus::Ok, obs}, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_NEAR(phys(out[0], MessageId::ObstacleSummary, summary_sig::NearestDistance), 3.0, 0.005);
  EXPECT_EQ(raw(out[0], MessageId::ObstacleSummary, summary_sig::ListTruncated), 1U);
}

TEST(CanEncoder, OutOfRangeValuesAreClampedCountedAndFlagged) {
  CanEncoder e(CanParams{});
  Obstacle far = obstacle(150, 160, -200, 300, 700.F, 0.F);
  far.height_above_ground_m = -0.5F;
  far.points = 100000;
  std::vector<CanFrame> out;
  e.encode_frame(FrameReport{2, FrameStatus::Ok, std::span<const Obstacle>(&far, 1)}, out);
  ASSERT_EQ(out.size(), 2U);
  // distance, XMin, XMax, YMin, YMax, height, points
  EXPECT_EQ(e.saturated_values(), 7U);
  EXPECT_EQ(raw(out[0], MessageId::ObstacleSummary, summary_sig::Saturated), 1U);
  EXPECT_NEAR(phys(out[0], MessageId::ObstacleSummary, summary_sig::NearestDistance), 600.0, 1e-9);
  EXPECT_NEAR(phys(out[1], MessageId::Obstacle, obstacle_sig::XMin), 102.3, 1e-9);
  EXPECT_NEAR(phys(out[1], MessageId::Obstacle, obstacle_sig::YMin), -102.4, 1e-9);
  EXPECT_EQ(raw(out[1], MessageId::Obstacle, obstacle_sig::Points), 255U);
  EXPECT_EQ(raw(out[1], MessageId::Obstacle, obstacle_sig::Height), 0U);
  // The heartbeat reports the running count.
  const CanFrame hb = e.encode_heartbeat(Heartbeat{});
  EXPECT_EQ(raw(hb, MessageId::Heartbeat, heartbeat_sig::SaturatedValues), 7U);
}

TEST(CanEncoder, NanObstaclesAreNearestAndFlaggedNeverUndefined) {
  CanEncoder e(CanParams{});
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<Obstacle> obs{obstacle(4, 5, 0, 1, 4.F, 1.F), obstacle(nan, nan, nan, nan, nan, nan),
                            obstacle(2, 3, 0, 1, 2.F, 1.F)};
  obs[1].height_above_ground_m = std::numeric_limits<float>::infinity();
  std::vector<CanFrame> out;
  e.encode_frame(FrameReport{3, FrameStatus::Degraded, obs}, out);
  ASSERT_EQ(out.size(), 4U);
  EXPECT_EQ(raw(out[0], MessageId::ObstacleSummary, summary_sig::Saturated), 1U);
  EXPECT_EQ(raw(out[0], MessageId::ObstacleSummary, summary_sig::NearestDistance), 0U);  // clamped to 0 m
  EXPECT_NEAR(phys(out[2], MessageId::Obstacle, obstacle_sig::XMin), 2.0, 0.05);
  EXPECT_NEAR(phys(out[3], MessageId::Obstacle, obstacle_sig::XMin), 4.0, 0.05);
  EXPECT_GT(e.saturated_values(), 0U);
}

// Any bit pattern as a float (NaN payloads, infinities, denormals, 1e38): clamped and counted, and under
// UBSan no float-to-integer conversion overflows.
TEST(CanEncoder, ArbitraryFloatsNeverReachUndefinedBehaviour) {
  std::mt19937 rng(11);
  const auto any_float = [&] { return std::bit_cast<float>(static_cast<std::uint32_t>(rng())); };
  CanEncoder e(CanParams{});
  std::vector<CanFrame> out;
  for (int frame = 0; frame < 2000; ++frame) {
    std::vector<Obstacle> obs(static_cast<std::size_t>(rng() % 20));
    for (auto& o : obs) {
      o.min = {any_float(), any_float(), any_float()};
      o.max = {any_float(), any_float(), any_float()};
      o.distance_m = any_float();
      o.bearing_deg = any_float();
      o.height_above_ground_m = any_float();
      o.points = static_cast<std::uint32_t>(rng());
      o.size_class = static_cast<perception::SizeClass>(rng() % 256);
    }
    out.clear();
    e.encode_frame(FrameReport{static_cast<std::uint32_t>(rng()), static_cast<FrameStatus>(rng() % 4), obs}, out);
    ASSERT_EQ(out.size(), 1 + std::min<std::size_t>(obs.size(), 8));
    for (std::size_t i = 1; i < out.size(); ++i) {
      EXPECT_EQ(raw(out[i], MessageId::Obstacle, obstacle_sig::Index), i - 1);
    }
  }
  EXPECT_GT(e.saturated_values(), 0U);
}

TEST(CanEncoder, HeartbeatCarriesHealthLossCounterAndCrc) {
  CanEncoder e(CanParams{});
  Heartbeat hb;
  hb.lidar3d = SensorHealth::Ok;
  hb.lidar2d = SensorHealth::Fault;
  hb.gnss = SensorHealth::NotRequired;
  hb.ahrs = SensorHealth::Unknown;
  hb.frames_lost = 65536 + 7;
  const CanFrame f = e.encode_heartbeat(hb);
  EXPECT_EQ(f.data[0], 0b11'10'01'00);
  EXPECT_EQ(raw(f, MessageId::Heartbeat, heartbeat_sig::FramesLost), 7U);
  EXPECT_EQ(raw(f, MessageId::Heartbeat, heartbeat_sig::AliveCounter), 0U);
  EXPECT_EQ(f.data[7], crc8<kCrc8SaeJ1850>(std::span<const std::uint8_t>(f.data.data(), 7)));
  EXPECT_EQ(raw(e.encode_heartbeat(hb), MessageId::Heartbeat, heartbeat_sig::AliveCounter), 1U);
}

}  // namespace
}  // namespace fieldguard::output
