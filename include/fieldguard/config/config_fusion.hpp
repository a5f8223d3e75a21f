#pragma once
// The configuration of sensor fusion: how frames are cut from the sensors' streams (`sync:`) and how the
// points are put where they really were (`geo:`). Plain values with defaults, filled and checked by the
// config loader (src/app/config_fusion.cpp).

#include <array>
#include <cstdint>

#include "fieldguard/geo/attitude.hpp"
#include "fieldguard/geo/projection.hpp"

namespace fieldguard::app {

// Frames are fused (sync::Synchronizer + geo::FrameCompensator) when a sensor besides the 3D LiDAR feeds
// them: live, when scan2d, gnss or ahrs is enabled; in replay, when their byte logs are given. A 3D LiDAR
// alone gives one frame per rotation in its sensor frame, as before fusion existed.
struct SyncConfig {
  double rate_hz = 5.0;            // frames a second, each made of whole rotations
  double timeout_s = 0.5;          // a frame still waiting for a sensor this long after its window goes out
  double max_scan_offset_s = 0.1;  // the 2D scan nearest the window's middle, if at most this far
  int max_pending = 8;             // windows waiting for late sensors; beyond it the oldest goes out
  // A frame goes out when its last rotation is whole, its pose extrapolated from the newest GNSS fix and AHRS sample
  // (within geo's extrapolation limits of the window's end: half max_position_gap_s, 0.4 max_attitude_gap_s);
  // false: it waits for the fix and the sample after its end and interpolates (a fix period plus the receiver's
  // latency later).
  bool extrapolate_pose = true;
};

struct GeoConfig {
  geo::ProjectionParams projection;                 // ellipsoid, zone width, fixed zone, zone prefix
  std::array<double, 3> antenna_m{0.0, 0.0, 2.8};   // GNSS antenna in the vehicle frame: on the cab roof
  geo::AhrsFrame ahrs_frame = geo::AhrsFrame::Enu;  // what the AHRS outputs (an MTData2 packet says it too)
  double declination_deg = 0.0;                     // east positive; 0 for a GNSS-aided (true north) AHRS
  int min_gnss_quality = 1;  // GGA fix quality ranked by precision (1 GPS < 2 DGPS = 3 PPS < 5 RTK float < 4 RTK fixed)
  double max_attitude_gap_s = 0.05;  // AHRS samples farther apart: a dropout, points dropped
  double max_position_gap_s = 0.5;   // GNSS fixes farther apart: a dropout
};

}  // namespace fieldguard::app
