// The stop decision: each reason, hysteresis, start-up, sensors going silent and coming back, the zone's
// edges and speed scaling, NaN inputs, and events once per change.

#include "fieldguard/output/safety_monitor.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>
#include <vector>

#include "output/test_obstacles.hpp"

namespace fieldguard::output::safety {
namespace {

constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();
constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kT0 = 1'000'000 * kMs;  // any host clock: a monotonic one in the daemon

using test::box;

// Drives a monitor at 5 Hz with every required sensor fresh unless told otherwise.
class Drive {
 public:
  explicit Drive(Params p) : params(p), monitor(p) {}

  Decision frame(std::vector<perception::Obstacle> obstacles = {}, std::optional<double> speed = std::nullopt) {
    t_ += 200 * kMs;
    obstacles_ = std::move(obstacles);
    FrameInput f{obstacles_, Stamp{t_ - 50 * kMs}, speed};
    Input in = inputs();
    in.frame = &f;
    return record(monitor.update(in));
  }
  Decision tick(std::int64_t after_ms) {
    t_ += after_ms * kMs;
    return record(monitor.update(inputs()));
  }
  // Frame whose data ended `latency_ms` before the decision.
  Decision late_frame(std::int64_t latency_ms) {
    t_ += 200 * kMs;
    obstacles_.clear();
    FrameInput f{obstacles_, Stamp{t_ - latency_ms * kMs}, std::nullopt};
    Input in = inputs();
    in.frame = &f;
    return record(monitor.update(in));
  }
  void silence(Sensor s) { silent_[static_cast<std::size_t>(s)] = true; }
  void resume(Sensor s) { silent_[static_cast<std::size_t>(s)] = false; }
  void problem(Sensor s, Problem p) { problem_[static_cast<std::size_t>(s)] = p; }
  void no_address(bool v) { no_address_ = v; }
  [[nodiscard]] std::int64_t now() const { return t_; }

  Params params;
  Monitor monitor;
  std::vector<Event> events;

