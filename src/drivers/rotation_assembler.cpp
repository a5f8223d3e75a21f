// Cuts decoded points into rotations at a fixed azimuth.
#include "fieldguard/drivers/rotation_assembler.hpp"

#include <cmath>
#include <utility>

namespace fieldguard {

namespace {
constexpr int kFullTurnCdeg = 36000;
// A frame ends where the azimuth relative to the cut angle falls back by more than half a turn. Smaller
// steps back (dual returns of one firing, per-laser azimuth corrections, jitter) never cut.
constexpr int kWrapCdeg = kFullTurnCdeg / 2;
// A step back across the cut angle of at most this much (just after a cut) is not progress: see push().
constexpr int kStepBackCdeg = 1000;
}  // namespace

RotationAssembler::RotationAssembler(double cut_deg) {
  double c = std::fmod(cut_deg, 360.0);
  if (c < 0.0) c += 360.0;
  const long cdeg = std::lround(c * 100.0);
  cut_cdeg_ = static_cast<std::uint16_t>(cdeg >= kFullTurnCdeg || cdeg < 0 ? 0 : cdeg);
}

void RotationAssembler::emit(std::vector<LidarFrame>& done, bool partial) {
  current_.index = next_index_++;
  current_.partial = partial;
  done.push_back(std::move(current_));
  current_ = LidarFrame{};
  current_.points.reserve(done.back().points.size());  // the next rotation is about as large
  have_current_ = false;
}

void RotationAssembler::push(std::span<const LidarPoint> points, Stamp packet_sensor_time, Stamp packet_host_time,
                             std::vector<LidarFrame>& done) {
  bool counted = false;  // this packet already counted in the current frame
  for (const LidarPoint& p : points) {
    const int rel = (static_cast<int>(p.azimuth_cdeg) - static_cast<int>(cut_cdeg_) + kFullTurnCdeg) % kFullTurnCdeg;
    if (prev_rel_cdeg_ >= 0) {
      if (rel + kWrapCdeg < prev_rel_cdeg_) {
        // Passed the cut angle: the frame so far is complete (or partial if it did not start at the cut).
        if (have_current_) emit(done, !current_started_at_cut_);
        current_started_at_cut_ = true;
        counted = false;
        prev_rel_cdeg_ = rel;
      } else if (rel > prev_rel_cdeg_ + kWrapCdeg && prev_rel_cdeg_ + kFullTurnCdeg - rel <= kStepBackCdeg) {
        // A point a little before the cut after the stream already passed it (per-laser azimuth corrections):
        // it stays in the new frame and does not move the reference, so it cannot cause a second cut.
      } else {
        prev_rel_cdeg_ = rel;
      }
    } else {
      prev_rel_cdeg_ = rel;
    }

    if (!have_current_) {
      have_current_ = true;
      const auto offset_ns = static_cast<std::int64_t>(std::llround(static_cast<double>(p.time_s) * 1e9));
      current_.sensor_stamp = Stamp{packet_sensor_time.ns + offset_ns};
      current_.host_stamp = packet_host_time;
      current_.packets = 0;
    }
    if (!counted) {
      ++current_.packets;
      counted = true;
    }
    LidarPoint q = p;
    const double packet_to_frame_s = static_cast<double>(packet_sensor_time.ns - current_.sensor_stamp.ns) * 1e-9;
    q.time_s = static_cast<float>(packet_to_frame_s + static_cast<double>(p.time_s));
    current_.points.push_back(q);
  }
}

void RotationAssembler::finish(std::vector<LidarFrame>& done) {
  if (have_current_ && !current_.points.empty()) emit(done, true);
  current_ = LidarFrame{};
  have_current_ = false;
  current_started_at_cut_ = false;
  prev_rel_cdeg_ = -1;
}

}  // namespace fieldguard
