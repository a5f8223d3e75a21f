#pragma once
// When each message goes out, on one clock (replay time in replay, the monotonic clock live): per pipeline
// frame the summary, its obstacles and the stop request; every period (100 ms, the layouts' cycle time) a
// heartbeat and the latest stop request again, so the controller hears from us at a fixed rate even when the
// pipeline stalls. Thread-compatible: the caller serialises frame() and tick() (one output thread).

#include <cstdint>
#include <optional>
#include <vector>

#include "fieldguard/core/time.hpp"
#include "fieldguard/output/can_encoder.hpp"
#include "fieldguard/output/can_sink.hpp"

namespace fieldguard::output {

class CanSchedule {
 public:
  // Both must outlive the schedule. Throws std::invalid_argument for a period <= 0.
  CanSchedule(CanEncoder& encoder, CanSink& sink, Nanos period = std::chrono::milliseconds(100));

  // Sends every cycle due at or before `now`, each stamped at its due time. The first call starts the
  // clock (one cycle at `now`). After a gap of more than kMaxCatchUp periods only the last is sent and the
  // rest are counted in skipped_cycles(): a burst of stale heartbeats helps nobody.
  void tick(Stamp now, const Heartbeat& heartbeat);
  // One pipeline frame's messages at `t` (call tick(t, ...) first so the log stays in time order).
  void frame(const FrameReport& report, const StopRequest& stop, Stamp t);
  // A stop request decided between frames (a sensor timing out, the pipeline stalling, shutting down): sent
  // at `t` at once, and repeated by the following cycles until the next frame or stop() replaces it.
  void stop(const StopRequest& stop, Stamp t);

  // A new period (a configuration reload) from the next cycle on; the cycle due keeps its time. Throws
  // std::invalid_argument for a period <= 0.
  void set_period(Nanos period);

  [[nodiscard]] std::uint64_t skipped_cycles() const { return skipped_; }
  [[nodiscard]] const std::optional<StopRequest>& last_stop() const { return last_stop_; }

  static constexpr std::int64_t kMaxCatchUp = 10;

 private:
  void cycle(Stamp t, const Heartbeat& heartbeat);

  CanEncoder& encoder_;
  CanSink& sink_;
  std::int64_t period_ns_;
  std::optional<std::int64_t> next_due_ns_;
  std::optional<StopRequest> last_stop_;
  std::uint64_t skipped_ = 0;
  std::vector<CanFrame> buf_;
};

}  // namespace fieldguard::output
