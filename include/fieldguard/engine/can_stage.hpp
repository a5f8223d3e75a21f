#pragma once
// The output stage the daemon and replay share: each finished rotation goes to the safety monitor, and its
// obstacles, the stop request and the heartbeats go to a CAN sink on one clock (replay: capture time; live:
// the host clock). Runs on the output thread only, rotations in order (thread-compatible).

#include <cstdint>
#include <memory>
#include <optional>

#include "fieldguard/config/config.hpp"
#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/core/time.hpp"
#include "fieldguard/engine/can_link.hpp"
#include "fieldguard/output/can_encoder.hpp"
#include "fieldguard/output/can_sink.hpp"
#include "fieldguard/output/safety_monitor.hpp"
#include "fieldguard/perception/obstacle.hpp"

namespace fieldguard::app {

struct CanStageCounts {
  std::uint64_t stop_frames = 0;  // rotations decided stop
  std::uint64_t go_frames = 0;    // rotations decided go
  std::uint64_t changes = 0;      // state changes (monitor events), each logged once
};

class CanStage {
 public:
  // `sink` must outlive the stage. Throws std::invalid_argument for parameters the loader should have refused.
  CanStage(const Config& cfg, output::CanSink& sink);

  // The first data at `t`: the heartbeat clock starts, the address claim (can.j1939) stamped 250 ms (its hold)
  // before; until the first rotation is decided the stop request says STOP, starting up.
  void start(Stamp t);
  // One rotation, decided at `complete` (when its last packet was in hand, which is also the 3D LiDAR's newest
  // receive time); the other sensors count as never heard unless given with sensor_data().
  void frame(const LidarFrame& f, const perception::FrameResult& result, Stamp complete, std::uint64_t frames_lost);
  // A sensor other than the 3D LiDAR was heard at `t` (live: the io threads' receive times).
  void sensor_data(output::safety::Sensor s, Stamp t);
  // A GNSS or AHRS sample failed its plausibility check (SensorFusion::take_problems()); the next decision
  // sees the first such problem.
  void sensor_problem(output::safety::Sensor s, output::safety::Problem p);
  // Heartbeats (with the latest stop request) due up to `now`.
  void tick(Stamp now, std::uint64_t frames_lost);

  [[nodiscard]] const CanStageCounts& counts() const { return counts_; }
  [[nodiscard]] const std::optional<output::safety::Decision>& last_decision() const { return last_; }
  [[nodiscard]] const CanLink& link() const { return link_; }

  // The stop request for a decision: while a stop is held for clear frames its reason is the one that caused it.
  [[nodiscard]] static output::StopRequest request_for(const output::safety::Decision& d);
  // The heartbeat's health bits for the latest decision (none yet: Unknown for each required sensor).
  [[nodiscard]] static output::Heartbeat heartbeat_for(const output::safety::Params& safety,
                                                       const std::optional<output::safety::Decision>& last,
                                                       std::uint64_t frames_lost);

 private:
  [[nodiscard]] output::Heartbeat heartbeat(std::uint64_t frames_lost) const;

  const Config& cfg_;
  CanLink link_;
  output::safety::Monitor monitor_;
  output::safety::Input input_;
  std::optional<output::safety::Decision> last_;
  CanStageCounts counts_;
};

}  // namespace fieldguard::app
