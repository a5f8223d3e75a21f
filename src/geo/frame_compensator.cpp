#include "fieldguard/geo/frame_compensator.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <stdexcept>
#include <variant>

namespace fieldguard::geo {

namespace {

// Fixes without an altitude take the height of the nearest earlier fix of the frame that has one (of the first
// later one when none before); with none at all every height stays 0: no vertical motion, rather than a jump.
void fill_missing_heights(std::vector<CompensationWork::Fix>& fixes) {
  const CompensationWork::Fix* known = nullptr;
  for (const auto& f : fixes) {
    if (f.has_height) {
      known = &f;
      break;
    }
  }
  if (known == nullptr) return;
  double up = known->plane.up_m;
  for (auto& f : fixes) {
    if (f.has_height) {
      up = f.plane.up_m;
    } else {
      f.plane.up_m = up;
    }
  }
}

constexpr double kDeg = std::numbers::pi / 180.0;

void add_all(std::vector<std::string>& to, const std::vector<std::string>& from, const char* prefix) {
  for (const auto& p : from) to.push_back(std::string(prefix) + p);
}

const CompensationParams& checked(const CompensationParams& p) {
  const auto problems = p.validate();
  if (!problems.empty()) {
    std::string msg = "invalid frame compensation parameters:";
    for (const auto& s : problems) msg += "\n  " + s;
    throw std::invalid_argument(msg);
  }
  return p;
}

AhrsParams enu_input(AhrsParams a) {
  a.frame = AhrsFrame::Enu;
  return a;
}

DeskewParams deskew_params(const CompensationParams& p, bool use_positions) {
  DeskewParams d;
  d.lidar = p.lidar;
  d.use_positions = use_positions;
  d.pose_step_s = p.pose_step_s;
  return d;
}

ScanLiftParams lift_params(const CompensationParams& p) {
  ScanLiftParams l;
  l.scanner = p.scanner;
  l.lidar = p.lidar;
  l.turn_period_s = p.scan_turn_period_s;
  return l;
}

// GGA fix quality by precision (the codes are not ordered: 5 RTK float is worse than 4 RTK fixed); 0 for the
// codes that are never a measured position (0 invalid, 6 estimated, 7 manual, 8 simulator, 9 vendor).
int quality_rank(int q) {
  switch (q) {
    case 1: return 1;
    case 2:
    case 3: return 2;
    case 5: return 3;
    case 4: return 4;
    default: return 0;
  }
}

using Fix = CompensationWork::Fix;
using AttSample = CompensationWork::AttSample;

// The sample's Euler angles turned to the ENU convention AttitudeModel was built for; nullopt when the
// coordinate system is not one we can interpret.
std::optional<EulerDeg> enu_euler(const xsens::Vec3& e, xsens::CoordinateSystem cs) {
  const EulerDeg raw{e.x, e.y, e.z};
  switch (cs) {
    case xsens::CoordinateSystem::Enu: return raw;
    case xsens::CoordinateSystem::Ned: return enu_from_ned(raw);
    // North-west-up with the same body axes as ENU: the local frame is ENU turned by -90 deg about z, so
    // the yaw (from north, counter-clockwise) is 90 deg less than ENU's (from east).
    case xsens::CoordinateSystem::Nwu: return EulerDeg{raw.roll_deg, raw.pitch_deg, raw.yaw_deg + 90.0};
    case xsens::CoordinateSystem::Reserved: break;
  }
  return std::nullopt;
}

bool frame_matches(xsens::CoordinateSystem cs, AhrsFrame configured) {
  return (cs == xsens::CoordinateSystem::Enu && configured == AhrsFrame::Enu) ||
         (cs == xsens::CoordinateSystem::Ned && configured == AhrsFrame::Ned);
}

// Clockwise from x, 0.01 deg, 0..35999 (LidarPoint's convention).
std::uint16_t azimuth_cdeg_of(double angle_ccw_rad) {
  double cdeg = -angle_ccw_rad / kDeg * 100.0;
  cdeg = std::fmod(cdeg, 36000.0);
  if (cdeg < 0.0) cdeg += 36000.0;
  const long v = std::lround(cdeg);
  return static_cast<std::uint16_t>(v >= 36000 ? 0 : v);
}

LidarPoint detection_point(const SourcedPoint& s, const Eigen::Vector3f& t_lidar) {
  LidarPoint p;
  p.x = s.x - t_lidar.x();
  p.y = s.y - t_lidar.y();
  p.z = s.z - t_lidar.z();
  p.intensity = s.intensity;
  p.time_s = s.time_s;
  p.range_m = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
  p.ring = s.channel;
  p.source = static_cast<std::uint8_t>(s.source);
  return p;
}

bool finite_point(const LidarPoint& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.time_s);
}

}  // namespace

