#include "fieldguard/output/can_schedule.hpp"

#include <stdexcept>

namespace fieldguard::output {

CanSchedule::CanSchedule(CanEncoder& encoder, CanSink& sink, Nanos period)
    : encoder_(encoder), sink_(sink), period_ns_(period.count()) {
  if (period_ns_ <= 0) throw std::invalid_argument("CanSchedule: the period must be positive");
  buf_.reserve(kMaxObstacleMessages + 4);
}

void CanSchedule::set_period(Nanos period) {
  if (period.count() <= 0) throw std::invalid_argument("CanSchedule: the period must be positive");
  period_ns_ = period.count();
}

void CanSchedule::cycle(Stamp t, const Heartbeat& heartbeat) {
  buf_.clear();
  buf_.push_back(encoder_.encode_heartbeat(heartbeat));
  // Until the first decision the only safe thing to say is STOP, starting up.
  StopRequest stop = last_stop_.value_or(StopRequest{StopCommand::Stop, StopReasons{.starting_up = true}});
  buf_.push_back(encoder_.encode_stop(stop));
  sink_.write(buf_, t);
}

void CanSchedule::tick(Stamp now, const Heartbeat& heartbeat) {
  if (!next_due_ns_) next_due_ns_ = now.ns;
  if (now.ns < *next_due_ns_) return;
  const std::int64_t due = (now.ns - *next_due_ns_) / period_ns_ + 1;  // cycles at or before now
  if (due > kMaxCatchUp) {
    skipped_ += static_cast<std::uint64_t>(due - 1);
    *next_due_ns_ += (due - 1) * period_ns_;
  }
  while (*next_due_ns_ <= now.ns) {
    cycle(Stamp{*next_due_ns_}, heartbeat);
    *next_due_ns_ += period_ns_;
  }
}

void CanSchedule::frame(const FrameReport& report, const StopRequest& stop, Stamp t) {
  last_stop_ = stop;
  buf_.clear();
  encoder_.encode_frame(report, buf_);
  buf_.push_back(encoder_.encode_stop(stop));
  sink_.write(buf_, t);
}

void CanSchedule::stop(const StopRequest& stop, Stamp t) {
  last_stop_ = stop;
  buf_.clear();
  buf_.push_back(encoder_.encode_stop(stop));
  sink_.write(buf_, t);
}

}  // namespace fieldguard::output
