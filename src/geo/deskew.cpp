#include "fieldguard/geo/deskew.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fieldguard/geo/attitude.hpp"
#include "geo/round.hpp"

namespace fieldguard::geo {

namespace {

struct Meta {
  float intensity;
  float time_s;
  std::uint16_t channel;
  PointSource source;
};

Meta meta_of(const LidarPoint& p) { return {p.intensity, p.time_s, p.ring, PointSource::Lidar3d}; }
Meta meta_of(const SourcedPoint& p) { return {p.intensity, p.time_s, p.channel, p.source}; }

std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  std::int64_t q = a / b;
  if ((a % b != 0) && ((a < 0) != (b < 0))) --q;
  return q;
}

void count(DeskewStats& s, TrackError e) {
  switch (e) {
    case TrackError::Empty: ++s.dropped_no_pose; break;
    case TrackError::BeforeStart: ++s.dropped_before_start; break;
    case TrackError::AfterEnd: ++s.dropped_after_end; break;
    case TrackError::Gap: ++s.dropped_gap; break;
  }
}

// Sensor point -> target frame at one instant: v = r p + t.
struct Xf {
  // Initialised although every use follows a pose (have_xf): g++ 12 at -O3 cannot see that (-Wmaybe-uninitialized).
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  bool extrapolated = false;
};

// The target frame: plane (identity) or the level frame of t_ref: v_target = l (v_plane - origin).
struct Target {
  Eigen::Matrix3d l = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
};

}  // namespace

std::vector<std::string> DeskewParams::validate() const {
  std::vector<std::string> problems;
  const Mounting& m = lidar;
  if (!std::isfinite(m.x_m) || !std::isfinite(m.y_m) || !std::isfinite(m.z_m) || !std::isfinite(m.roll_deg) ||
      !std::isfinite(m.pitch_deg) || !std::isfinite(m.yaw_deg)) {
    problems.emplace_back("lidar mounting: every value must be a finite number");
  }
  if (!std::isfinite(pose_step_s) || pose_step_s < 0.0 || pose_step_s > 0.01) {
    problems.emplace_back("pose_step_s: must be 0 (exact) .. 0.01 s");
  }
  return problems;
}

Deskewer::Deskewer(const DeskewParams& params) : params_(params) {
  const auto problems = params.validate();
  if (!problems.empty()) {
    std::string msg = "invalid deskew parameters:";
    for (const auto& p : problems) msg += "\n  " + p;
    throw std::invalid_argument(msg);
  }
  const Eigen::Isometry3d m = transform_of(params.lidar);
  lidar_r_ = m.linear();
  lidar_t_ = m.translation();
  step_ns_ = std::llround(params.pose_step_s * 1e9);
}

namespace {

template <typename P, typename Emit>
DeskewStats run(std::span<const P> points, Stamp base, const PoseTrack& track, const Target& target, bool use_positions,
                const Eigen::Matrix3d& lidar_r, const Eigen::Vector3d& lidar_t, std::int64_t step_ns, Emit&& emit) {
  DeskewStats stats;
  stats.points_in = points.size();
  // The current step's times [step_lo, step_hi): a point inside it shares the pose without a division.
  std::int64_t step_lo = 0;
  std::int64_t step_hi = 0;
  bool have_step = false;
  Xf xf{};
  bool have_xf = false;
  TrackError last_error = TrackError::Empty;
  for (const P& p : points) {
    const Meta m = meta_of(p);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(m.time_s)) {
      ++stats.dropped_not_finite;
      continue;
    }
    const std::int64_t t_ns = base.ns + round_half_away(static_cast<double>(m.time_s) * 1e9);
    const bool same_step = have_step && (step_ns > 0 ? t_ns >= step_lo && t_ns < step_hi : t_ns == step_lo);
    if (!same_step) {
      step_lo = step_ns > 0 ? floor_div(t_ns, step_ns) * step_ns : t_ns;
      step_hi = step_lo + step_ns;
      have_step = true;
      const Stamp at{step_ns > 0 ? step_lo + step_ns / 2 : t_ns};
      have_xf = false;
      auto q = track.attitude_at(at);
      if (!q) {
        last_error = q.error();
      } else {
        Eigen::Vector3d pos = Eigen::Vector3d::Zero();
        bool extrapolated = q->extrapolated;
        bool ok = true;
        if (use_positions) {
          auto pp = track.position_at(at);
          if (!pp) {
            last_error = pp.error();
            ok = false;
          } else {
            pos = pp->p;
            extrapolated = extrapolated || pp->extrapolated;
          }
        }
        if (ok) {
          const Eigen::Matrix3d r = q->q.toRotationMatrix();
          xf.r = target.l * r * lidar_r;
          xf.t = target.l * (r * lidar_t + pos - target.origin);
          xf.extrapolated = extrapolated;
          have_xf = true;
        }
      }
    }
    if (!have_xf) {
      count(stats, last_error);
      continue;
    }
    // Written out: Eigen's product here was a call per point.
    const auto px = static_cast<double>(p.x);
    const auto py = static_cast<double>(p.y);
    const auto pz = static_cast<double>(p.z);
    const Eigen::Matrix3d& r = xf.r;
    const Eigen::Vector3d v(r(0, 0) * px + r(0, 1) * py + r(0, 2) * pz + xf.t.x(),
                            r(1, 0) * px + r(1, 1) * py + r(1, 2) * pz + xf.t.y(),
                            r(2, 0) * px + r(2, 1) * py + r(2, 2) * pz + xf.t.z());
    emit(v, p, m, xf.extrapolated ? kExtrapolatedPose : std::uint8_t{0});
    ++stats.points_out;
    if (xf.extrapolated) ++stats.extrapolated;
  }
  return stats;
}