 private:
  Input inputs() {
    Input in;
    in.now = Stamp{t_};
    in.no_address = no_address_;
    for (std::size_t i = 0; i < kSensorCount; ++i) {
      if (!silent_[i]) last_[i] = t_ - 10 * kMs;  // heard 10 ms ago
      in.sensors[i].last_data = Stamp{last_[i]};
      in.sensors[i].problem = problem_[i];
      problem_[i] = Problem::None;  // a problem is reported for one update, as GnssCheck::take() does
    }
    return in;
  }
  Decision record(Decision d) {
    if (d.event) events.push_back(*d.event);
    return d;
  }
  std::int64_t t_ = kT0;
  std::vector<perception::Obstacle> obstacles_;
  std::array<bool, kSensorCount> silent_{};
  std::array<std::int64_t, kSensorCount> last_{};
  std::array<Problem, kSensorCount> problem_{};
  bool no_address_ = false;
};

Params lidar_and_ahrs() {
  Params p;
  p.sensor(Sensor::Ahrs).required = true;
  p.clear_frames = 3;
  return p;
}

// Until the first update at which every sensor is fresh, the reason is start-up.
Drive started(Params p = lidar_and_ahrs()) {
  Drive d(p);
  d.frame();
  return d;
}

TEST(SafetyMonitor, RejectsInvalidParameters) {
  Params p;
  p.clear_frames = 0;
  EXPECT_THROW(Monitor{p}, std::invalid_argument);
}

TEST(SafetyMonitor, StartsStoppedAndWaitsForEveryRequiredSensor) {
  Drive d(lidar_and_ahrs());
  d.silence(Sensor::Ahrs);
  // AHRS never heard: starting up, naming it.
  Decision r = d.tick(0);
  EXPECT_TRUE(r.stop);
  EXPECT_EQ(r.reason, Reason::StartingUp);
  EXPECT_EQ(r.fault_sensors, bit(Sensor::Ahrs));
  ASSERT_TRUE(r.event);
  EXPECT_TRUE(r.event->first);
  EXPECT_EQ(r.event->text, "stop: starting up: waiting for ahrs");
  for (int i = 0; i < 5; ++i) {
    r = d.frame();
    EXPECT_TRUE(r.stop);
    EXPECT_EQ(r.reason, Reason::StartingUp);
    EXPECT_FALSE(r.event) << "no event per frame";
  }
  EXPECT_FALSE(d.monitor.started());
  d.resume(Sensor::Ahrs);
  r = d.frame();  // started, first clear frame
  EXPECT_TRUE(d.monitor.started());
  EXPECT_TRUE(r.stop);
  EXPECT_EQ(r.reasons, 0);
  EXPECT_EQ(r.reason, Reason::StartingUp);  // held until the clear frames are counted
  EXPECT_EQ(r.clear_frames, 1);
  d.frame();
  r = d.frame();
  EXPECT_FALSE(r.stop);
  EXPECT_EQ(r.reason, Reason::None);
  ASSERT_TRUE(r.event);
  EXPECT_EQ(r.event->text, "go: every reason clear for 3 frames");
  EXPECT_TRUE(r.event->was_stop);
  EXPECT_EQ(r.event->previous_reason, Reason::StartingUp);
  EXPECT_EQ(d.events.size(), 2U);
}

TEST(SafetyMonitor, FirstDecisionWithEverySensorHeardSaysWhatStartUpWaitsFor) {
  // Every sensor fresh at the very first frame: started, but go waits for the clear frames. The event says so
  // (it read "waiting for " with no sensor named).
  Drive d(lidar_and_ahrs());
  const Decision r = d.frame();
  EXPECT_TRUE(d.monitor.started());
  EXPECT_EQ(r.reason, Reason::StartingUp);
  ASSERT_TRUE(r.event);
  EXPECT_EQ(r.event->text, "stop: starting up: every required sensor heard, clear 1 of 3 frames");
  EXPECT_EQ(headline(r, 3), "STOP starting up, clear 1 of 3 frames");
}

TEST(SafetyMonitor, HeadlineIsTheDecisionAndItsReasonInAFewWords) {
  Drive d(lidar_and_ahrs());
  d.silence(Sensor::Ahrs);
  EXPECT_EQ(headline(d.tick(0), 3), "STOP starting up: waiting for ahrs");
  d.resume(Sensor::Ahrs);
  for (int i = 0; i < 3; ++i) d.frame();
  EXPECT_EQ(headline(d.frame(), 3), "GO");
  // An obstacle: how far ahead its near edge is, rounded to a decimetre; then, gone, how far the clearing is.
  EXPECT_EQ(headline(d.frame({box(5.44F, -0.3F, 6.0F, 0.3F)}), 3), "STOP obstacle 5.4 m ahead");
  EXPECT_EQ(headline(d.frame({box(7.0F, -0.3F, 8.0F, 0.3F), box(4.96F, 0.5F, 5.5F, 1.0F)}), 3),
            "STOP obstacle 5.0 m ahead");
  EXPECT_EQ(headline(d.frame(), 3), "STOP obstacle gone, clear 1 of 3 frames");
  d.frame();
  EXPECT_EQ(headline(d.frame(), 3), "GO");
  // A box reaching behind the sensor: 0.0 m, not a negative distance.
  EXPECT_EQ(headline(d.frame({box(-1.0F, -0.3F, 1.0F, 0.3F)}), 3), "STOP obstacle 0.0 m ahead");
  for (int i = 0; i < 3; ++i) d.frame();
  // Sensor faults and implausible data name the sensor; the clearing after them says so.
  d.silence(Sensor::Ahrs);
  EXPECT_EQ(headline(d.tick(500), 3), "STOP ahrs silent");
  d.resume(Sensor::Ahrs);
  EXPECT_EQ(headline(d.frame(), 3), "STOP sensor fault cleared, clear 1 of 3 frames");
  for (int i = 0; i < 2; ++i) d.frame();
  d.problem(Sensor::Lidar, Problem::TimeWentBack);
  EXPECT_EQ(headline(d.frame(), 3), "STOP lidar implausible");
  EXPECT_EQ(headline(d.frame(), 3), "STOP implausible data cleared, clear 1 of 3 frames");
  for (int i = 0; i < 2; ++i) d.frame();
  EXPECT_EQ(headline(d.late_frame(420), 3), "STOP pipeline late");
  d.no_address(true);
  EXPECT_EQ(headline(d.tick(10), 3), "STOP no CAN address");
}

TEST(SafetyMonitor, FaultsOfTheMonitorsOwnViewAreWarningsAndNoAddressAnError) {
  EXPECT_EQ(severity(Reason::None), Severity::Info);
  EXPECT_EQ(severity(Reason::StartingUp), Severity::Info);
  EXPECT_EQ(severity(Reason::ObstacleInZone), Severity::Info);
  EXPECT_EQ(severity(Reason::SensorFault), Severity::Warning);
  EXPECT_EQ(severity(Reason::ImplausibleData), Severity::Warning);
  EXPECT_EQ(severity(Reason::PipelineLate), Severity::Warning);
  EXPECT_EQ(severity(Reason::NoAddress), Severity::Error);
}

TEST(SafetyMonitor, StartUpSilenceIsNotASensorFault) {
  Drive d(lidar_and_ahrs());
  d.silence(Sensor::Lidar);
  const Decision r = d.tick(5000);  // never heard, however long
  EXPECT_EQ(r.reasons, bit(Reason::StartingUp));
}

TEST(SafetyMonitor, ObstacleInTheZoneStops) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  ASSERT_FALSE(d.frame().stop);
  const Decision r = d.frame({box(6.0F, -0.3F, 6.5F, 0.3F)});
  EXPECT_TRUE(r.stop);
  EXPECT_EQ(r.reason, Reason::ObstacleInZone);
  EXPECT_EQ(r.reasons, bit(Reason::ObstacleInZone));
  EXPECT_EQ(r.obstacles_in_zone, 1);
  ASSERT_TRUE(r.event);
  EXPECT_FALSE(r.event->was_stop);
  EXPECT_EQ(
      r.event->text.rfind("stop: obstacle in zone: 1 obstacle, nearest box x 6.00..6.50 m, y -0.30..0.30 m; zone x "
                          "-5.00..",
                          0),
      0U)
      << r.event->text;
  EXPECT_NE(r.event->text.find("(speed unknown)"), std::string::npos) << r.event->text;
}

TEST(SafetyMonitor, ObstacleOutsideTheZoneDoesNotStop) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  // Beyond the full-speed zone (0.4 + 17 m with the defaults), and beside it beyond 2 m.
  const Decision r =
      d.frame({box(25.0F, -0.5F, 26.0F, 0.5F), box(5.0F, 2.2F, 6.0F, 3.0F), box(3.0F, -4.0F, 4.0F, -2.05F)});
  EXPECT_FALSE(r.stop);
  EXPECT_EQ(r.obstacles_in_zone, 0);
  EXPECT_FALSE(r.event);
}

