// Frames from whole rotations, with the nearest 2D scan and the bracketing GNSS/AHRS samples
// (frame_assembler.hpp).

#include "fieldguard/sync/frame_assembler.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <type_traits>

namespace fieldguard::sync {
namespace {

std::int64_t to_ns(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }

// Inserts keeping the deque sorted by time; equal times keep arrival order.
template <typename T>
void insert_sorted(std::deque<T>& d, std::type_identity_t<T>&& v) {  // v: an rvalue, moved in
  if (d.empty() || d.back().time <= v.time) {
    d.push_back(std::move(v));
    return;
  }
  const auto it = std::upper_bound(d.begin(), d.end(), v.time, [](Stamp t, const T& e) { return t < e.time; });
  d.insert(it, std::move(v));
}

// Bounds a buffer whatever the LiDAR does: samples more than `history` behind the sensor's newest go (for GNSS
// and AHRS the newest one older than that stays, it may still open a bracket).
template <typename T>
void trim(std::deque<T>& d, std::int64_t history, bool keep_one_before) {
  if (d.empty()) return;
  const std::int64_t keep_from = d.back().time.ns - history;
  while (!d.empty() && d.front().time.ns < keep_from) {
    if (keep_one_before && d.size() >= 2 && d[1].time.ns >= keep_from) break;
    d.pop_front();
  }
}

// The newest sample is at most `lead` before `end`, and an earlier epoch within `max_gap` of it gives the motion to
// continue from it.
template <typename T>
bool extrapolable(const std::deque<T>& d, Stamp end, std::int64_t lead, std::int64_t max_gap) {
  if (d.size() < 2 || d.back().time.ns < end.ns - lead) return false;
  for (auto it = d.rbegin() + 1; it != d.rend(); ++it) {
    if (it->time != d.back().time) return d.back().time.ns - it->time.ns <= max_gap;
  }
  return false;
}

// Samples from the last at or before `start` to the first at or after `end`; `complete` when both exist within
// `max_gap` of the window, or when the first exists and, with no sample at or after `end`, the newest one is at most
// `lead` before it (the pose is extrapolated from there).
template <typename T>
bool bracket(const std::deque<T>& d, Stamp start, Stamp end, std::int64_t max_gap, std::int64_t lead,
             std::vector<T>& out) {
  out.clear();
  if (d.empty()) return false;
  // First index with time > start, then step back to the last at or before it.
  auto first = std::upper_bound(d.begin(), d.end(), start, [](Stamp t, const T& e) { return t < e.time; });
  bool lower_ok = false;
  if (first != d.begin() && start.ns - std::prev(first)->time.ns <= max_gap) {
    --first;
    lower_ok = true;
    // Samples of one epoch share a time (GGA, RMC and VTG of one fix): all of them open the bracket.
    while (first != d.begin() && std::prev(first)->time == first->time) --first;
  }
  auto last = std::lower_bound(d.begin(), d.end(), end, [](const T& e, Stamp t) { return e.time < t; });
  bool upper_ok = false;
  if (last != d.end() && last->time.ns - end.ns <= max_gap) {
    upper_ok = true;
    const Stamp t = last->time;
    while (last != d.end() && last->time == t) ++last;
  } else if (last == d.end() && lead > 0 && extrapolable(d, end, lead, max_gap)) {
    upper_ok = true;
    // Extrapolated from the newest samples: the epoch before the first goes in too, so that two epochs at least
    // give the motion to continue (one alone would only be held).
    if (lower_ok && first != d.begin() && first->time.ns - std::prev(first)->time.ns <= max_gap) {
      --first;
      while (first != d.begin() && std::prev(first)->time == first->time) --first;
    }
  }
  if (first < last) out.assign(first, last);
  return lower_ok && upper_ok;
}

}  // namespace

std::vector<std::string> AssemblerParams::validate() const {
  std::vector<std::string> p;
  if (!(rate_hz >= 0.5 && rate_hz <= 50.0)) p.emplace_back("sync.rate_hz must be 0.5..50");
  if (!(timeout_s > 0.0 && timeout_s <= 10.0)) p.emplace_back("sync.timeout_s must be in (0, 10]");
  if (!(max_scan_offset_s > 0.0)) p.emplace_back("sync.max_scan_offset_s must be positive");
  if (!(max_bracket_gap_s > 0.0)) p.emplace_back("sync.max_bracket_gap_s must be positive");
  if (!(gnss_lead_s >= 0.0 && gnss_lead_s <= max_bracket_gap_s))
    p.emplace_back("sync.gnss_lead_s must be in [0, max_bracket_gap_s]");
  if (!(ahrs_lead_s >= 0.0 && ahrs_lead_s <= max_bracket_gap_s))
    p.emplace_back("sync.ahrs_lead_s must be in [0, max_bracket_gap_s]");
  if (!(history_s >= timeout_s)) p.emplace_back("sync.history_s must be at least timeout_s");
  if (max_pending < 1) p.emplace_back("sync.max_pending must be at least 1");
  return p;
}

FrameAssembler::FrameAssembler(const AssemblerParams& params) : params_(params) {
  if (const auto problems = params_.validate(); !problems.empty()) throw std::invalid_argument(problems.front());
  period_ns_ = to_ns(1.0 / params_.rate_hz);
}

void FrameAssembler::add_rotation(LidarRotation&& r) {
  ++counters_.rotations;
  constexpr std::int64_t kOverlapTolerance = 1'000'000;  // 1 ms of clock-model wobble between rotations
  if (r.end < r.start || (last_rotation_end_ && r.start.ns < last_rotation_end_->ns - kOverlapTolerance) ||
      (emitted_until_ && r.start.ns < emitted_until_->ns - kOverlapTolerance)) {
    ++counters_.late_rotations;
    return;
  }
  const std::int64_t span = r.end.ns - r.start.ns;
  if (!open_.empty()) {
    // A lost rotation (or a long loss of packets) leaves a gap: the window so far is closed short.
    const std::int64_t gap_limit = std::max<std::int64_t>(span / 4, 5'000'000);
    if (r.start.ns - open_.back().end.ns > gap_limit) close_open(true);
  }
  last_rotation_end_ = r.end;
  if (r.partial) {
    // A partial rotation (stream start or end) is a frame of its own, so a whole one is never cut by it.
    if (!open_.empty()) close_open(true);
    open_.push_back(std::move(r));
    close_open(true);
    return;
  }
  open_.push_back(std::move(r));
  const std::int64_t window = open_.back().end.ns - open_.front().start.ns;
  if (window >= period_ns_ - span / 2) close_open(false);
}

void FrameAssembler::close_open(bool partial) {
  if (open_.empty()) return;
  Window w;
  w.start = open_.front().start;
  w.end = open_.back().end;
  w.partial = partial;
  for (const LidarRotation& r : open_) w.partial = w.partial || r.partial;
  w.rotations.swap(open_);
  if (!spare_lists_.empty()) {  // the next window's rotations go into an earlier window's list: no allocation
    open_.swap(spare_lists_.back());
    spare_lists_.pop_back();
  }
  pending_.push_back(std::move(w));
}

void FrameAssembler::add_scan(TimedScan&& s) {
  if (emitted_until_ && s.time.ns < emitted_until_->ns - to_ns(params_.history_s)) {
    ++counters_.late_samples;
    return;
  }
  insert_sorted(scans_, std::move(s));
  trim(scans_, to_ns(params_.history_s), false);
}

void FrameAssembler::add_gnss(TimedGnss&& g) {
  if (emitted_until_ && g.time.ns < emitted_until_->ns - to_ns(params_.history_s)) {
    ++counters_.late_samples;
    return;
  }
  insert_sorted(gnss_, std::move(g));
  trim(gnss_, to_ns(params_.history_s), true);
}

void FrameAssembler::add_attitude(TimedAttitude&& a) {
  if (emitted_until_ && a.time.ns < emitted_until_->ns - to_ns(params_.history_s)) {
    ++counters_.late_samples;
    return;
  }
  insert_sorted(ahrs_, std::move(a));
  trim(ahrs_, to_ns(params_.history_s), true);
}

std::uint8_t FrameAssembler::not_ready(const Window& w) const {
  std::uint8_t nr = 0;
  const Stamp mid{w.start.ns + (w.end.ns - w.start.ns) / 2};
  if (params_.require_scan2d && (scans_.empty() || scans_.back().time < mid)) nr |= bit(SensorKind::Scan2d);
  // A sample at or after the end, or one close enough before it to extrapolate from (see bracket()).
  const std::int64_t gap = to_ns(params_.max_bracket_gap_s);
  const auto ready = [&](const auto& d, double lead_s) {
    return !d.empty() && (d.back().time >= w.end || (lead_s > 0.0 && extrapolable(d, w.end, to_ns(lead_s), gap)));
  };
  if (params_.require_gnss && !ready(gnss_, params_.gnss_lead_s)) nr |= bit(SensorKind::Gnss);
  if (params_.require_ahrs && !ready(ahrs_, params_.ahrs_lead_s)) nr |= bit(SensorKind::Ahrs);
  return nr;
}

std::size_t FrameAssembler::buffered(SensorKind k) const {
  switch (k) {
    case SensorKind::Lidar3d: {
      std::size_t n = open_.size();
      for (const Window& w : pending_) n += w.rotations.size();
      return n;
    }
    case SensorKind::Scan2d: return scans_.size();
    case SensorKind::Gnss: return gnss_.size();
    case SensorKind::Ahrs: return ahrs_.size();
  }
  return 0;
}

std::optional<Stamp> FrameAssembler::oldest_pending_end() const {
  if (pending_.empty()) return std::nullopt;
  return pending_.front().end;
}

std::optional<SensorKind> FrameAssembler::waiting_for() const {
  if (pending_.empty()) return std::nullopt;
  const std::uint8_t nr = not_ready(pending_.front());
  for (SensorKind k : kAllSensors) {
    if ((nr & bit(k)) != 0) return k;
  }
  return std::nullopt;
}

void FrameAssembler::recycle(SyncedFrame&& frame) { (void)spare_frames_.put(std::move(frame)); }

bool FrameAssembler::take_spare_points(std::vector<LidarPoint>& out) {
  if (spare_points_.empty()) return false;
  out = std::move(spare_points_.back());
  spare_points_.pop_back();
  return true;
}

SyncedFrame FrameAssembler::build(Window&& w, bool timed_out) {
  SyncedFrame f;
  (void)spare_frames_.take(f);
  f.seq = next_seq_++;
  f.window_start = w.start;
  f.window_end = w.end;
  f.last_packet_host = Stamp{};
  f.partial = w.partial;
  f.timed_out = timed_out;
  f.missing = 0;
  f.rotations = static_cast<std::uint32_t>(w.rotations.size());
  for (const LidarRotation& r : w.rotations) f.last_packet_host = std::max(f.last_packet_host, r.last_host);
  // The first rotation starts the window: its points are taken over as they are (no copy at 5 Hz spin) unless the
  // recycled frame's buffer has the room its rotation's lacks; the others are appended with their times shifted
  // onto the window's start. Every buffer left over goes back to the rotation assembler (take_spare_points()).
  std::size_t n = 0;
  for (const LidarRotation& r : w.rotations) n += r.points.size();
  std::vector<LidarPoint>& first = w.rotations.front().points;
  if (first.capacity() >= n || f.points.capacity() < n) {
    f.points.swap(first);
  } else {
    f.points.assign(first.begin(), first.end());
  }
  f.points.reserve(n);
  for (std::size_t i = 1; i < w.rotations.size(); ++i) {
    const LidarRotation& r = w.rotations[i];
    const auto shift = static_cast<float>(static_cast<double>(r.start.ns - w.start.ns) * 1e-9);
    // Room made once, then each point copied with its time shifted in the same pass (a point-by-point push_back
    // was a tenth of the io thread's time; a block copy and a second pass for the times, 0.3-0.5 ms at frame close).
    const std::size_t at = f.points.size();
    f.points.resize(at + r.points.size());  // within the room reserved above: constructs, no allocation
    LidarPoint* const dst = f.points.data() + at;
    const LidarPoint* const src = r.points.data();
    for (std::size_t k = 0; k < r.points.size(); ++k) {
      dst[k] = src[k];
      dst[k].time_s += shift;
    }
  }
  // Room for a whole frame (and an eighth more, as rotations vary) in every buffer handed back: the rotation
  // written into it next, when it starts a window, becomes that frame's buffer as it is, and only the window's
  // later rotations are copied. One allocation per buffer while warming up; the same buffers after.
  const std::size_t frame_room = n + n / 8;
  for (LidarRotation& r : w.rotations) {
    if (r.points.capacity() == 0 || spare_points_.size() >= kMaxSpare) continue;
    if (w.rotations.size() > 1 && (r.points.capacity() < frame_room || r.points.capacity() > 2 * frame_room)) {
      r.points = std::vector<LidarPoint>();  // nothing to keep; and one grown by a burst goes back to the system
      r.points.reserve(frame_room);
    }
    // Otherwise not cleared: the rotation assembler writes over the points it holds (RotationAssembler::recycle())
    // instead of constructing them again.
    spare_points_.push_back(std::move(r.points));
  }
  w.rotations.clear();
  if (spare_lists_.size() < kMaxSpare) spare_lists_.push_back(std::move(w.rotations));

  const Stamp mid = f.middle();
  if (!scans_.empty()) {
    auto it =
        std::lower_bound(scans_.begin(), scans_.end(), mid, [](const TimedScan& e, Stamp t) { return e.time < t; });
    if (it == scans_.end() || (it != scans_.begin() && mid.ns - std::prev(it)->time.ns <= it->time.ns - mid.ns)) {
      --it;
    }
    if (std::llabs(it->time.ns - mid.ns) <= to_ns(params_.max_scan_offset_s)) {
      f.scan2d = *it;  // over a recycled frame's scan: its vectors keep their room
    } else {
      f.scan2d.reset();
    }
  } else {
    f.scan2d.reset();
  }
  if (params_.require_scan2d && !f.scan2d) f.missing |= bit(SensorKind::Scan2d);
  const std::int64_t gap = to_ns(params_.max_bracket_gap_s);
  if (!bracket(gnss_, w.start, w.end, gap, to_ns(params_.gnss_lead_s), f.gnss) && params_.require_gnss)
    f.missing |= bit(SensorKind::Gnss);
  if (!bracket(ahrs_, w.start, w.end, gap, to_ns(params_.ahrs_lead_s), f.ahrs) && params_.require_ahrs)
    f.missing |= bit(SensorKind::Ahrs);

  ++counters_.frames;
  if (timed_out) ++counters_.timed_out;
  if (f.missing == 0) ++counters_.complete;
  for (SensorKind k : kAllSensors) {
    if (f.is_missing(k)) ++counters_.missing[static_cast<std::size_t>(k)];
  }
  emitted_until_ = w.end;
  prune(w.end);
  return f;
}

void FrameAssembler::prune(Stamp used_until) {
  const std::int64_t keep_from = used_until.ns - to_ns(params_.history_s);
  while (!scans_.empty() && scans_.front().time.ns < keep_from) scans_.pop_front();
  // The last GNSS/AHRS sample at or before the window's end opens the next window's bracket: always kept.
  while (gnss_.size() >= 2 && gnss_.front().time.ns < keep_from && gnss_[1].time <= used_until) gnss_.pop_front();
  while (ahrs_.size() >= 2 && ahrs_.front().time.ns < keep_from && ahrs_[1].time <= used_until) ahrs_.pop_front();
}

void FrameAssembler::poll(Stamp now, std::vector<SyncedFrame>& out) {
  const std::int64_t timeout = to_ns(params_.timeout_s);
  while (!pending_.empty()) {
    const std::uint8_t nr = not_ready(pending_.front());
    const bool overflow = pending_.size() > params_.max_pending;
    const bool expired = now.ns - pending_.front().end.ns > timeout;
    if (nr != 0 && !overflow && !expired) break;
    if (nr != 0 && overflow && !expired) ++counters_.overflowed;
    Window w = std::move(pending_.front());
    pending_.erase(pending_.begin());
    out.push_back(build(std::move(w), nr != 0));
  }
}

void FrameAssembler::finish(std::vector<SyncedFrame>& out) {
  close_open(true);
  while (!pending_.empty()) {
    const std::uint8_t nr = not_ready(pending_.front());
    Window w = std::move(pending_.front());
    pending_.erase(pending_.begin());
    out.push_back(build(std::move(w), nr != 0));
  }
}

}  // namespace fieldguard::sync
