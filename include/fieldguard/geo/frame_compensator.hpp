#pragma once
// One SyncedFrame (sync/synced_frame.hpp) made into the cloud detection runs on and the cloud a recorder
// keeps:
//   - the frame's own GNSS fixes (GGA with a fix: antenna position projected to the plane, lever arm
//     removed with the attitude at the fix's time) and AHRS samples (Euler angles through AttitudeModel,
//     with the meridian convergence of the frame's first usable fix) become a PoseTrack of this frame only,
//     so every frame is compensated from its own data, whatever worker runs it and in whatever order;
//   - the 3D LiDAR's points are deskewed (each moved with the pose at its own time) into the level frame of
//     the window's end, the newest instant the frame knows (the stop decision wants where things are now);
//   - the 2D LiDAR's scan is lifted through its mounting into the 3D LiDAR's frame and deskewed the same
//     way, each point marked PointSource::Lidar2d;
//   - the result is expressed in the detection frame (below) and, on request, in plane coordinates.
//
// Detection frame: the level frame (attitude.hpp) moved to the 3D LiDAR's nominal mounting position:
//   p_detect = p_level - (lidar.x_m, lidar.y_m, lidar.z_m)
// so x is the vehicle's horizontal heading, y left, z up, and flat level ground under the tractor lies at
// z = -lidar.z_m, which is what perception's sensor_height_m (copied from lidar.mounting.z_m) expects.
// ROI, body box and stop zone, configured in the sensor frame, keep their meaning; only roll and pitch
// (and the travel during the window) are gone.
//
// Degraded data is a mode, never an exception, and is reported in `levelling`:
//   Full          attitude and positions: deskewed for rocking and travel;
//   AttitudeOnly  no usable GNSS in the frame: roll and pitch removed, travel during the window not (the
//                 vehicle taken to stand still at the reference point); no plane output;
//   None          no usable AHRS (or no attitude at the window's end): the points stay as mounted, i.e.
//                 p_detect = R_lidar p_sensor + t_lidar - t_lidar, and the scan is lifted without deskew.
// Points whose own time has no pose (a gap inside the window) are dropped and counted in the stats.
// GNSS that does not reach the window's end (no position at t_ref) also degrades to AttitudeOnly.
//
// Inputs, as sync hands them over:
//   - GNSS: GGA only (the other sentences carry no position); quality at least min_gnss_quality, latitude,
//     longitude and altitude present; ellipsoidal height = alt_m + geoid_sep_m (0 when absent). The lever
//     arm is removed with the attitude at the fix's time; a fix the attitude track cannot answer (the
//     frame's first fix may be up to a GNSS period before the first AHRS sample) takes the nearest AHRS
//     sample's attitude when it is within track.max_position_gap_s (roll and pitch change little in that
//     time), counted in gnss_lever_nearest; farther it is rejected.
//   - AHRS: MtData2::euler_deg in the coordinate system its data id names (euler_frame). The decoded
//     data id is what the sensor really sent, so it wins over AhrsParams::frame (the configured
//     expectation); samples where the two differ are used as decoded and counted in
//     ahrs_frame_mismatch so the health report can flag the misconfiguration. ENU, NED and NWU are
//     understood; the reserved coordinate system is rejected.
//   - 2D scan: TimedScan::time is the scan's SCIP timestamp mapped, which marks step 0 (AMIN) of the
//     turn (tools/sim/session.cpp: step i is measured i steps after the timestamp); a scan that starts at
//     a later first_step has its first step that many step times after the stamp. Single source: the
//     simulator; protocols.md does not say which step a real UTM-30LX-EW's timestamp marks.
// Output metadata: a 3D point keeps its firing's azimuth_cdeg and return_type; a 2D point's azimuth_cdeg
// is its step's angle (clockwise from the scanner's x, 0.01 deg) and return_type Strongest.
//
// Thread-safe for const calls: compensate() may run on several workers at once.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/core/mounting.hpp"
#include "fieldguard/core/time.hpp"
#include "fieldguard/drivers/scip_data.hpp"
#include "fieldguard/geo/attitude.hpp"
#include "fieldguard/geo/deskew.hpp"
#include "fieldguard/geo/pose_track.hpp"
#include "fieldguard/geo/projection.hpp"
#include "fieldguard/geo/scan_lift.hpp"
#include "fieldguard/sync/synced_frame.hpp"

