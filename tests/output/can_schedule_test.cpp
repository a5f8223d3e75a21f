#include "fieldguard/output/can_schedule.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace fieldguard::output {
namespace {

struct Sent {
  CanFrame frame;
  Stamp t;
};

class RecordingSink final : public CanSink {
 public:
  void write(std::span<const CanFrame> frames, Stamp t) override {
    for (const auto& f : frames) sent.push_back({f, t});
    stats_.sent += frames.size();
  }
  [[nodiscard]] const CanSinkStats& stats() const override { return stats_; }
  std::vector<Sent> sent;

 private:
  CanSinkStats stats_;
};

constexpr std::int64_t kMs = 1'000'000;

struct CanScheduleTest : ::testing::Test {
  CanEncoder enc{CanParams{}};
  RecordingSink sink;
  CanSchedule sched{enc, sink};

  std::vector<std::int64_t> stamps_of(MessageId m) const {
    std::vector<std::int64_t> out;
    for (const auto& s : sink.sent) {
      if (s.frame.id == enc.id_of(m)) out.push_back(s.t.ns);
    }
    return out;
  }
};

TEST_F(CanScheduleTest, HeartbeatsComeAtAFixedRateOnTheGivenClock) {
  const std::int64_t t0 = 1'000 * kMs;
  // A 5 Hz replay: tick and frame every 200 ms; heartbeats at every 100 ms, stamped at their due times.
  for (int k = 0; k < 5; ++k) {
    const Stamp t{t0 + k * 200 * kMs};
    sched.tick(t, Heartbeat{});
    sched.frame(FrameReport{static_cast<std::uint32_t>(k), FrameStatus::Ok, {}}, StopRequest{StopCommand::Go, {}}, t);
  }
  const auto hb = stamps_of(MessageId::Heartbeat);
  ASSERT_EQ(hb.size(), 9U);  // t0, t0+100, ..., t0+800
  for (std::size_t i = 0; i < hb.size(); ++i) EXPECT_EQ(hb[i], t0 + static_cast<std::int64_t>(i) * 100 * kMs);
  EXPECT_EQ(stamps_of(MessageId::ObstacleSummary).size(), 5U);
  // Time order in the log.
  for (std::size_t i = 1; i < sink.sent.size(); ++i) EXPECT_LE(sink.sent[i - 1].t, sink.sent[i].t);
  EXPECT_EQ(sched.skipped_cycles(), 0U);
}

TEST_F(CanScheduleTest, StopRequestRepeatsWithTheHeartbeatAndStartsAsStop) {
  sched.tick(Stamp{0}, Heartbeat{});  // no decision yet
  ASSERT_EQ(sink.sent.size(), 2U);
  const Signal& cmd = layout(MessageId::StopRequest).signals[stop_sig::Command];
  const Signal& starting = layout(MessageId::StopRequest).signals[stop_sig::ReasonStartingUp];
  EXPECT_EQ(sink.sent[1].frame.id, enc.id_of(MessageId::StopRequest));
  EXPECT_EQ(get_raw(sink.sent[1].frame.data, cmd), 1U);
  EXPECT_EQ(get_raw(sink.sent[1].frame.data, starting), 1U);
  sched.frame(FrameReport{}, StopRequest{StopCommand::Go, {}}, Stamp{50 * kMs});
  sched.tick(Stamp{100 * kMs}, Heartbeat{});  // the pipeline's last word, repeated
  EXPECT_EQ(get_raw(sink.sent.back().frame.data, cmd), 0U);
  // Alive counter advances over every stop request sent, repeats included.
  const Signal& alive = layout(MessageId::StopRequest).signals[stop_sig::AliveCounter];
  std::uint64_t expect = 0;
  for (const auto& s : sink.sent) {
    if (s.frame.id != enc.id_of(MessageId::StopRequest)) continue;
    EXPECT_EQ(get_raw(s.frame.data, alive), expect++);
  }
  EXPECT_EQ(expect, 3U);
}

TEST_F(CanScheduleTest, ALongGapSendsOneCycleNotABurst) {
  sched.tick(Stamp{0}, Heartbeat{});
  sched.tick(Stamp{5'000 * kMs + 30 * kMs}, Heartbeat{});  // 5 s stall
  const auto hb = stamps_of(MessageId::Heartbeat);
  ASSERT_EQ(hb.size(), 2U);
  EXPECT_EQ(hb[1], 5'000 * kMs);
  EXPECT_EQ(sched.skipped_cycles(), 49U);
  sched.tick(Stamp{5'050 * kMs}, Heartbeat{});  // not due yet
  EXPECT_EQ(stamps_of(MessageId::Heartbeat).size(), 2U);
  sched.tick(Stamp{5'100 * kMs}, Heartbeat{});
  EXPECT_EQ(stamps_of(MessageId::Heartbeat).size(), 3U);
  // A clock that steps back sends nothing until it catches up.
  sched.tick(Stamp{1'000 * kMs}, Heartbeat{});
  EXPECT_EQ(stamps_of(MessageId::Heartbeat).size(), 3U);
  EXPECT_THROW(CanSchedule(enc, sink, Nanos{0}), std::invalid_argument);
}

TEST_F(CanScheduleTest, AStopDecidedBetweenFramesGoesOutAtOnceAndRepeats) {
  const Signal& cmd = layout(MessageId::StopRequest).signals[stop_sig::Command];
  const Signal& fault = layout(MessageId::StopRequest).signals[stop_sig::ReasonSensorFault];
  sched.tick(Stamp{0}, Heartbeat{});
  sched.frame(FrameReport{}, StopRequest{StopCommand::Go, {}}, Stamp{10 * kMs});
  const std::size_t before = sink.sent.size();
  sched.stop(StopRequest{StopCommand::Stop, StopReasons{.sensor_fault = true}}, Stamp{40 * kMs});
  ASSERT_EQ(sink.sent.size(), before + 1);  // the stop request alone, no summary: no frame was decided
  EXPECT_EQ(sink.sent.back().t.ns, 40 * kMs);
  EXPECT_EQ(sink.sent.back().frame.id, enc.id_of(MessageId::StopRequest));
  EXPECT_EQ(get_raw(sink.sent.back().frame.data, cmd), 1U);
  EXPECT_EQ(get_raw(sink.sent.back().frame.data, fault), 1U);
  sched.tick(Stamp{100 * kMs}, Heartbeat{});  // repeated by the next cycle, not the GO of the last frame
  EXPECT_EQ(sink.sent.back().frame.id, enc.id_of(MessageId::StopRequest));
  EXPECT_EQ(get_raw(sink.sent.back().frame.data, cmd), 1U);
  EXPECT_EQ(get_raw(sink.sent.back().frame.data, fault), 1U);
  ASSERT_TRUE(sched.last_stop().has_value());
  EXPECT_EQ(sched.last_stop()->command, StopCommand::Stop);
}

}  // namespace
}  // namespace fieldguard::output
