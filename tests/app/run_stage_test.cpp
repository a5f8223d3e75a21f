// The daemon's output stage on a fake clock: decisions between rotations reach the bus at once.
#include "daemon/run_stage.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "app/recording_sink.hpp"
#include "fieldguard/output/can_layout.hpp"
#include "fieldguard/output/safety_params.hpp"

namespace fieldguard::app {
namespace {

constexpr std::int64_t kMs = 1'000'000;

using testing::RecordingSink;
using testing::Sent;

// The defaults (the 3D LiDAR required, timeout 0.3 s, 3 clear frames, heartbeat 100 ms) without the address claim:
// these tests are about the stop path from the first tick on (the claim's hold is CanLink's tests').
Config unclaimed() {
  Config c;
  c.can.j1939.address_claim = false;
  return c;
}

struct LiveStageTest : ::testing::Test {
  Config cfg = unclaimed();
  RecordingSink sink;
  CanLink link{cfg.can, sink};
  output::CanEncoder enc{cfg.can.params};
  const std::int64_t t0 = 1'700'000'000'000 * kMs;

  [[nodiscard]] std::vector<Sent> stops() const {
    std::vector<Sent> out;
    for (const auto& s : sink.sent) {
      if (s.frame.id == enc.id_of(output::MessageId::StopRequest)) out.push_back(s);
    }
    return out;
  }
  static std::uint64_t sig(const Sent& s, std::size_t i) {
    return output::get_raw(s.frame.data, output::layout(output::MessageId::StopRequest).signals[i]);
  }
};

TEST_F(LiveStageTest, SilenceAfterGoStopsAtTheTimeoutWithoutARotation) {
  LiveStage stage(cfg, link);
  stage.tick(Stamp{t0}, 0);
  ASSERT_FALSE(stops().empty());
  EXPECT_EQ(sig(stops().back(), output::stop_sig::Command), 1U);
  EXPECT_EQ(sig(stops().back(), output::stop_sig::ReasonStartingUp), 1U);
  // Four clear rotations, 100 ms apart, data to the end of each: GO after the clear frames.
  perception::FrameResult nothing;
  LidarFrame f;
  std::int64_t t = t0;
  for (int k = 0; k < 4; ++k) {
    t = t0 + (k + 1) * 100 * kMs;
    stage.sensor_data(output::safety::Sensor::Lidar, Stamp{t});
    f.index = static_cast<std::uint64_t>(k);
    stage.frame(f, nothing, Stamp{t}, Stamp{t + 20 * kMs}, 0);
  }
  ASSERT_TRUE(stage.started());
  EXPECT_EQ(sig(stops().back(), output::stop_sig::Command), 0U);
  const std::int64_t last_data = t;
  // Ticks every 5 ms: GO while within the timeout, STOP (sensor fault) at the first tick past it, sent then.
  std::size_t before = 0;
  std::int64_t stop_at = 0;
  for (std::int64_t now = last_data + 25 * kMs; now < last_data + 600 * kMs && stop_at == 0; now += 5 * kMs) {
    before = stops().size();
    if (stage.tick(Stamp{now}, 0).stop) stop_at = now;
  }
  ASSERT_NE(stop_at, 0);
  EXPECT_GE(stop_at, last_data + 300 * kMs);  // the monitor counts a silence of exactly the timeout as too long
  EXPECT_LE(stop_at, last_data + 305 * kMs);
  ASSERT_GT(stops().size(), before);
  const Sent s = stops().back();
  EXPECT_EQ(s.t.ns, stop_at) << "not sent when decided";
  EXPECT_EQ(sig(s, output::stop_sig::Command), 1U);
  EXPECT_EQ(sig(s, output::stop_sig::ReasonSensorFault), 1U);
  // The next cycle repeats it; an unchanged decision is not sent again between cycles.
  const std::size_t n = stops().size();
  stage.tick(Stamp{stop_at + 1 * kMs}, 0);
  EXPECT_EQ(stops().size(), n);
  stage.tick(Stamp{stop_at + 100 * kMs}, 0);
  ASSERT_GT(stops().size(), n);
  EXPECT_EQ(sig(stops().back(), output::stop_sig::ReasonSensorFault), 1U);
  // The last word: STOP, shutting down; the log stays in time order.
  stage.shutdown(Stamp{stop_at + 150 * kMs});
  EXPECT_EQ(sig(stops().back(), output::stop_sig::Command), 1U);
  EXPECT_EQ(sig(stops().back(), output::stop_sig::ReasonShuttingDown), 1U);
  for (std::size_t i = 1; i < sink.sent.size(); ++i) EXPECT_LE(sink.sent[i - 1].t.ns, sink.sent[i].t.ns);
}

// The tractor's speed from the bus sizes the zone: an obstacle 10 m ahead is inside the full-speed zone (speed
// unknown) and outside the zone of a tractor creeping at 1 m/s; a speed older than can.speed_timeout_s is
// unknown again.
TEST_F(LiveStageTest, AFreshBusSpeedSizesTheZoneAStaleOneDoesNot) {
  const double full = cfg.safety.zone.front_x_m + output::safety::zone_length_m(cfg.safety.zone, std::nullopt);
  const double slow = cfg.safety.zone.front_x_m + output::safety::zone_length_m(cfg.safety.zone, 1.0);
  ASSERT_GT(full, 10.5);
  ASSERT_LT(slow, 9.5);
  LiveStage stage(cfg, link);
  perception::FrameResult ahead;
  perception::Obstacle o;
  o.min = {9.8F, -0.2F, -0.9F};
  o.max = {10.2F, 0.2F, 0.8F};
  o.distance_m = 9.8F;
  ahead.obstacles.push_back(o);
  LidarFrame f;
  std::int64_t t = t0;
  auto decide = [&](int k) {
    t = t0 + (k + 1) * 100 * kMs;
    stage.sensor_data(output::safety::Sensor::Lidar, Stamp{t});
    f.index = static_cast<std::uint64_t>(k);
    return stage.frame(f, ahead, Stamp{t}, Stamp{t + 10 * kMs}, 0);
  };
  // Speed unknown: STOP, obstacle in zone, frame after frame.
  for (int k = 0; k < 4; ++k) {
    const auto& d = decide(k);
    EXPECT_TRUE(d.stop) << k;
    EXPECT_EQ(d.obstacles_in_zone, 1) << k;
  }
  // 1 m/s, fresh with every frame: the zone shrinks, and after the clear frames it is GO.
  bool go = false;
  for (int k = 4; k < 4 + cfg.safety.clear_frames + 1; ++k) {
    stage.vehicle_speed(1.0, Stamp{t0 + (k + 1) * 100 * kMs});
    const auto& d = decide(k);
    EXPECT_EQ(d.obstacles_in_zone, 0) << k;
    EXPECT_LT(d.zone.x_max_m, 9.5);
    go = !d.stop;
  }
  EXPECT_TRUE(go);
  // The bus falls silent: within the timeout the last speed still counts, past it the zone is full again.
  const std::int64_t last_speed = t;
  const int k_stale = 4 + cfg.safety.clear_frames + 1 + static_cast<int>(cfg.can.speed_timeout_s * 10.0) + 1;
  const auto& d = decide(k_stale);
  ASSERT_GT(t - last_speed, static_cast<std::int64_t>(cfg.can.speed_timeout_s * 1e9));
  EXPECT_TRUE(d.stop);
  EXPECT_EQ(d.obstacles_in_zone, 1);
  EXPECT_GT(d.zone.x_max_m, 10.5);
}

// What the daemon hands the hold (obstacle_hold.hpp) and the zone: the bus's speed while fresh, then unknown.
TEST_F(LiveStageTest, SpeedAtIsTheBusSpeedWithinItsTimeout) {
  LiveStage stage(cfg, link);
  EXPECT_FALSE(stage.speed_at(Stamp{t0}).has_value()) << "no speed heard yet";
  stage.vehicle_speed(2.5, Stamp{t0});
  const auto timeout = static_cast<std::int64_t>(cfg.can.speed_timeout_s * 1e9);
  ASSERT_TRUE(stage.speed_at(Stamp{t0 + timeout}).has_value());
  EXPECT_DOUBLE_EQ(*stage.speed_at(Stamp{t0 + timeout}), 2.5);
  EXPECT_FALSE(stage.speed_at(Stamp{t0 + timeout + kMs}).has_value());
  stage.vehicle_speed(0.5, Stamp{t0 + 2 * timeout});
  EXPECT_DOUBLE_EQ(stage.speed_at(Stamp{t0 + 2 * timeout}).value_or(-1.0), 0.5);
}

}  // namespace
}  // namespace fieldguard::app