TEST(SafetyMonitor, BoxOverlappingTheZoneEdgeStopsThoughItsCentreIsOutside) {
  // Through the monitor: the edge box stops the tractor.
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  EXPECT_TRUE(d.frame({box(5.0F, 1.9F, 6.0F, 3.0F)}).stop);
}

TEST(SafetyMonitor, GoOnlyAfterNClearFramesAndASingleClearFrameDoesNot) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  const auto ped = box(8.0F, -0.2F, 8.4F, 0.3F);
  EXPECT_TRUE(d.frame({ped}).stop);
  // Obstacle, one clear frame, obstacle: never go, and no event between (the reason never changed).
  const std::size_t events = d.events.size();
  Decision r = d.frame();
  EXPECT_TRUE(r.stop);
  EXPECT_EQ(r.reason, Reason::ObstacleInZone);
  EXPECT_EQ(r.reasons, 0);
  EXPECT_EQ(r.clear_frames, 1);
  r = d.frame({ped});
  EXPECT_TRUE(r.stop);
  EXPECT_EQ(r.clear_frames, 0);
  r = d.frame();
  EXPECT_TRUE(r.stop);
  r = d.frame();
  EXPECT_TRUE(r.stop);
  EXPECT_EQ(r.clear_frames, 2);
  EXPECT_EQ(d.events.size(), events);
  r = d.frame();
  EXPECT_FALSE(r.stop);
  ASSERT_TRUE(r.event);
  EXPECT_EQ(r.event->text, "go: every reason clear for 3 frames");
  EXPECT_EQ(r.event->previous_reason, Reason::ObstacleInZone);
}

TEST(SafetyMonitor, TicksBetweenFramesCountNoClearFrame) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  d.frame({box(8.0F, -0.2F, 8.4F, 0.3F)});
  d.frame();
  for (int i = 0; i < 10; ++i) {
    const Decision r = d.tick(10);
    EXPECT_TRUE(r.stop);
    EXPECT_EQ(r.clear_frames, 1);
  }
}

TEST(SafetyMonitor, ObstacleStaysInZoneThroughTicks) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  d.frame({box(8.0F, -0.2F, 8.4F, 0.3F)});
  const Decision r = d.tick(100);
  EXPECT_EQ(r.reasons, bit(Reason::ObstacleInZone));
  EXPECT_FALSE(r.event);
}