// The level frame of t_ref: yaw about the vertical and the reference position (with positions).
Expected<Target, DeskewError> level_target(const PoseTrack& track, Stamp t_ref, bool use_positions) {
  Target target;
  auto q_ref = track.attitude_at(t_ref);
  if (!q_ref) return Unexpected{DeskewError::NoReferencePose};
  if (use_positions) {
    auto p_ref = track.position_at(t_ref);
    if (!p_ref) return Unexpected{DeskewError::NoReferencePose};
    target.origin = p_ref->p;
  }
  target.l = Eigen::AngleAxisd(-horizontal_yaw_rad(q_ref->q), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return target;
}

template <typename P>
Expected<DeskewStats, DeskewError> level_impl(std::span<const P> points, Stamp base, const PoseTrack& track,
                                              Stamp t_ref, bool use_positions, const Eigen::Matrix3d& lidar_r,
                                              const Eigen::Vector3d& lidar_t, std::int64_t step_ns,
                                              std::vector<SourcedPoint>& out) {
  const auto target = level_target(track, t_ref, use_positions);
  if (!target) return Unexpected{target.error()};
  // Room for every point, written by index and trimmed after: a push_back per point (not inlined) cost more than
  // initialising the room.
  const std::size_t first = out.size();
  out.resize(first + points.size());
  SourcedPoint* const dst = out.data() + first;
  std::size_t n = 0;
  const DeskewStats stats = run(points, base, track, *target, use_positions, lidar_r, lidar_t, step_ns,
                                [dst, &n](const Eigen::Vector3d& v, const P&, const Meta& m, std::uint8_t flags) {
                                  dst[n++] = SourcedPoint{static_cast<float>(v.x()),
                                                          static_cast<float>(v.y()),
                                                          static_cast<float>(v.z()),
                                                          m.intensity,
                                                          m.time_s,
                                                          m.channel,
                                                          m.source,
                                                          flags};
                                });
  out.resize(first + n);
  return stats;
}

template <typename P>
DeskewStats plane_impl(std::span<const P> points, Stamp base, const PoseTrack& track, bool use_positions,
                       const Eigen::Matrix3d& lidar_r, const Eigen::Vector3d& lidar_t, std::int64_t step_ns,
                       std::vector<PlanePoint>& out) {
  const std::size_t first = out.size();  // as level_impl: room written by index, trimmed after
  out.resize(first + points.size());
  PlanePoint* const dst = out.data() + first;
  std::size_t n = 0;
  const DeskewStats stats = run(points, base, track, Target{}, use_positions, lidar_r, lidar_t, step_ns,
                                [dst, &n](const Eigen::Vector3d& v, const P&, const Meta& m, std::uint8_t flags) {
                                  dst[n++] = PlanePoint{v, m.intensity, m.time_s, m.channel, m.source, flags};
                                });
  out.resize(first + n);
  return stats;
}

}  // namespace

Expected<DeskewStats, DeskewError> Deskewer::to_level(std::span<const LidarPoint> points, Stamp base,
                                                      const PoseTrack& track, Stamp t_ref,
                                                      std::vector<SourcedPoint>& out) const {
  return level_impl(points, base, track, t_ref, params_.use_positions, lidar_r_, lidar_t_, step_ns_, out);
}

Expected<DeskewStats, DeskewError> Deskewer::to_detection(std::span<const LidarPoint> points, Stamp base,
                                                          const PoseTrack& track, Stamp t_ref,
                                                          const Eigen::Vector3f& offset,
                                                          std::span<LidarPoint> room) const {
  if (room.size() < points.size()) throw std::invalid_argument("Deskewer::to_detection: room for fewer points");
  const auto target = level_target(track, t_ref, params_.use_positions);
  if (!target) return Unexpected{target.error()};
  LidarPoint* const dst = room.data();
  std::size_t n = 0;
  // The same float steps as to_level() then the offset taken off, so either way gives the same bits.
  return run(points, base, track, *target, params_.use_positions, lidar_r_, lidar_t_, step_ns_,
             [dst, &n, &offset](const Eigen::Vector3d& v, const LidarPoint& in, const Meta&, std::uint8_t) {
               LidarPoint& p = dst[n++];
               p.x = static_cast<float>(v.x()) - offset.x();
               p.y = static_cast<float>(v.y()) - offset.y();
               p.z = static_cast<float>(v.z()) - offset.z();
               p.intensity = in.intensity;
               p.time_s = in.time_s;
               p.range_m = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
               p.azimuth_cdeg = in.azimuth_cdeg;
               p.ring = in.ring;
               p.return_type = in.return_type;
               p.source = static_cast<std::uint8_t>(PointSource::Lidar3d);
               p.reserved1 = 0;
             });
}

Expected<DeskewStats, DeskewError> Deskewer::to_level(std::span<const SourcedPoint> points, Stamp base,
                                                      const PoseTrack& track, Stamp t_ref,
                                                      std::vector<SourcedPoint>& out) const {
  return level_impl(points, base, track, t_ref, params_.use_positions, lidar_r_, lidar_t_, step_ns_, out);
}

DeskewStats Deskewer::to_plane(std::span<const LidarPoint> points, Stamp base, const PoseTrack& track,
                               std::vector<PlanePoint>& out) const {
  return plane_impl(points, base, track, params_.use_positions, lidar_r_, lidar_t_, step_ns_, out);
}

DeskewStats Deskewer::to_plane(std::span<const SourcedPoint> points, Stamp base, const PoseTrack& track,
                               std::vector<PlanePoint>& out) const {
  return plane_impl(points, base, track, params_.use_positions, lidar_r_, lidar_t_, step_ns_, out);
}

}  // namespace fieldguard::geo
