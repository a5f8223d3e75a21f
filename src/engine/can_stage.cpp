#include "fieldguard/engine/can_stage.hpp"

#include <chrono>
#include <cmath>

#include "fieldguard/engine/logging.hpp"

namespace fieldguard::app {
namespace {

namespace safety = output::safety;

}  // namespace

CanStage::CanStage(const Config& cfg, output::CanSink& sink) : cfg_(cfg), link_(cfg.can, sink), monitor_(cfg.safety) {}

void CanStage::start(Stamp t) {
  // The claim one hold time before the capture's first data, as a daemon started before its sensors has claimed
  // its address by the time they speak: every decision of the capture reaches the log.
  link_.start(Stamp{t.ns - link_.claim_hold().count()});
  link_.schedule().tick(t, heartbeat(0));
}

void CanStage::sensor_data(safety::Sensor s, Stamp t) { input_.sensors[static_cast<std::size_t>(s)].last_data = t; }

void CanStage::sensor_problem(safety::Sensor s, safety::Problem p) {
  auto& slot = input_.sensors[static_cast<std::size_t>(s)].problem;
  if (slot == safety::Problem::None) slot = p;
}

void CanStage::tick(Stamp now, std::uint64_t frames_lost) {
  link_.schedule().tick(now, heartbeat(frames_lost));
  link_.advance(now);
}

output::StopRequest CanStage::request_for(const safety::Decision& d) {
  output::StopRequest r;
  r.command = d.stop ? output::StopCommand::Stop : output::StopCommand::Go;
  if (!d.stop) return r;
  const auto reasons = static_cast<std::uint8_t>(d.reasons | safety::bit(d.reason));
  auto has = [&](safety::Reason x) { return (reasons & safety::bit(x)) != 0; };
  r.reasons.obstacle_in_zone = has(safety::Reason::ObstacleInZone);
  // The DBC has no bit of its own for implausible data: to the controller it is a sensor it cannot trust.
  r.reasons.sensor_fault = has(safety::Reason::SensorFault) || has(safety::Reason::ImplausibleData);
  r.reasons.pipeline_late = has(safety::Reason::PipelineLate);
  r.reasons.starting_up = has(safety::Reason::StartingUp);
  return r;
}

output::Heartbeat CanStage::heartbeat(std::uint64_t frames_lost) const {
  return heartbeat_for(cfg_.safety, last_, frames_lost);
}

output::Heartbeat CanStage::heartbeat_for(const safety::Params& safety, const std::optional<safety::Decision>& last,
                                          std::uint64_t frames_lost) {
  auto health = [&](safety::Sensor s) {
    if (!safety.sensor(s).required) return output::SensorHealth::NotRequired;
    if (!last) return output::SensorHealth::Unknown;
    const auto bad = static_cast<std::uint8_t>(last->fault_sensors | last->implausible_sensors);
    return (bad & safety::bit(s)) != 0 ? output::SensorHealth::Fault : output::SensorHealth::Ok;
  };
  output::Heartbeat h;
  h.lidar3d = health(safety::Sensor::Lidar);
  h.lidar2d = health(safety::Sensor::Scan2d);
  h.gnss = health(safety::Sensor::Gnss);
  h.ahrs = health(safety::Sensor::Ahrs);
  h.frames_lost = frames_lost;
  return h;
}

void CanStage::frame(const LidarFrame& f, const perception::FrameResult& result, Stamp complete,
                     std::uint64_t frames_lost) {
  // Heartbeats due before this decision go out first, with what was known then: the log stays in time order.
  link_.schedule().tick(complete, heartbeat(frames_lost));
  input_.now = complete;
  input_.no_address = link_.no_address();
  input_.sensors[static_cast<std::size_t>(safety::Sensor::Lidar)].last_data = complete;
  safety::FrameInput frame_in;
  frame_in.obstacles = result.obstacles;
  frame_in.data_end = complete;
  input_.frame = &frame_in;
  last_ = monitor_.update(input_);
  input_.frame = nullptr;
  for (auto& s : input_.sensors) s.problem = safety::Problem::None;

  const safety::Decision& d = *last_;
  link_.decided(d, complete);
  if (d.stop) {
    ++counts_.stop_frames;
  } else {
    ++counts_.go_frames;
  }
  if (d.event) {
    ++counts_.changes;
    log_safety_event(*d.event, "rotation " + std::to_string(f.index));
  }
  output::FrameReport report;
  report.frame_counter = static_cast<std::uint32_t>(f.index);
  report.status = f.partial ? output::FrameStatus::PartialFrame : output::FrameStatus::Ok;
  report.obstacles = result.obstacles;
  link_.schedule().frame(report, request_for(d), complete);
}

}  // namespace fieldguard::app