TEST(SafetyMonitor, SensorGoingSilentStopsNamingItAndComingBackGoesAfterNFrames) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  d.silence(Sensor::Ahrs);  // last heard 10 ms before `now`, timeout 0.1 s
  Decision r = d.tick(50);  // silent 60 ms: fine
  EXPECT_FALSE(r.stop);
  r = d.tick(50);  // 110 ms
  EXPECT_TRUE(r.stop);
  EXPECT_EQ(r.reason, Reason::SensorFault);
  EXPECT_EQ(r.fault_sensors, bit(Sensor::Ahrs));
  ASSERT_TRUE(r.event);
  EXPECT_EQ(r.event->sensors, bit(Sensor::Ahrs));
  EXPECT_EQ(r.event->text, "stop: sensor fault: ahrs silent 0.110 s (timeout 0.100 s)");
  // Silent on: no new event, frames or ticks.
  for (int i = 0; i < 4; ++i) {
    EXPECT_FALSE(d.frame().event);
    EXPECT_FALSE(d.tick(20).event);
  }
  // The LiDAR too: the same reason, another sensor: one event naming both.
  d.silence(Sensor::Lidar);
  r = d.tick(400);
  ASSERT_TRUE(r.event);
  EXPECT_EQ(r.fault_sensors, bit(Sensor::Ahrs) | bit(Sensor::Lidar));
  EXPECT_NE(r.event->text.find("sensor fault: lidar silent"), std::string::npos) << r.event->text;
  EXPECT_NE(r.event->text.find(", ahrs silent"), std::string::npos) << r.event->text;
  d.resume(Sensor::Lidar);
  d.resume(Sensor::Ahrs);
  r = d.frame();
  EXPECT_TRUE(r.stop);
  EXPECT_EQ(r.reasons, 0);
  EXPECT_EQ(r.reason, Reason::SensorFault);
  d.frame();
  r = d.frame();
  EXPECT_FALSE(r.stop);
  ASSERT_TRUE(r.event);
  EXPECT_EQ(r.event->previous_reason, Reason::SensorFault);
}

TEST(SafetyMonitor, SilenceOrProblemsOfASensorThatIsNotRequiredAreIgnored) {
  Drive d = started();
  d.silence(Sensor::Gnss);
  d.silence(Sensor::Scan2d);
  Decision r{};
  for (int i = 0; i < 10; ++i) {
    d.problem(Sensor::Gnss, Problem::NoFix);
    r = d.frame();
  }
  EXPECT_FALSE(r.stop);
  EXPECT_EQ(r.fault_sensors, 0);
  EXPECT_EQ(r.implausible_sensors, 0);
}

TEST(SafetyMonitor, ImplausibleDataStopsNamingSensorAndProblem) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  d.problem(Sensor::Ahrs, Problem::RollBeyondLimit);
  Decision r = d.frame();
  EXPECT_TRUE(r.stop);
  EXPECT_EQ(r.reason, Reason::ImplausibleData);
  EXPECT_EQ(r.implausible_sensors, bit(Sensor::Ahrs));
  ASSERT_TRUE(r.event);
  EXPECT_EQ(r.event->text, "stop: implausible data: ahrs roll beyond limit");
  // Plausible again: go after the clear frames.
  d.frame();
  d.frame();
  r = d.frame();
  EXPECT_FALSE(r.stop);
}

TEST(SafetyMonitor, ImplausibleDataDuringStartUpIsReportedAndDelaysStart) {
  Drive d(lidar_and_ahrs());
  d.problem(Sensor::Ahrs, Problem::NotFinite);
  const Decision r = d.frame();
  EXPECT_FALSE(d.monitor.started());
  EXPECT_EQ(r.reasons, bit(Reason::StartingUp) | bit(Reason::ImplausibleData));
  EXPECT_EQ(r.reason, Reason::ImplausibleData);
  EXPECT_EQ(r.event->text, "stop: implausible data: ahrs not a number; also starting up");
}

