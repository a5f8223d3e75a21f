// Cuts decoded points into rotations at a fixed azimuth.
//
// Points are assembled in place: a packet's points are written at the end of the frame under construction (by
// push(), or by a decoder through append_room()) and commit() then walks the new points once, making their times
// frame-relative and looking for the cut. Where a packet straddles the cut, its points past the cut (at most one
// packet's) move to the next frame's buffer. A frame's buffer is reserved with headroom over the last frame and
// constructed once, and buffers can be recycled: a steady stream neither reallocates, nor copies a frame,
// nor initialises points it is about to overwrite.
#include "fieldguard/drivers/rotation_assembler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <utility>

namespace fieldguard {

namespace {
constexpr int kFullTurnCdeg = 36000;
// A frame ends where the azimuth relative to the cut angle falls back by more than half a turn. Smaller
// steps back (dual returns of one firing, per-laser azimuth corrections, jitter) never cut.
constexpr int kWrapCdeg = kFullTurnCdeg / 2;
// A step back across the cut angle of at most this much (just after a cut) is not progress: see commit().
constexpr int kStepBackCdeg = 1000;
// Headroom of a new frame's buffer over the last frame: rotations vary by a packet or two and with the scene;
// 1/8 plus two packets' worth makes a reallocation inside a frame rare. (The last frame, not the largest ever: one
// overlong frame, after the sensor stood still, must not size every later buffer.)
constexpr std::size_t kHeadroomPoints = 2 * 384;

// Points constructed at a time when a buffer needs room (128 KiB): a buffer's points are value-initialised once in
// its life (resize() cannot leave them uninitialised), in steps of this many rather than packet by packet, and a
// recycled buffer only where the new frame outgrows the old one.
constexpr std::size_t kConstructStep = 4096;

// Makes `v` hold at least keep + n constructed points, keeping the first `keep`.
void make_room(std::vector<LidarPoint>& v, std::size_t keep, std::size_t n) {
  const std::size_t need = keep + n;
  if (v.size() >= need) return;
  if (v.capacity() < need) {
    std::vector<LidarPoint> bigger;
    bigger.reserve(std::max(need, 2 * v.capacity()));
    bigger.insert(bigger.end(), v.begin(), v.begin() + static_cast<std::ptrdiff_t>(std::min(keep, v.size())));
    v = std::move(bigger);
  }
  v.resize(std::min(v.capacity(), std::max(need, v.size() + kConstructStep)));
}
}  // namespace

RotationAssembler::RotationAssembler(double cut_deg, RotationClose close) : close_(close) {
  double c = std::fmod(cut_deg, 360.0);
  if (c < 0.0) c += 360.0;
  const long cdeg = std::lround(c * 100.0);
  cut_cdeg_ = static_cast<std::uint16_t>(cdeg >= kFullTurnCdeg || cdeg < 0 ? 0 : cdeg);
}

std::vector<LidarPoint> RotationAssembler::fresh_buffer() {
  std::vector<LidarPoint> b;
  (void)spare_.take(b);
  const std::size_t want = last_frame_points_ + last_frame_points_ / 8 + kHeadroomPoints;
  // Too small, or far too big (more than four rotations' room: grown by an overlong rotation, after the sensor
  // stood still or came back; a synchronizer hands back buffers with room for a frame of two or three): a buffer
  // of the right size, so that no outage leaves the process holding its largest buffers for good.
  if (b.capacity() < want || (last_frame_points_ > 0 && b.capacity() > 4 * want)) {
    b = std::vector<LidarPoint>();  // nothing to keep: reserve() need not copy the old points
    b.reserve(want);
  }
  return b;
}

void RotationAssembler::emit(std::vector<LidarFrame>& done, bool partial, std::vector<LidarPoint>&& next_points) {
  current_.points.resize(count_);  // trim the room (trivially destructible points: no work)
  last_frame_points_ = count_;
  current_.index = next_index_++;
  current_.partial = partial;
  done.push_back(std::move(current_));
  current_ = LidarFrame{};
  current_.points = std::move(next_points);
  count_ = 0;
  have_current_ = false;
}

std::span<LidarPoint> RotationAssembler::append_room(std::size_t n) {
  make_room(current_.points, count_, n);
  return {current_.points.data() + count_, n};
}

void RotationAssembler::push(std::span<const LidarPoint> points, Stamp packet_sensor_time, Stamp packet_host_time,
                             std::vector<LidarFrame>& done) {
  const std::span<LidarPoint> room = append_room(points.size());
  std::copy(points.begin(), points.end(), room.begin());
  commit(points.size(), packet_sensor_time, packet_host_time, done);
}

// Azimuth relative to the cut, 0..35999: (azimuth - cut) mod 36000 for any u16 azimuth, without a division.
inline int relative_cdeg(std::uint16_t azimuth_cdeg, int cut_cdeg) {
  int rel = static_cast<int>(azimuth_cdeg) - cut_cdeg + kFullTurnCdeg;  // 1 .. 101535
  rel -= kFullTurnCdeg * static_cast<int>(rel >= kFullTurnCdeg);
  rel -= kFullTurnCdeg * static_cast<int>(rel >= kFullTurnCdeg);
  return rel;
}

void RotationAssembler::commit(std::size_t count, Stamp packet_sensor_time, Stamp packet_host_time,
                               std::vector<LidarFrame>& done) {
  std::size_t end = count_ + std::min(count, current_.points.size() - std::min(count_, current_.points.size()));
  std::size_t i = count_;
  std::size_t packet_first = count_;  // where this packet's points begin in the frame under way
  const int first_rel = i < end ? relative_cdeg(current_.points[i].azimuth_cdeg, cut_cdeg_) : -1;
  bool counted = false;  // this packet already counted in the current frame
  double packet_to_frame_s = static_cast<double>(packet_sensor_time.ns - current_.sensor_stamp.ns) * 1e-9;
  // Members the loops read and write, in locals (stores to the points must not make the compiler reload them).
  const int cut = cut_cdeg_;
  int prev = prev_rel_cdeg_;
  bool have = have_current_;
  while (i < end) {
    LidarPoint* const pts = current_.points.data();
    // Point i with every case: the first point ever, a cut, the start of a frame, the packet's first point in it.
    {
      LidarPoint& p = pts[i];
      const int rel = relative_cdeg(p.azimuth_cdeg, cut);
      if (prev >= 0) {
        if (rel + kWrapCdeg < prev) {
          // Passed the cut angle: the frame so far is complete (or partial if it did not start at the cut).
          prev = rel;
          counted = false;
          if (have) {
            // Points [i, end) (the rest of this packet, times still packet-relative) start the next frame; point i
            // is then taken again as its first (no second cut: prev == rel).
            const std::size_t tail = end - i;
            last_frame_points_ = i;  // sizes the next buffer
            std::vector<LidarPoint> next = fresh_buffer();
            make_room(next, 0, tail);
            std::copy(pts + i, pts + end, next.begin());
            count_ = i;
            current_.last_host_stamp = packet_host_time;
            emit(done, !current_started_at_cut_, std::move(next));
            current_started_at_cut_ = true;
            have = false;
            i = 0;
            end = tail;
            packet_first = 0;
            continue;
          }
          current_started_at_cut_ = true;
        } else if (rel > prev + kWrapCdeg && prev + kFullTurnCdeg - rel <= kStepBackCdeg) {
          // A point a little before the cut after the stream already passed it (per-laser azimuth corrections):
          // it stays in the new frame and does not move the reference, so it cannot cause a second cut.
        } else {
          prev = rel;
        }
      } else {
        prev = rel;
      }
      if (!have) {
        have = true;
        const auto offset_ns = static_cast<std::int64_t>(std::llround(static_cast<double>(p.time_s) * 1e9));
        current_.sensor_stamp = Stamp{packet_sensor_time.ns + offset_ns};
        current_.host_stamp = packet_host_time;
        current_.packets = 0;
        packet_to_frame_s = static_cast<double>(packet_sensor_time.ns - current_.sensor_stamp.ns) * 1e-9;
      }
      if (!counted) {
        ++current_.packets;
        counted = true;
      }
      p.time_s = static_cast<float>(packet_to_frame_s + static_cast<double>(p.time_s));
    }
    // The points after it, as long as none cuts: the frame is started and the packet counted, so all that is left
    // is the reference azimuth and the time. A cut leaves the loop with point i untouched, for the code above.
    for (++i; i < end; ++i) {
      LidarPoint& p = pts[i];
      const int rel = relative_cdeg(p.azimuth_cdeg, cut);
      if (rel + kWrapCdeg < prev) break;
      const bool step_back = rel > prev + kWrapCdeg && prev + kFullTurnCdeg - rel <= kStepBackCdeg;
      prev = step_back ? prev : rel;
      p.time_s = static_cast<float>(packet_to_frame_s + static_cast<double>(p.time_s));
    }
  }
  count_ = end;
  prev_rel_cdeg_ = prev;
  have_current_ = have;
  end_packet(packet_first, first_rel, packet_host_time, done);
}

void RotationAssembler::end_packet(std::size_t first, int first_rel, Stamp packet_host_time,
                                   std::vector<LidarFrame>& done) {
  if (first >= count_) return;  // no point: not a packet of the frame (as it is not counted)
  current_.last_host_stamp = packet_host_time;
  // The step of the packet's first firing from the packet before's (mod one turn).
  if (packet_first_rel_ >= 0) {
    const int step = (first_rel - packet_first_rel_ + kFullTurnCdeg) % kFullTurnCdeg;
    step_jitter_ = packet_step_ >= 0 ? std::abs(step - packet_step_) : -1;
    packet_step_ = step;
  }
  packet_first_rel_ = first_rel;
  if (close_ != RotationClose::LastFiring || !have_current_ || step_jitter_ < 0) return;
  // A steady step (a lost packet or a jump shows as a change of more than an eighth) of at most a tenth of a turn.
  if (packet_step_ <= 0 || packet_step_ > kFullTurnCdeg / 10 || 8 * step_jitter_ > packet_step_) return;
  // The frame must be in its second half (its last firing before the cut, no step back across it pending).
  if (prev_rel_cdeg_ < kWrapCdeg) return;
  // The lowest azimuth of this packet, one step on, with twice the step's jitter as margin: at or past the cut, the
  // next packet holds no firing of this rotation. (Only the packets near the cut are looked at point by point.)
  if (first_rel + packet_step_ < kFullTurnCdeg) return;
  int lowest = kFullTurnCdeg;
  for (std::size_t i = first; i < count_; ++i) {
    lowest = std::min(lowest, relative_cdeg(current_.points[i].azimuth_cdeg, cut_cdeg_));
  }
  if (lowest < kWrapCdeg || lowest + packet_step_ - 2 * step_jitter_ < kFullTurnCdeg) return;
  last_frame_points_ = count_;  // sizes the next buffer
  emit(done, !current_started_at_cut_, fresh_buffer());
  // The cut is made: the next frame starts at it. Should a firing of the next packet still lie a little before the
  // cut after all (the prediction missed), it is a step back just after a cut: it joins the next frame, as a per-laser
  // azimuth correction does, and cuts nothing.
  prev_rel_cdeg_ = 0;
  current_started_at_cut_ = true;
}

std::optional<double> RotationAssembler::in_frame_offset_s(AzimuthRange azimuths, Stamp packet_sensor_time) const {
  const int cut = cut_cdeg_;
  const int prev = prev_rel_cdeg_;
  if (!have_current_ || prev < 0) return std::nullopt;
  if (azimuths.min_cdeg > azimuths.max_cdeg || azimuths.max_cdeg >= kFullTurnCdeg) return std::nullopt;
  // The azimuth relative to the cut rises with the azimuth over the bounds only if the cut is not inside them.
  if (azimuths.min_cdeg < cut && cut <= azimuths.max_cdeg) return std::nullopt;
  const int lo = std::min(relative_cdeg(azimuths.min_cdeg, cut), prev);
  const int hi = std::max(relative_cdeg(azimuths.max_cdeg, cut), prev);
  // commit() cuts where an azimuth falls more than half a turn below the previous one, and holds the reference back
  // where one lies more than half a turn above it. Neither can happen while every azimuth of the packet and the
  // reference lie within half a turn of each other: every point then just becomes the reference, the last one last.
  if (hi - lo > kWrapCdeg) return std::nullopt;
  return static_cast<double>(packet_sensor_time.ns - current_.sensor_stamp.ns) * 1e-9;
}

void RotationAssembler::commit_in_frame(std::size_t count, Stamp packet_host_time, std::vector<LidarFrame>& done) {
  const std::size_t size = current_.points.size();
  const std::size_t end = count_ + std::min(count, size - std::min(count_, size));
  // No point: nothing happens, as in commit() (the packet is not counted).
  if (end == count_) return;
  ++current_.packets;
  prev_rel_cdeg_ = relative_cdeg(current_.points[end - 1].azimuth_cdeg, cut_cdeg_);
  const std::size_t first = count_;
  count_ = end;
  end_packet(first, relative_cdeg(current_.points[first].azimuth_cdeg, cut_cdeg_), packet_host_time, done);
}

bool RotationAssembler::commit_within_frame(std::size_t count, Stamp packet_sensor_time, Stamp packet_host_time,
                                            std::vector<LidarFrame>& done, AzimuthRange azimuths) {
  const std::size_t size = current_.points.size();
  const std::size_t end = count_ + std::min(count, size - std::min(count_, size));
  if (end == count_) return false;
  const std::optional<double> packet_to_frame_s = in_frame_offset_s(azimuths, packet_sensor_time);
  if (!packet_to_frame_s) return false;
  LidarPoint* const pts = current_.points.data();
  for (std::size_t i = count_; i < end; ++i) {
    pts[i].time_s = static_cast<float>(*packet_to_frame_s + static_cast<double>(pts[i].time_s));
  }
  commit_in_frame(count, packet_host_time, done);
  return true;
}

void RotationAssembler::commit(std::size_t count, Stamp packet_sensor_time, Stamp packet_host_time,
                               std::vector<LidarFrame>& done, AzimuthRange azimuths) {
  if (!commit_within_frame(count, packet_sensor_time, packet_host_time, done, azimuths))
    commit(count, packet_sensor_time, packet_host_time, done);
}

void RotationAssembler::finish(std::vector<LidarFrame>& done) {
  if (have_current_ && count_ > 0) emit(done, true, {});
  current_ = LidarFrame{};
  count_ = 0;
  have_current_ = false;
  current_started_at_cut_ = false;
  prev_rel_cdeg_ = -1;
  packet_first_rel_ = -1;
  packet_step_ = -1;
  step_jitter_ = -1;
}

void RotationAssembler::recycle(LidarFrame&& frame) {
  if (frame.points.capacity() > 0) (void)spare_.put(std::move(frame.points));
  frame = LidarFrame{};
}

}  // namespace fieldguard
