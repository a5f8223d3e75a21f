#pragma once
// Cuts the mapped sensor streams into SyncedFrames at the configured rate.
//
// The window of a frame is made of whole 3D LiDAR rotations: at 5 Hz spin one rotation, at 10 Hz the last two,
// at 20 Hz four. A window is closed at the end of the rotation that brings its span within half a rotation of
// the frame period, so no point is cut off or used twice, and at a spin that is no divisor of the rate (7 Hz)
// each frame is one rotation. A gap in the rotations (a lost one) closes the window early, marked partial.
//
// A closed window waits until every required sensor can no longer change its contents: a 2D scan at or after
// the window's middle (the nearest is then known), a GNSS fix and an AHRS sample at or after its end. With a lead
// (gnss_lead_s, ahrs_lead_s) it need not wait for that fix or sample: a newest one at most the lead before the end
// makes it ready, and the pose is extrapolated over the rest (geo::PoseTrack), so a frame goes out when its last
// rotation is whole instead of a fix period plus the receiver's latency later. Any sensor
// may run ahead of or behind the others. Samples are kept sorted, so one sensor's own samples may also arrive out
// of order, as long as none arrives after a newer one of the same sensor has already completed a window that
// needed it (serial and TCP streams keep their order; that case is not compensated).
// A window still incomplete `timeout_s` (host clock, `now` of poll()) after its end is emitted with the
// sensors it lacks in `missing`. Frames leave in window order.
//
// Pure: no clock is read, `now` is passed in. Thread-compatible.

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/core/spare_list.hpp"
#include "fieldguard/sync/synced_frame.hpp"

namespace fieldguard::sync {

struct AssemblerParams {
  double rate_hz = 5.0;            // frames per second (0.5..50)
  double timeout_s = 0.5;          // wait for late sensors this long after a window's end
  double max_scan_offset_s = 0.1;  // a 2D scan farther than this from the window's middle is not "its" scan
  double max_bracket_gap_s = 1.0;  // GNSS/AHRS bracket samples farther than this outside the window do not count
  double gnss_lead_s = 0.0;        // ready without the fix after the end when the newest is at most this before it
  double ahrs_lead_s = 0.0;        // likewise for the AHRS sample (0: wait for the bracket)
  double history_s = 3.0;          // samples kept behind the newest window and behind each sensor's newest sample
  std::size_t max_pending = 8;     // closed windows waiting; beyond it the oldest is emitted as timed out
  bool require_scan2d = true;
  bool require_gnss = true;
  bool require_ahrs = true;

  [[nodiscard]] std::vector<std::string> validate() const;
};

struct AssemblerCounters {
  std::uint64_t rotations = 0;
  std::uint64_t late_rotations = 0;  // starting before the end of an earlier one: dropped
  std::uint64_t frames = 0;
  std::uint64_t complete = 0;
  std::uint64_t timed_out = 0;
  std::uint64_t overflowed = 0;              // emitted early because max_pending was reached
  std::uint64_t late_samples = 0;            // older than what emitted frames already used: dropped
  std::uint64_t missing[kSensorCount] = {};  // frames emitted lacking each sensor
};

class FrameAssembler {
 public:
  explicit FrameAssembler(const AssemblerParams& params = {});  // throws std::invalid_argument when invalid

  void add_rotation(LidarRotation&& r);
  void add_scan(TimedScan&& s);
  void add_gnss(TimedGnss&& g);
  void add_attitude(TimedAttitude&& a);

  // Emits (appends to `out`) every frame that is complete, or whose timeout has passed at host time `now`.
  void poll(Stamp now, std::vector<SyncedFrame>& out);
  // End of input: closes the rotations still open and emits every pending window as it is.
  void finish(std::vector<SyncedFrame>& out);

  // Buffer reuse, so that a steady stream allocates nothing once warm. recycle(): a frame the consumer is done
  // with; its vectors hold a later frame (its points buffer, sized for a whole window, takes the window's first
  // rotation's place). take_spare_points(): the point buffers of rotations copied into a frame (their points stale),
  // for the 3D LiDAR's rotation assembler (RotationAssembler::recycle()); false when there is none. Both keep at most
  // a few.
  void recycle(SyncedFrame&& frame);
  bool take_spare_points(std::vector<LidarPoint>& out);
  // Frees the recycled frames that sat unused since the last call (SpareList::trim()); returns how many.
  std::size_t trim_spares() { return spare_frames_.trim(); }

  // The first required sensor the oldest closed window waits for; nullopt when no window is waiting.
  [[nodiscard]] std::optional<SensorKind> waiting_for() const;
  // Window end of the oldest closed window; nullopt when none waits.
  [[nodiscard]] std::optional<Stamp> oldest_pending_end() const;
  [[nodiscard]] std::size_t pending() const { return pending_.size(); }
  // Samples (rotations for the 3D LiDAR) held. Each other sensor's buffer keeps history_s behind its newest
  // sample, so memory stays bounded when the LiDAR is silent; poll() after pushing keeps `pending` bounded.
  [[nodiscard]] std::size_t buffered(SensorKind k) const;
  [[nodiscard]] const AssemblerCounters& counters() const { return counters_; }
  [[nodiscard]] const AssemblerParams& params() const { return params_; }

 private:
  struct Window {
    Stamp start, end;
    bool partial = false;
    std::vector<LidarRotation> rotations;
  };
  void close_open(bool partial);
  [[nodiscard]] std::uint8_t not_ready(const Window& w) const;
  [[nodiscard]] SyncedFrame build(Window&& w, bool timed_out);
  void prune(Stamp used_until);

  AssemblerParams params_;
  std::int64_t period_ns_ = 0;
  std::vector<LidarRotation> open_;  // rotations of the window being filled
  std::vector<Window> pending_;      // closed, waiting for the other sensors, oldest first (a few at most)
  std::vector<std::vector<LidarRotation>> spare_lists_;  // emptied rotation lists of emitted windows, for open_
  std::deque<TimedScan> scans_;                          // each sorted by time
  std::deque<TimedGnss> gnss_;
  std::deque<TimedAttitude> ahrs_;
  std::optional<Stamp> last_rotation_end_;
  std::optional<Stamp> emitted_until_;  // end of the last emitted window
  std::uint64_t next_seq_ = 0;
  AssemblerCounters counters_;
  static constexpr std::size_t kMaxSpare = 4;
  SpareList<SyncedFrame> spare_frames_{kMaxSpare};     // recycled
  std::vector<std::vector<LidarPoint>> spare_points_;  // at most kMaxSpare, in transit to the rotation assembler
};

}  // namespace fieldguard::sync
