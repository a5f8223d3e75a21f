#pragma once
// The daemon's output stage: the safety monitor and the CAN schedule on the host clock. Unlike replay's
// CanStage, which decides only when a rotation is finished, the live stage also decides between rotations
// (every tick of the output timer), so a 3D LiDAR that falls silent or a pipeline that stalls turns into
// STOP within the sensor's timeout even though no rotation ever arrives to carry the news. The per-rotation
// mapping to the CAN stop request is CanStage's (request_for), so replay and the daemon say the same thing.
// Thread-compatible: the io thread calls everything.

#include <cstdint>
#include <optional>
#include <utility>

#include "fieldguard/config/config.hpp"
#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/core/time.hpp"
#include "fieldguard/engine/can_link.hpp"
#include "fieldguard/output/can_encoder.hpp"
#include "fieldguard/output/safety_monitor.hpp"
#include "fieldguard/perception/obstacle.hpp"

namespace fieldguard::app {

struct LiveStageCounts {
  std::uint64_t frames = 0;  // rotations decided
  std::uint64_t stop_frames = 0;
  std::uint64_t go_frames = 0;
  std::uint64_t changes = 0;  // monitor events, each logged once
};

class LiveStage {
 public:
  // `cfg` and `link` must outlive the stage; the link (the encoder's counters, the schedule's cycle, the J1939
  // node) outlives it across reloads. Throws std::invalid_argument for parameters the loader should have refused.
  LiveStage(const Config& cfg, CanLink& link);

  // A sensor's data arrived at host time `t` (the 3D LiDAR: every datagram).
  void sensor_data(output::safety::Sensor s, Stamp t);
  // The tractor's speed from the bus, received at `t`; a frame decided within can.speed_timeout_s of it sizes
  // the stop zone with it (older: unknown, the zone's full-speed length).
  void vehicle_speed(double speed_mps, Stamp t);
  // The last speed from the bus if received within can.speed_timeout_s before `now`; else unknown.
  [[nodiscard]] std::optional<double> speed_at(Stamp now) const;
  // A GNSS or AHRS sample failed its plausibility check; the next decision (frame or tick) sees it.
  void sensor_problem(output::safety::Sensor s, output::safety::Problem p);
  // A finished rotation, decided at `now`; `data_end`: the receive time of the packet that completed it.
  const output::safety::Decision& frame(const LidarFrame& f, const perception::FrameResult& result, Stamp data_end,
                                        Stamp now, std::uint64_t frames_lost);
  // No rotation: timeouts are checked (a change of the stop request goes out at once) and heartbeats sent.
  const output::safety::Decision& tick(Stamp now, std::uint64_t frames_lost);
  // The last word before the process ends: STOP, shutting down.
  void shutdown(Stamp now);

  [[nodiscard]] bool started() const { return monitor_.started(); }
  [[nodiscard]] const LiveStageCounts& counts() const { return counts_; }
  [[nodiscard]] const CanLink& link() const { return link_; }
  [[nodiscard]] const std::optional<output::safety::Decision>& last_decision() const { return last_; }
  // The host time of the sensor's newest data, as the monitor sees it (the 3D LiDAR: its newest datagram); 0 = never.
  [[nodiscard]] Stamp last_data(output::safety::Sensor s) const {
    return input_.sensors[static_cast<std::size_t>(s)].last_data;
  }

 private:
  [[nodiscard]] output::Heartbeat heartbeat(std::uint64_t frames_lost) const;
  void note(const output::safety::Decision& d, const char* what);

  const Config& cfg_;
  CanLink& link_;
  output::safety::Monitor monitor_;
  output::safety::Input input_;
  std::optional<output::safety::Decision> last_;
  std::optional<output::StopRequest> sent_;        // the stop request the schedule repeats
  std::optional<std::pair<double, Stamp>> speed_;  // m/s, receive time
  LiveStageCounts counts_;
};

[[nodiscard]] bool same_request(const output::StopRequest& a, const output::StopRequest& b);

}  // namespace fieldguard::app