TEST(SafetyMonitor, PipelineLaterThanItsDeadlineStops) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  EXPECT_FALSE(d.late_frame(290).stop);  // deadline 0.3 s
  const Decision r = d.late_frame(420);
  EXPECT_TRUE(r.stop);
  EXPECT_EQ(r.reason, Reason::PipelineLate);
  ASSERT_TRUE(r.event);
  EXPECT_EQ(r.event->text, "stop: pipeline late: frame decided 0.420 s after its data (deadline 0.300 s)");
  // Stays late through the ticks until a frame on time.
  EXPECT_EQ(d.tick(50).reasons, bit(Reason::PipelineLate));
  EXPECT_EQ(d.frame().reasons, 0);
}

TEST(SafetyMonitor, NoFrameForTooLongIsAStalledPipeline) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  EXPECT_FALSE(d.tick(400).stop);  // 0.4 s since the last frame, limit 0.5 s
  const Decision r = d.tick(200);
  EXPECT_TRUE(r.stop);
  EXPECT_EQ(r.reason, Reason::PipelineLate);
  EXPECT_EQ(r.event->text, "stop: pipeline late: no frame for 0.600 s (limit 0.500 s)");
}

TEST(SafetyMonitor, StalledRightAfterStartUpIsLateToo) {
  Drive d(lidar_and_ahrs());
  d.tick(0);  // started by sensors alone, no frame yet
  EXPECT_TRUE(d.monitor.started());
  EXPECT_EQ(d.tick(600).reasons, bit(Reason::PipelineLate));
}

TEST(SafetyMonitor, HighestReasonIsReportedWithEveryActiveOneInTheMask) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  d.silence(Sensor::Ahrs);
  d.tick(500);
  d.problem(Sensor::Lidar, Problem::TimeWentBack);
  const Decision r = d.frame({box(4.0F, -1.0F, 5.0F, 1.0F)});
  EXPECT_EQ(r.reason, Reason::SensorFault);
  EXPECT_EQ(r.reasons, bit(Reason::SensorFault) | bit(Reason::ImplausibleData) | bit(Reason::ObstacleInZone));
  EXPECT_EQ(r.implausible_sensors, bit(Sensor::Lidar));
}

TEST(SafetyMonitor, NoCanAddressStopsAheadOfEveryOtherReason) {
  Drive d = started();
  d.silence(Sensor::Ahrs);
  d.no_address(true);
  const Decision s = d.tick(400);
  EXPECT_TRUE(s.stop);
  EXPECT_EQ(s.reason, Reason::NoAddress);
  EXPECT_NE(s.reasons & bit(Reason::SensorFault), 0) << "the silent AHRS stays in the mask";
  ASSERT_TRUE(s.event);
  EXPECT_EQ(s.event->text.rfind("stop: no CAN address", 0), 0U) << s.event->text;
  EXPECT_NE(s.event->text.find("another node holds our J1939 address"), std::string::npos) << s.event->text;
  d.resume(Sensor::Ahrs);
  d.no_address(false);
  EXPECT_TRUE(d.frame().stop) << "an address again, then the clear frames as for any reason";
  Decision last;
  for (int i = 0; i < d.params.clear_frames; ++i) last = d.frame();
  EXPECT_FALSE(last.stop);
}

TEST(SafetyMonitor, ChangeOfReasonIsOneEvent) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  const auto ped = box(8.0F, -0.2F, 8.4F, 0.3F);
  d.frame({ped});
  d.silence(Sensor::Ahrs);
  Decision r = d.frame({ped});
  ASSERT_TRUE(r.event);
  EXPECT_EQ(r.event->previous_reason, Reason::ObstacleInZone);
  EXPECT_EQ(r.event->text.rfind("stop: sensor fault (was obstacle in zone): ahrs silent", 0), 0U) << r.event->text;
  EXPECT_NE(r.event->text.find("; also obstacle in zone"), std::string::npos) << r.event->text;
  EXPECT_FALSE(d.frame({ped}).event);
  d.resume(Sensor::Ahrs);
  r = d.frame({ped});
  ASSERT_TRUE(r.event);
  EXPECT_EQ(r.reason, Reason::ObstacleInZone);
  EXPECT_EQ(r.event->previous_reason, Reason::SensorFault);
}

