#include "fieldguard/geo/pose_track.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fieldguard::geo {

namespace {

std::int64_t to_ns(double s) { return std::llround(s * 1e9); }

bool valid_limit(double s) { return std::isfinite(s) && s >= 0.0 && s <= 60.0; }

// Index of the first sample later than t (samples sorted by t_ns, strictly increasing).
template <typename Samples>
std::size_t upper(const Samples& d, std::int64_t t) {
  const auto it = std::upper_bound(d.begin(), d.end(), t, [](std::int64_t v, const auto& s) { return v < s.t_ns; });
  return static_cast<std::size_t>(it - d.begin());
}

}  // namespace

const char* to_string(TrackError e) {
  switch (e) {
    case TrackError::Empty: return "empty";
    case TrackError::BeforeStart: return "before_start";
    case TrackError::AfterEnd: return "after_end";
    case TrackError::Gap: return "gap";
  }
  return "?";
}

std::vector<std::string> TrackParams::validate() const {
  std::vector<std::string> problems;
  if (!valid_limit(max_attitude_gap_s) || max_attitude_gap_s <= 0.0) {
    problems.emplace_back("max_attitude_gap_s: must be > 0 and <= 60 s");
  }
  if (!valid_limit(max_attitude_extrapolation_s)) {
    problems.emplace_back("max_attitude_extrapolation_s: must be 0..60 s");
  }
  if (!valid_limit(max_position_gap_s) || max_position_gap_s <= 0.0) {
    problems.emplace_back("max_position_gap_s: must be > 0 and <= 60 s");
  }
  if (!valid_limit(max_position_extrapolation_s)) {
    problems.emplace_back("max_position_extrapolation_s: must be 0..60 s");
  }
  if (max_samples < 2) problems.emplace_back("max_samples: must be at least 2");
  return problems;
}

PoseTrack::PoseTrack(const TrackParams& params)
    : params_(params),
      att_gap_ns_(to_ns(params.max_attitude_gap_s)),
      att_extra_ns_(to_ns(params.max_attitude_extrapolation_s)),
      pos_gap_ns_(to_ns(params.max_position_gap_s)),
      pos_extra_ns_(to_ns(params.max_position_extrapolation_s)) {
  const auto problems = params.validate();
  if (!problems.empty()) {
    std::string msg = "invalid pose track parameters:";
    for (const auto& p : problems) msg += "\n  " + p;
    throw std::invalid_argument(msg);
  }
}

bool PoseTrack::add_attitude(Stamp t, const Eigen::Quaterniond& vehicle_in_plane) {
  const Eigen::Quaterniond& q = vehicle_in_plane;
  if (!q.coeffs().allFinite() || q.norm() < 0.5) {
    ++rejected_finite_;
    return false;
  }
  if (!att_.empty() && t.ns <= att_.back().t_ns) {
    ++rejected_order_;
    return false;
  }
  att_.push_back({t.ns, q.normalized()});
  if (att_.size() > params_.max_samples) att_.erase(att_.begin());
  return true;
}

bool PoseTrack::add_position(Stamp t, const Eigen::Vector3d& reference_in_plane) {
  const Eigen::Vector3d& p = reference_in_plane;
  if (!p.allFinite()) {
    ++rejected_finite_;
    return false;
  }
  if (!pos_.empty() && t.ns <= pos_.back().t_ns) {
    ++rejected_order_;
    return false;
  }
  pos_.push_back({t.ns, p});
  if (pos_.size() > params_.max_samples) pos_.erase(pos_.begin());
  return true;
}

Expected<AttitudeAt, TrackError> PoseTrack::attitude_at(Stamp t) const {
  if (att_.empty()) return Unexpected{TrackError::Empty};
  const std::size_t i = upper(att_, t.ns);
  if (i == 0) {
    if (att_.front().t_ns - t.ns > att_extra_ns_) return Unexpected{TrackError::BeforeStart};
    return AttitudeAt{att_.front().q, true};
  }
  const AttSample& a = att_[i - 1];
  if (a.t_ns == t.ns) return AttitudeAt{a.q, false};
  if (i == att_.size()) {
    if (t.ns - a.t_ns > att_extra_ns_) return Unexpected{TrackError::AfterEnd};
    return AttitudeAt{a.q, true};
  }
  const AttSample& b = att_[i];
  const std::int64_t span = b.t_ns - a.t_ns;
  if (span > att_gap_ns_) return Unexpected{TrackError::Gap};
  const double u = static_cast<double>(t.ns - a.t_ns) / static_cast<double>(span);
  return AttitudeAt{a.q.slerp(u, b.q), false};
}

Expected<PositionAt, TrackError> PoseTrack::position_at(Stamp t) const {
  if (pos_.empty()) return Unexpected{TrackError::Empty};
  const std::size_t i = upper(pos_, t.ns);
  // Outside the fixes: continue the velocity of the two end fixes (held when there is one, or when the two
  // end fixes straddle a gap, which says nothing about the velocity).
  const auto extrapolate = [&](const PosSample& end, const PosSample* other) -> PositionAt {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    if (other != nullptr) {
      const std::int64_t dt = end.t_ns - other->t_ns;
      if (dt != 0 && std::llabs(dt) <= pos_gap_ns_) v = (end.p - other->p) / (static_cast<double>(dt) * 1e-9);
    }
    return PositionAt{end.p + v * (static_cast<double>(t.ns - end.t_ns) * 1e-9), true};
  };
  if (i == 0) {
    if (pos_.front().t_ns - t.ns > pos_extra_ns_) return Unexpected{TrackError::BeforeStart};
    return extrapolate(pos_.front(), pos_.size() > 1 ? &pos_[1] : nullptr);
  }
  const PosSample& a = pos_[i - 1];
  if (a.t_ns == t.ns) return PositionAt{a.p, false};
  if (i == pos_.size()) {
    if (t.ns - a.t_ns > pos_extra_ns_) return Unexpected{TrackError::AfterEnd};
    return extrapolate(a, pos_.size() > 1 ? &pos_[i - 2] : nullptr);
  }
  const PosSample& b = pos_[i];
  const std::int64_t span = b.t_ns - a.t_ns;
  if (span > pos_gap_ns_) return Unexpected{TrackError::Gap};
  const double u = static_cast<double>(t.ns - a.t_ns) / static_cast<double>(span);
  return PositionAt{a.p + u * (b.p - a.p), false};
}

Expected<Pose, TrackError> PoseTrack::pose_at(Stamp t) const {
  auto q = attitude_at(t);
  if (!q) return Unexpected{q.error()};
  auto p = position_at(t);
  if (!p) return Unexpected{p.error()};
  return Pose{q->q, p->p, q->extrapolated || p->extrapolated};
}

void PoseTrack::drop_before(Stamp t) {
  // The first sample to keep: the last at or before t (the one after it is the first later than t).
  const auto keep_from = [&](const auto& v) {
    std::size_t i = 0;
    while (i + 1 < v.size() && v[i + 1].t_ns <= t.ns) ++i;
    return static_cast<std::ptrdiff_t>(i);
  };
  att_.erase(att_.begin(), att_.begin() + keep_from(att_));
  pos_.erase(pos_.begin(), pos_.begin() + keep_from(pos_));
}

void PoseTrack::clear() {
  att_.clear();
  pos_.clear();
  rejected_order_ = 0;
  rejected_finite_ = 0;
}

}  // namespace fieldguard::geo
