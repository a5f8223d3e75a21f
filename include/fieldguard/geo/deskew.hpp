#pragma once
// Per-point motion compensation ("deskew"): every point is moved with the vehicle pose at its own time,
// then expressed in
//   - the level frame of a reference time t_ref (attitude.hpp): origin the vehicle reference point at
//     t_ref, z vertical, x the vehicle's horizontal heading at t_ref. Detection works in it: the ground
//     is level whatever the tractor's roll and pitch, and a rotation swept while the tractor rocks and
//     drives is one consistent snapshot;
//   - or the plane frame (Gauss-Krueger easting, northing, height; doubles) for recording and maps.
//
// p_plane(t) = P(t) + R(t) (R_lidar p_sensor + t_lidar)      P, R: PoseTrack at t = base + point.time_s
// p_level    = Rz(yaw_ref)^T (p_plane(t) - P(t_ref))
//
// A point whose time has no pose (TrackError) is dropped and counted by reason; a pose held or continued
// past the samples marks the point (kExtrapolatedPose) and is counted.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "fieldguard/core/expected.hpp"
#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/core/mounting.hpp"
#include "fieldguard/core/time.hpp"
#include "fieldguard/geo/pose_track.hpp"
#include "fieldguard/geo/sourced_point.hpp"

namespace fieldguard::geo {

struct DeskewParams {
  Mounting lidar;  // the 3D LiDAR in the vehicle frame; every input point is in its frame
  // false: no GNSS positions, the vehicle is taken to stand still (attitude-only levelling: roll and
  // pitch removed, travel during the rotation not).
  bool use_positions = true;
  // Poses are computed once per step of this length and shared by the points inside it (0: exactly at
  // every point's time). The pose is taken at the step's centre: at most step/2 off, e.g. 50 us, which at
  // 0.5 rad/s of rocking and 5 m/s is 25 urad (1.3 mm at 50 m) and 0.25 mm.
  double pose_step_s = 1e-4;

  [[nodiscard]] std::vector<std::string> validate() const;
};

struct DeskewStats {
  std::size_t points_in = 0;
  std::size_t points_out = 0;
  std::size_t extrapolated = 0;  // out, with a held/continued pose
  std::size_t dropped_no_pose = 0;
  std::size_t dropped_before_start = 0;
  std::size_t dropped_after_end = 0;
  std::size_t dropped_gap = 0;
  std::size_t dropped_not_finite = 0;  // NaN/inf coordinates or time
  [[nodiscard]] std::size_t dropped() const {
    return dropped_no_pose + dropped_before_start + dropped_after_end + dropped_gap + dropped_not_finite;
  }
};

struct PlanePoint {
  Eigen::Vector3d enu = Eigen::Vector3d::Zero();  // easting, northing, height (m)
  float intensity = 0.F;
  float time_s = 0.F;
  std::uint16_t channel = 0;
  PointSource source = PointSource::Lidar3d;
  std::uint8_t flags = 0;
};

enum class DeskewError : std::uint8_t {
  NoReferencePose,  // the track cannot answer t_ref (level frame only)
};

// Thread-compatible; const calls may run concurrently on one Deskewer.
class Deskewer {
 public:
  explicit Deskewer(const DeskewParams& params);  // throws std::invalid_argument when invalid

  // Appends to `out` (not cleared). Points in the 3D LiDAR's frame; times after `base`.
  [[nodiscard]] Expected<DeskewStats, DeskewError> to_level(std::span<const LidarPoint> points, Stamp base,
                                                            const PoseTrack& track, Stamp t_ref,
                                                            std::vector<SourcedPoint>& out) const;
  [[nodiscard]] Expected<DeskewStats, DeskewError> to_level(std::span<const SourcedPoint> points, Stamp base,
                                                            const PoseTrack& track, Stamp t_ref,
                                                            std::vector<SourcedPoint>& out) const;
  // 3D points straight into detection points (FrameCompensator's one pass): the level frame of t_ref less
  // `offset` (the LiDAR's position, so that range_m is measured from it), range_m recomputed, azimuth, ring,
  // return type and intensity kept, source Lidar3d. Writes room[0, points_out); room holds points.size().
  [[nodiscard]] Expected<DeskewStats, DeskewError> to_detection(std::span<const LidarPoint> points, Stamp base,
                                                                const PoseTrack& track, Stamp t_ref,
                                                                const Eigen::Vector3f& offset,
                                                                std::span<LidarPoint> room) const;
  [[nodiscard]] DeskewStats to_plane(std::span<const LidarPoint> points, Stamp base, const PoseTrack& track,
                                     std::vector<PlanePoint>& out) const;
  [[nodiscard]] DeskewStats to_plane(std::span<const SourcedPoint> points, Stamp base, const PoseTrack& track,
                                     std::vector<PlanePoint>& out) const;

  [[nodiscard]] const DeskewParams& params() const { return params_; }

 private:
  DeskewParams params_;
  Eigen::Matrix3d lidar_r_;
  Eigen::Vector3d lidar_t_;
  std::int64_t step_ns_;
};

}  // namespace fieldguard::geo