namespace fieldguard::geo {

struct CompensationParams {
  ProjectionParams projection;
  AhrsParams ahrs;                                      // output frame, mounting, declination
  Eigen::Vector3d antenna_m = Eigen::Vector3d::Zero();  // GNSS antenna phase centre in the vehicle frame
  Mounting lidar;                                       // the 3D LiDAR in the vehicle frame
  Mounting scanner;                                     // the 2D LiDAR in the vehicle frame
  double scan_turn_period_s = 0.025;                    // UTM-30LX-EW: 40 turns a second
  scip::Geometry scan_geometry;                         // the 2D LiDAR's PP answer (defaults: UTM-30LX-EW)
  TrackParams track;
  double pose_step_s = 1e-4;  // DeskewParams::pose_step_s
  // The least GGA fix quality used, by precision, not by code: 1 GPS < 2 DGPS = 3 PPS < 5 RTK float < 4 RTK
  // fixed (4: RTK fixed only; 5: RTK float or fixed). 0 invalid, 6 estimated (dead reckoning), 7 manual
  // and 8 simulator are never positions; 1..5 are the valid settings.
  int min_gnss_quality = 1;
  bool plane_points = false;  // also fill CompensatedFrame::plane (recording)

  [[nodiscard]] std::vector<std::string> validate() const;  // "key: problem" each; empty when valid
};

enum class Levelling : std::uint8_t { Full = 0, AttitudeOnly = 1, None = 2 };
[[nodiscard]] const char* to_string(Levelling l);

struct CompensationStats {
  DeskewStats lidar;  // 3D LiDAR points through deskew
  DeskewStats scan;   // lifted 2D points through deskew
  ScanLiftStats lift;
  std::size_t gnss_used = 0;            // fixes that went into the track
  std::size_t gnss_rejected = 0;        // GGA without a fix, below min_gnss_quality, not projectable, out of order
  std::size_t gnss_without_height = 0;  // used, but the GGA had no altitude (its height from the frame's others)
  std::size_t ahrs_used = 0;
  std::size_t ahrs_rejected = 0;        // no Euler angles, not finite, out of order, reserved coordinate system
  std::size_t ahrs_frame_mismatch = 0;  // used, but the data id's frame differs from AhrsParams::frame
  std::size_t gnss_lever_nearest = 0;   // used with the nearest AHRS sample's attitude for the lever arm
};

// Working storage of FrameCompensator::compensate(), kept with the caller's CompensatedFrame: a caller that reuses
// its frame allocates nothing once warm.
struct CompensationWork {
  struct Fix {  // one GGA fix that passed the checks, projected
    Stamp t;
    PlaneCoord plane;
    bool has_height = true;  // the GGA had an altitude (a position-only receiver sends none)
  };
  struct AttSample {
    Stamp t;
    Eigen::Quaterniond q;
  };
  std::vector<Fix> fixes;
  std::vector<AttSample> atts;
  std::vector<SourcedPoint> lifted;  // the 2D scan in the 3D LiDAR's frame
  std::vector<SourcedPoint> level;   // the 2D scan deskewed and levelled, before it becomes detection points
  std::optional<PoseTrack> track;
  const void* track_owner = nullptr;  // the compensator whose TrackParams built `track`
};

struct CompensatedFrame {
  Levelling levelling = Levelling::None;
  Stamp t_ref;  // the instant of the level frame: the window's end
  // Detection frame (above); 3D LiDAR points first in their input order, then the 2D scan's, each with
  // `source` set. time_s stays relative to the frame's window_start; range_m is the distance from the
  // 3D LiDAR's nominal position after compensation; ring: 3D ring, or the 2D scan's step.
  std::vector<LidarPoint> points;
  std::vector<PlanePoint> plane;  // when params.plane_points and levelling == Full
  // The vehicle reference point at t_ref (levelling Full); zone, convergence and scale are those of the
  // frame's first usable fix.
  std::optional<PlaneCoord> reference;
  std::optional<EulerDeg> attitude;  // the vehicle's attitude at t_ref, plane frame (levelling != None)
  CompensationStats stats;
  CompensationWork work;  // compensate()'s, not a result
};

class FrameCompensator {
 public:
  explicit FrameCompensator(const CompensationParams& params);  // throws std::invalid_argument when invalid

  // Fills `out` (cleared first; its vectors' capacity is reused).
  void compensate(const sync::SyncedFrame& frame, CompensatedFrame& out) const;

  [[nodiscard]] const CompensationParams& params() const { return params_; }

 private:
  CompensationParams params_;
  GaussKrueger projection_;
  AttitudeModel attitude_;  // built for ENU input: each sample is turned to ENU by its own euler_frame
  Deskewer deskew_full_;
  Deskewer deskew_attitude_only_;
  ScanLifter lifter_;
};

}  // namespace fieldguard::geo