TEST(SafetyMonitor, ZoneScalesWithSpeed) {
  Params p = lidar_and_ahrs();
  p.zone.reaction_time_s = 0.0;
  p.zone.margin_m = 1.0;
  p.zone.min_length_m = 3.0;
  Drive d = started(p);
  for (int i = 0; i < 3; ++i) d.frame();
  // 10 m ahead of the front (x 10.4 m): inside the zone at 30 km/h (11.8 + 1 m) ...
  const auto at10 = box(10.4F, -0.2F, 10.8F, 0.2F);
  Decision r = d.frame({at10}, 30.0 / 3.6);
  EXPECT_TRUE(r.stop);
  EXPECT_TRUE(r.zone.speed_known);
  EXPECT_NEAR(r.zone.x_max_m, 0.4 + 11.8 + 1.0, 0.01);
  EXPECT_NE(r.event->text.find("at 30.0 km/h"), std::string::npos) << r.event->text;
  // ... and outside it at 10 km/h (1.31 + 1 m, floored at 3 m).
  for (int i = 0; i < 3; ++i) r = d.frame({at10}, 10.0 / 3.6);
  EXPECT_FALSE(r.stop);
  EXPECT_NEAR(r.zone.x_max_m, 0.4 + 3.0, 1e-9);
  // Speed lost: the full-speed zone again.
  r = d.frame({at10}, std::nullopt);
  EXPECT_TRUE(r.stop);
  EXPECT_FALSE(r.zone.speed_known);
  EXPECT_NEAR(r.zone.x_max_m, 0.4 + 12.8, 0.01);
}

TEST(SafetyMonitor, NaNSpeedIsUnknownSpeed) {
  Drive d = started();
  const Decision r = d.frame({}, std::numeric_limits<double>::quiet_NaN());
  EXPECT_FALSE(r.zone.speed_known);
  EXPECT_DOUBLE_EQ(r.zone.x_max_m, d.monitor.zone_for(std::nullopt).x_max_m);
}

TEST(SafetyMonitor, ObstacleWithANaNBoxIsTakenToBeInTheZone) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  auto o = box(30.0F, 5.0F, 31.0F, 6.0F);  // far outside, but for its NaN
  o.min[1] = kNaNf;
  const Decision r = d.frame({o});
  EXPECT_TRUE(r.stop);
  EXPECT_EQ(r.reason, Reason::ObstacleInZone);
  EXPECT_EQ(r.unplaceable_obstacles, 1);
  EXPECT_NE(r.event->text.find("1 with a non-finite box"), std::string::npos) << r.event->text;
}

TEST(SafetyMonitor, FrameWithoutADataTimeIsLate) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  std::vector<perception::Obstacle> none;
  FrameInput f{none, Stamp{0}, std::nullopt};
  Input in;
  in.now = Stamp{d.now() + 200 * kMs};
  for (auto& s : in.sensors) s.last_data = Stamp{d.now() + 190 * kMs};
  in.frame = &f;
  Monitor& m = d.monitor;
  const Decision r = m.update(in);
  EXPECT_EQ(r.reasons, bit(Reason::PipelineLate));
  EXPECT_EQ(r.event->text, "stop: pipeline late: the frame has no data time");
}

TEST(SafetyMonitor, DataStampedFarAheadOfTheClockCannotVouchForASensor) {
  Drive d = started();
  for (int i = 0; i < 3; ++i) d.frame();
  Input in;
  in.now = Stamp{d.now() + 100 * kMs};
  for (auto& s : in.sensors) s.last_data = Stamp{d.now() + 95 * kMs};
  in.sensors[static_cast<std::size_t>(Sensor::Lidar)].last_data = Stamp{d.now() + 5000 * kMs};
  const Decision r = d.monitor.update(in);
  EXPECT_EQ(r.reason, Reason::SensorFault);
  EXPECT_NE(r.event->text.find("lidar data stamped 4.900 s ahead of the monitor's clock"), std::string::npos)
      << r.event->text;
}

TEST(SafetyMonitor, SameInputsGiveTheSameDecisions) {
  auto run = [] {
    Drive d = started();
    std::vector<std::string> texts;
    for (int i = 0; i < 40; ++i) {
      if (i % 7 == 3) d.silence(Sensor::Ahrs);
      if (i % 7 == 5) d.resume(Sensor::Ahrs);
      std::vector<perception::Obstacle> obs;
      if (i % 5 == 0) obs.push_back(box(6.0F, -0.3F, 6.5F, 0.3F));
      const Decision r = d.frame(obs, i % 2 ? std::optional<double>(3.0) : std::nullopt);
      texts.push_back(std::to_string(r.stop) + std::to_string(static_cast<int>(r.reason)) + std::to_string(r.reasons) +
                      (r.event ? r.event->text : ""));
      d.tick(60);
    }
    return texts;
  };
  EXPECT_EQ(run(), run());
}

}  // namespace
}  // namespace fieldguard::output::safety
