#pragma once
// Cuts a stream of decoded points into rotations: a frame ends where the azimuth passes the cut angle.
// One producer: not thread-safe. Push-style: frames come out as they complete.

#include <span>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"

namespace fieldguard {

class RotationAssembler {
 public:
  explicit RotationAssembler(double cut_deg = 0.0);

  // Points of one packet (time_s relative to packet_sensor_time), in firing order. Completed frames are
  // appended to `done`. Point times in an emitted frame are relative to the frame's sensor_stamp.
  void push(std::span<const LidarPoint> points, Stamp packet_sensor_time, Stamp packet_host_time,
            std::vector<LidarFrame>& done);

  // End of stream: emits what is pending as a partial frame (if it holds any point).
  void finish(std::vector<LidarFrame>& done);

  [[nodiscard]] std::uint64_t frames_emitted() const { return next_index_; }

 private:
  void emit(std::vector<LidarFrame>& done, bool partial);

  std::uint16_t cut_cdeg_;
  LidarFrame current_;
  bool have_current_ = false;
  bool current_started_at_cut_ = false;
  int prev_rel_cdeg_ = -1;  // previous point's azimuth relative to the cut, 0..35999
  std::uint64_t next_index_ = 0;
};

}  // namespace fieldguard