std::vector<std::string> CompensationParams::validate() const {
  std::vector<std::string> problems;
  add_all(problems, projection.validate(), "projection.");
  add_all(problems, ahrs.validate(), "ahrs.");
  add_all(problems, track.validate(), "track.");
  add_all(problems, deskew_params(*this, true).validate(), "");
  // The lifting parameters repeat the 3D LiDAR's mounting check; report only what is new.
  for (const auto& p : lift_params(*this).validate()) {
    if (p.rfind("lidar mounting", 0) != 0) problems.push_back(p);
  }
  if (!antenna_m.allFinite() || antenna_m.norm() > 30.0) {
    problems.emplace_back("antenna_m: must be finite and within 30 m of the vehicle origin");
  }
  if (!std::isfinite(scan_geometry.steps_per_turn) || scan_geometry.steps_per_turn <= 0.0 ||
      !std::isfinite(scan_geometry.front_step) || scan_geometry.dmin_mm >= scan_geometry.dmax_mm) {
    problems.emplace_back(
        "scan_geometry: steps_per_turn must be > 0, front_step finite and dmin_mm < dmax_mm (take the scanner's PP "
        "answer)");
  }
  if (quality_rank(min_gnss_quality) == 0) {
    problems.emplace_back(
        "min_gnss_quality: must be a GGA fix quality 1..5 (1 GPS, 2 DGPS, 3 PPS, 5 RTK float or better, 4 RTK fixed "
        "only)");
  }
  return problems;
}

const char* to_string(Levelling l) {
  switch (l) {
    case Levelling::Full: return "full";
    case Levelling::AttitudeOnly: return "attitude-only";
    case Levelling::None: return "none";
  }
  return "?";
}

FrameCompensator::FrameCompensator(const CompensationParams& params)
    : params_(checked(params)),
      projection_(params.projection),
      attitude_(enu_input(params.ahrs)),
      deskew_full_(deskew_params(params, true)),
      deskew_attitude_only_(deskew_params(params, false)),
      lifter_(lift_params(params)) {}

