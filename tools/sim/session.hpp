#pragma once
// The other sensors of a recorded session, written beside the LiDAR capture in the layout `fieldguard
// record` uses (README "record saves ..."; io/byte_log.hpp): DIR/gnss.log (NMEA GGA, RMC, HDT of an RTK
// receiver), DIR/ahrs.log (Xsens MTData2: PacketCounter, SampleTimeFine, EulerAngles ENU) and
// DIR/scan2d.log (the SCIP 2.0 conversation of a UTM-30LX-EW on the front bumper: start-up, MD, scans),
// plus DIR/pose.truth.jsonl, the true pose behind every sample.
//
// Clocks: the simulation's time 0 is SimSettings::start_time_ns (UTC; the LiDAR's first firing). GNSS
// epochs are on UTC tenths; the AHRS counts SampleTimeFine (10 kHz) and the scanner its ms counter from
// arbitrary power-on values, each with its own crystal's drift. Every record's host receive time is the
// sensor's time plus the link's latency and transmission time plus a little jitter, increasing in each log.
// Deterministic: each sensor draws from its own random stream of the seed.

#include <cstdint>
#include <string>

#include "sim/geodesy.hpp"
#include "sim/scene.hpp"

namespace fieldguard::sim {

// A pose in the vehicle frame (origin on the ground below the rear axle, x forward, y left, z up).
struct VehicleMount {
  Vec3 position;
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double yaw_deg = 0.0;
};

struct SessionSettings {
  std::string dir;
  std::uint64_t seed = 1;
  std::int64_t start_time_ns = 0;      // UTC of simulation time 0
  double duration_s = 10.0;            // samples in [0, duration_s)
  Geodetic origin{48.1, 11.6, 520.0};  // the world origin: a field north of Munich
  double field_heading_deg = 60.0;     // compass heading of world +x (the tractor's path)
  double geoid_separation_m = 47.0;    // ellipsoid - geoid there (GGA reports the height above the geoid)
  Vec3 antenna{0.0, 0.0, 2.8};         // GNSS antenna in the vehicle frame: on the cab roof
  VehicleMount scan2d{{3.95, 0.0, 0.30}, 0.0, 0.0, 0.0};  // the UTM-30LX-EW on the front bumper
  double gnss_rate_hz = 10.0;
  double gnss_sigma_m = 0.01;      // RTK fixed: horizontal, per axis (1.4 cm radial); vertical twice it
  double heading_sigma_deg = 0.1;  // dual-antenna heading
  double ahrs_rate_hz = 100.0;
  double ahrs_sigma_deg = 0.07;  // roll and pitch; yaw 0.1 deg
  double scan2d_sigma_m = 0.01;
};

struct SessionCounts {
  std::uint64_t gnss_epochs = 0;
  std::uint64_t ahrs_samples = 0;
  std::uint64_t scans = 0;
};

// The UTM-30LX-EW's geometry (protocols.md §3.3): 1081 steps of 0.25 deg, step 540 straight ahead,
// 40 scans a second, ranges to 30 m guaranteed (DMAX 60 m).
namespace utm30 {
inline constexpr int kSteps = 1081;
inline constexpr int kFrontStep = 540;
inline constexpr double kStepDeg = 0.25;
inline constexpr double kScanPeriodS = 0.025;
inline constexpr double kMaxRangeM = 30.0;
}  // namespace utm30

// Writes the three byte logs and the pose truth of `scene` (the same the LiDAR capture was made of).
// False with `error` set when a file cannot be written.
bool write_session(const Scene& scene, const SessionSettings& settings, SessionCounts& counts, std::string& error);

// The vehicle frame's origin and the vehicle -> world rotation for a sensor pose of the scene.
struct VehiclePose {
  Vec3 origin;
  Mat3 rot;
};
[[nodiscard]] VehiclePose vehicle_pose(const Scene& scene, const SensorPose& sensor);

}  // namespace fieldguard::sim
