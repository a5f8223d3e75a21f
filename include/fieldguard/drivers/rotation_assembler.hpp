#pragma once
// Cuts a stream of decoded points into rotations: a frame ends where the azimuth passes the cut angle.
// One producer: not thread-safe. Push-style: frames come out as they complete.
//
// A rotation is complete with the packet that carries its last firing. Where the cut angle falls inside a packet,
// that packet shows it; where it falls between two packets (an emulator, or a sensor phase-locked to the cut),
// the azimuth steps of the packets before tell it: when the next packet's firings, one steady step on, all lie
// past the cut, the rotation is emitted at once instead of a packet period later (RotationClose::LastFiring).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/core/spare_list.hpp"

namespace fieldguard {

// Bounds on the azimuth_cdeg of a run of points (every one of them in [min_cdeg, max_cdeg]; not necessarily
// attained). A decoder knows them per packet from the block azimuths and its calibration; the rotation assembler
// uses them to pass over a packet that cannot hold the cut angle without looking at each point's azimuth.
struct AzimuthRange {
  std::uint16_t min_cdeg = 0;
  std::uint16_t max_cdeg = 0xFFFF;  // the default holds every azimuth: no information
};

// When a rotation whose cut falls between two packets is emitted: with the packet carrying its last firing (as
// predicted from the steady azimuth step of the packets), or only when the next rotation's first packet arrives.
// The frames and their points are the same either way; the last rotation of a stream that ends on a whole turn is
// full with LastFiring and partial (emitted by finish()) with NextRotation.
enum class RotationClose : std::uint8_t { LastFiring, NextRotation };

class RotationAssembler {
 public:
  explicit RotationAssembler(double cut_deg = 0.0, RotationClose close = RotationClose::LastFiring);

  // Points of one packet (time_s relative to packet_sensor_time), in firing order. Completed frames are
  // appended to `done`. Point times in an emitted frame are relative to the frame's sensor_stamp.
  // Copies the points once; append_room() + commit() lets a decoder write them in place instead.
  void push(std::span<const LidarPoint> points, Stamp packet_sensor_time, Stamp packet_host_time,
            std::vector<LidarFrame>& done);

  // In-place variant of push(), for a decoder that writes straight into the frame under construction:
  // write one packet's points (time_s relative to the packet, as for push()) to the front of append_room(n),
  // then commit(count, ...) the first `count` of them. Gives exactly what push() of those points gives. The room
  // holds leftovers of earlier points, not value-initialised ones: write every field. It is valid until the next
  // call of any other non-const member; room not committed is not part of any frame.
  [[nodiscard]] std::span<LidarPoint> append_room(std::size_t n);
  void commit(std::size_t count, Stamp packet_sensor_time, Stamp packet_host_time, std::vector<LidarFrame>& done);
  // The same, given bounds on the azimuths of the `count` points (a decoder's, velodyne::Decoder::decode()): where
  // they show that no point of the packet can end the frame or step back across the cut angle (a frame is under
  // way, and the packet's azimuths and the last one before it lie within half a turn, on one side of the cut), the
  // points' azimuths are not looked at one by one. Gives exactly what commit() without them gives, as long as
  // every point's azimuth lies inside the bounds; AzimuthRange{} (every azimuth) is always safe.
  void commit(std::size_t count, Stamp packet_sensor_time, Stamp packet_host_time, std::vector<LidarFrame>& done,
              AzimuthRange azimuths);

  // For a decoder that makes the point times frame-relative itself (velodyne::Decoder::decode_accepted()): where a
  // packet with these azimuth bounds can neither end the frame under way nor step back across the cut (the
  // conditions of commit() with bounds, above), the offset in seconds from the packet's sensor time to the frame's,
  // which commit() would add to every packet-relative time (as float(offset + double(time_s))); nullopt where the
  // bounds do not show that (then decode packet-relative times and commit() as usual).
  [[nodiscard]] std::optional<double> in_frame_offset_s(AzimuthRange azimuths, Stamp packet_sensor_time) const;
  // Commits the first `count` points of append_room(), written with frame-relative times after in_frame_offset_s()
  // gave an offset (and nothing else changed the assembler in between). Gives exactly what commit() with bounds
  // gives for the same points with packet-relative times (including a frame the packet completes, into `done`).
  void commit_in_frame(std::size_t count, Stamp packet_host_time, std::vector<LidarFrame>& done);

  // End of stream: emits what is pending as a partial frame (if it holds any point).
  void finish(std::vector<LidarFrame>& done);

  // Optional: hands back a frame the consumer is done with, so that its point buffer (4.4 MB for a 5 Hz
  // HDL-32E rotation) is reused for a later frame instead of being freed, allocated and initialised again.
  void recycle(LidarFrame&& frame);
  // Frees the recycled buffers that sat unused since the last call (SpareList::trim()); returns how many.
  std::size_t trim_spares() { return spare_.trim(); }

  [[nodiscard]] std::uint64_t frames_emitted() const { return next_index_; }

 private:
  void emit(std::vector<LidarFrame>& done, bool partial, std::vector<LidarPoint>&& next_points);
  [[nodiscard]] std::vector<LidarPoint> fresh_buffer();
  // commit() of a packet that, by its azimuth bounds, neither ends the frame nor starts one; false (nothing done)
  // where the bounds do not show that.
  [[nodiscard]] bool commit_within_frame(std::size_t count, Stamp packet_sensor_time, Stamp packet_host_time,
                                         std::vector<LidarFrame>& done, AzimuthRange azimuths);
  // Bookkeeping of a packet whose points [first, count_) of the frame under way were just committed (first_rel: its
  // first firing's azimuth relative to the cut): its azimuth step, the frame's last host time, and the emission of
  // a frame the packet completes (RotationClose::LastFiring).
  void end_packet(std::size_t first, int first_rel, Stamp packet_host_time, std::vector<LidarFrame>& done);

  std::uint16_t cut_cdeg_;
  RotationClose close_;
  int packet_first_rel_ = -1;  // the last packet's first firing, relative to the cut (cdeg)
  int packet_step_ = -1;       // cdeg between the first firings of the last two packets
  int step_jitter_ = -1;       // |change| of that step from the packet before; -1 unknown
  // The frame under construction. Its points vector is kept larger than the frame (room for the next packets,
  // constructed once per buffer): the frame's points are the first count_; emit() trims it.
  LidarFrame current_;
  std::size_t count_ = 0;
  bool have_current_ = false;
  bool current_started_at_cut_ = false;
  int prev_rel_cdeg_ = -1;  // previous point's azimuth relative to the cut, 0..35999
  std::uint64_t next_index_ = 0;
  std::size_t last_frame_points_ = 0;            // points of the last frame emitted (sizes the next buffer)
  SpareList<std::vector<LidarPoint>> spare_{2};  // recycled point buffers
};

}  // namespace fieldguard