void FrameCompensator::compensate(const sync::SyncedFrame& frame, CompensatedFrame& out) const {
  out.levelling = Levelling::None;
  out.t_ref = frame.window_end;
  // out.points is not cleared: it is sized once below, and the room a reused frame already has is written over
  // rather than initialised again.
  out.plane.clear();
  out.reference.reset();
  out.attitude.reset();
  out.stats = CompensationStats{};
  CompensationStats& st = out.stats;

  // GNSS first: the first usable fix gives the meridian convergence the attitudes need.
  CompensationWork& work = out.work;
  std::vector<Fix>& fixes = work.fixes;
  fixes.clear();
  for (const sync::TimedGnss& g : frame.gnss) {
    const auto* gga = std::get_if<nmea::Gga>(&g.sentence);
    if (gga == nullptr) continue;
    if (!gga->quality || quality_rank(*gga->quality) == 0 ||
        quality_rank(*gga->quality) < quality_rank(params_.min_gnss_quality) || !gga->lat_deg || !gga->lon_deg) {
      ++st.gnss_rejected;
      continue;
    }
    // A position-only receiver (DGPS) leaves the altitude empty: a fix all the same. The plane position does not
    // depend on the height; the height is taken from the frame's fixes that have one (below).
    const Geodetic geo{*gga->lat_deg, *gga->lon_deg, gga->alt_m.value_or(0.0) + gga->geoid_sep_m.value_or(0.0)};
    auto plane = projection_.forward(geo);
    if (!plane) {
      ++st.gnss_rejected;
      continue;
    }
    if (!gga->alt_m) ++st.gnss_without_height;
    fixes.push_back(Fix{g.time, *plane, gga->alt_m.has_value()});
  }
  fill_missing_heights(fixes);
  const double convergence_deg = fixes.empty() ? 0.0 : fixes.front().plane.convergence_deg;

  if (!work.track || work.track_owner != this) {
    work.track.emplace(params_.track);
    work.track_owner = this;
  } else {
    work.track->clear();
  }
  PoseTrack& track = *work.track;
  std::vector<AttSample>& atts = work.atts;
  atts.clear();
  for (const sync::TimedAttitude& a : frame.ahrs) {
    const auto& e = a.data.euler_deg;
    const auto enu = e ? enu_euler(*e, a.data.euler_frame) : std::nullopt;
    if (!enu) {
      ++st.ahrs_rejected;
      continue;
    }
    const Eigen::Quaterniond q = attitude_.vehicle_in_plane(*enu, convergence_deg);
    if (!track.add_attitude(a.time, q)) {  // not finite or out of order
      ++st.ahrs_rejected;
      continue;
    }
    atts.push_back(AttSample{a.time, q});
    ++st.ahrs_used;
    if (!frame_matches(a.data.euler_frame, params_.ahrs.frame)) ++st.ahrs_frame_mismatch;
  }

  const auto max_nearest_ns = std::llround(params_.track.max_position_gap_s * 1e9);
  for (const Fix& f : fixes) {
    Eigen::Quaterniond q;
    bool nearest_used = false;
    if (auto at = track.attitude_at(f.t)) {
      q = at->q;
    } else {
      // atts is in time order (the track refused anything else); the nearest sample is at the bracket.
      const auto it =
          std::lower_bound(atts.begin(), atts.end(), f.t, [](const AttSample& s, Stamp t) { return s.t < t; });
      std::int64_t best = std::numeric_limits<std::int64_t>::max();
      const AttSample* nearest = nullptr;
      if (it != atts.end()) {
        best = it->t.ns - f.t.ns;
        nearest = &*it;
      }
      if (it != atts.begin() && f.t.ns - std::prev(it)->t.ns < best) {
        best = f.t.ns - std::prev(it)->t.ns;
        nearest = &*std::prev(it);
      }
      if (nearest == nullptr || best > max_nearest_ns) {
        ++st.gnss_rejected;
        continue;
      }
      q = nearest->q;
      nearest_used = true;
    }
    if (!track.add_position(f.t, reference_from_antenna(f.plane.enu(), q, params_.antenna_m))) {
      ++st.gnss_rejected;  // out of order
      continue;
    }
    ++st.gnss_used;
    if (nearest_used) ++st.gnss_lever_nearest;
  }

  // The 2D scan in the 3D LiDAR's frame, its times relative to window_start like the 3D points'.
  std::vector<SourcedPoint>& lifted = work.lifted;
  lifted.clear();
  if (frame.scan2d) {
    const scip::Scan& scan = frame.scan2d->scan;
    const double step_s = params_.scan_turn_period_s / params_.scan_geometry.steps_per_turn;
    const double offset_s = static_cast<double>(frame.scan2d->time.ns - frame.window_start.ns) * 1e-9 +
                            static_cast<double>(scan.first_step) * step_s;
    st.lift = lifter_.lift(scan, params_.scan_geometry, static_cast<float>(offset_s), lifted);
  }

  const Eigen::Vector3f t_lidar(static_cast<float>(params_.lidar.x_m), static_cast<float>(params_.lidar.y_m),
                                static_cast<float>(params_.lidar.z_m));
  std::vector<SourcedPoint>& level = work.level;
  level.clear();
  std::span<const LidarPoint> points3d(frame.points);
  std::span<const SourcedPoint> points2d(lifted);
  // Room for every point, written by index and trimmed after (a push_back per point cost more than initialising
  // the room); the 3D points go straight from the sensor into detection points, in one pass. The room is kept from
  // frame to frame, with an eighth to spare as frames vary, and made anew when too small (resize() would double
  // it, and keep that for good) or over half as big again as the frame (an overlong frame, as when a sensor comes
  // back, does not size every later one).
  const std::size_t room_needed = frame.points.size() + lifted.size();
  if (out.points.capacity() < room_needed || 2 * out.points.capacity() > 3 * room_needed) {
    out.points = std::vector<LidarPoint>();
    out.points.reserve(room_needed + room_needed / 8);
  }
  out.points.resize(room_needed);
  const std::span<LidarPoint> room(out.points);
  const Deskewer* used = nullptr;
  if (track.position_count() > 0) {
    if (auto s = deskew_full_.to_detection(points3d, frame.window_start, track, out.t_ref, t_lidar, room)) {
      st.lidar = *s;
      used = &deskew_full_;
      out.levelling = Levelling::Full;
    }
  }
  if (used == nullptr && track.attitude_count() > 0) {
    if (auto s = deskew_attitude_only_.to_detection(points3d, frame.window_start, track, out.t_ref, t_lidar, room)) {
      st.lidar = *s;
      used = &deskew_attitude_only_;
      out.levelling = Levelling::AttitudeOnly;
    }
  }

  LidarPoint* const dst = out.points.data();
  std::size_t written = 0;
  if (used != nullptr) {
    written = st.lidar.points_out;
    level.reserve(lifted.size());
    if (auto s = used->to_level(points2d, frame.window_start, track, out.t_ref, level)) st.scan = *s;
    for (const SourcedPoint& s : level) {
      LidarPoint p = detection_point(s, t_lidar);
      const double angle = scip::step_angle_rad(static_cast<double>(s.channel), params_.scan_geometry);
      p.azimuth_cdeg = azimuth_cdeg_of(angle);
      dst[written++] = p;
    }
    if (auto q = track.attitude_at(out.t_ref)) out.attitude = euler_of(q->q);
  } else {
    // As mounted: p_detect = R_lidar p (the LiDAR's translation added and taken off again).
    const Eigen::Matrix3f r = transform_of(params_.lidar).linear().cast<float>();
    st.lidar.points_in = frame.points.size();
    for (const LidarPoint& in : frame.points) {
      if (!finite_point(in)) {
        ++st.lidar.dropped_not_finite;
        continue;
      }
      const Eigen::Vector3f v = r * Eigen::Vector3f(in.x, in.y, in.z);
      LidarPoint p = in;
      p.x = v.x();
      p.y = v.y();
      p.z = v.z();
      p.range_m = v.norm();
      p.source = static_cast<std::uint8_t>(PointSource::Lidar3d);
      dst[written++] = p;
      ++st.lidar.points_out;
    }
    st.scan.points_in = lifted.size();
    for (const SourcedPoint& s : lifted) {
      const Eigen::Vector3f v = r * Eigen::Vector3f(s.x, s.y, s.z);
      LidarPoint p = detection_point(s, Eigen::Vector3f::Zero());
      p.x = v.x();
      p.y = v.y();
      p.z = v.z();
      p.range_m = v.norm();
      p.azimuth_cdeg = azimuth_cdeg_of(scip::step_angle_rad(static_cast<double>(s.channel), params_.scan_geometry));
      dst[written++] = p;
      ++st.scan.points_out;
    }
  }
  out.points.resize(written);

  if (out.levelling == Levelling::Full) {
    if (auto p = track.position_at(out.t_ref)) {
      PlaneCoord ref = fixes.front().plane;  // zone, convergence and scale of the frame's place
      ref.easting_m = p->p.x();
      ref.northing_m = p->p.y();
      ref.up_m = p->p.z();
      out.reference = ref;
    }
    if (params_.plane_points) {
      out.plane.reserve(frame.points.size() + lifted.size());
      (void)deskew_full_.to_plane(points3d, frame.window_start, track, out.plane);
      (void)deskew_full_.to_plane(points2d, frame.window_start, track, out.plane);
    }
  }
}

}  // namespace fieldguard::geo
