#include "daemon/run_stage.hpp"

#include <chrono>

#include "fieldguard/engine/can_stage.hpp"
#include "fieldguard/engine/logging.hpp"

namespace fieldguard::app {
namespace {

namespace safety = output::safety;

}  // namespace

bool same_request(const output::StopRequest& a, const output::StopRequest& b) {
  return a.command == b.command && a.reasons.obstacle_in_zone == b.reasons.obstacle_in_zone &&
         a.reasons.sensor_fault == b.reasons.sensor_fault && a.reasons.pipeline_late == b.reasons.pipeline_late &&
         a.reasons.starting_up == b.reasons.starting_up && a.reasons.shutting_down == b.reasons.shutting_down;
}

LiveStage::LiveStage(const Config& cfg, CanLink& link) : cfg_(cfg), link_(link), monitor_(cfg.safety) {}

void LiveStage::sensor_data(safety::Sensor s, Stamp t) {
  auto& last = input_.sensors[static_cast<std::size_t>(s)].last_data;
  if (t.ns > last.ns) last = t;
}

void LiveStage::vehicle_speed(double speed_mps, Stamp t) { speed_ = {speed_mps, t}; }

std::optional<double> LiveStage::speed_at(Stamp now) const {
  if (speed_ && static_cast<double>(now.ns - speed_->second.ns) * 1e-9 <= cfg_.can.speed_timeout_s) {
    return speed_->first;
  }
  return std::nullopt;
}

void LiveStage::sensor_problem(safety::Sensor s, safety::Problem p) {
  auto& slot = input_.sensors[static_cast<std::size_t>(s)].problem;
  if (slot == safety::Problem::None) slot = p;
}

void LiveStage::note(const safety::Decision& d, const char* what) {
  if (!d.event) return;
  ++counts_.changes;
  log_safety_event(*d.event, what);
}

const safety::Decision& LiveStage::frame(const LidarFrame& f, const perception::FrameResult& result, Stamp data_end,
                                         Stamp now, std::uint64_t frames_lost) {
  // Cycles due before this decision go out first, with what was known then: the log stays in time order.
  link_.start(now);
  link_.schedule().tick(now, heartbeat(frames_lost));
  input_.now = now;
  input_.no_address = link_.no_address();
  safety::FrameInput frame_in;
  frame_in.obstacles = result.obstacles;
  frame_in.data_end = data_end;
  frame_in.speed_mps = speed_at(now);
  input_.frame = &frame_in;
  last_ = monitor_.update(input_);
  input_.frame = nullptr;
  for (auto& s : input_.sensors) s.problem = safety::Problem::None;
  const safety::Decision& d = *last_;
  link_.decided(d, now);
  ++counts_.frames;
  ++(d.stop ? counts_.stop_frames : counts_.go_frames);
  if (d.event) note(d, ("rotation " + std::to_string(f.index)).c_str());  // the label only when there is news
  output::FrameReport report;
  report.frame_counter = static_cast<std::uint32_t>(f.index);
  report.status = f.partial ? output::FrameStatus::PartialFrame : output::FrameStatus::Ok;
  report.obstacles = result.obstacles;
  sent_ = CanStage::request_for(d);
  link_.schedule().frame(report, *sent_, now);
  return d;
}

const safety::Decision& LiveStage::tick(Stamp now, std::uint64_t frames_lost) {
  link_.start(now);  // the address claim, once in the link's life (Session::start ticks first)
  link_.schedule().tick(now, heartbeat(frames_lost));
  input_.now = now;
  input_.frame = nullptr;
  input_.no_address = link_.no_address();
  last_ = monitor_.update(input_);
  for (auto& s : input_.sensors) s.problem = safety::Problem::None;
  note(*last_, "between rotations");
  link_.decided(*last_, now);
  // Before the first decision the schedule already repeats STOP, starting up; afterwards a change decided
  // between rotations (a timeout) must not wait for a rotation that may never come.
  const output::StopRequest request = CanStage::request_for(*last_);
  if (sent_ ? !same_request(*sent_, request)
            : request.command != output::StopCommand::Stop || !request.reasons.starting_up) {
    sent_ = request;
    link_.schedule().stop(request, now);
  }
  return *last_;
}

void LiveStage::shutdown(Stamp now) {
  link_.schedule().tick(now, heartbeat(0));
  output::StopRequest r;
  r.command = output::StopCommand::Stop;
  r.reasons.shutting_down = true;
  sent_ = r;
  link_.schedule().stop(r, now);
}

output::Heartbeat LiveStage::heartbeat(std::uint64_t frames_lost) const {
  return CanStage::heartbeat_for(cfg_.safety, last_, frames_lost);
}

}  // namespace fieldguard::app
