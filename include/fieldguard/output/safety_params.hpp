#pragma once
// Parameters of the stop decision (the safety monitor): plain values with defaults, filled by the app's
// config loader from the `safety:` section. Units are in the names. Frame: the 3D LiDAR's sensor frame
// (x forward, y left, metres), the frame the obstacles come in.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fieldguard::output::safety {

// The sensors the monitor watches. Their order is the bit order of every sensor mask.
enum class Sensor : std::uint8_t { Lidar = 0, Scan2d = 1, Gnss = 2, Ahrs = 3 };
inline constexpr std::size_t kSensorCount = 4;
[[nodiscard]] std::string_view to_string(Sensor s);  // "lidar", "scan2d", "gnss", "ahrs" (the config's names)
[[nodiscard]] constexpr std::uint8_t bit(Sensor s) { return static_cast<std::uint8_t>(1U << static_cast<unsigned>(s)); }

inline constexpr double kGravity_mps2 = 9.81;

// The stop zone: a rectangle from rear_x_m to front_x_m + length, and from -half_width_m to +half_width_m.
// length = max(min_length_m, reaction_time_s * v + v^2 / (2 friction g) + margin_m) at the vehicle speed v,
// or at full_speed_kmh when the speed is not known. The part behind front_x_m is the zone beside the tractor
// (the body itself is removed by perception, so only what stands beside it can be there).
struct ZoneParams {
  double front_x_m = 0.4;        // the tractor's front (perception.body.max x): the length counts from here
  double rear_x_m = -5.0;        // the zone beside the tractor reaches back to here (perception.body.min x)
  double half_width_m = 2.0;     // half the zone's width: half the widest of tractor and implement, plus a margin
  double margin_m = 1.0;         // added to the stopping distance
  double min_length_m = 3.0;     // shortest zone ahead of front_x_m, however slow the tractor goes
  double full_speed_kmh = 30.0;  // the zone is sized for this speed when the speed is not known
  double friction = 0.3;         // tyre-ground friction coefficient mu on the field (no unit)
  double reaction_time_s = 0.5;  // from the obstacle's first rotation to the brakes acting: frame, pipeline, CAN,
                                 // controller and brake build-up
};

struct SensorParams {
  bool required = false;   // the tractor may not drive without it: silence or implausible data stops it
  double timeout_s = 0.5;  // silent longer than this (host receive time) = sensor fault
};

// What makes GNSS data implausible (checked by GnssCheck, see plausibility.hpp).
struct GnssLimits {
  // Accepted GGA fix qualities, bit q for quality q (0 invalid, 1 GPS, 2 DGPS, 4 RTK fixed, 5 RTK float, ...).
  std::uint16_t accepted_fix_mask = (1U << 4U) | (1U << 5U);
  int min_satellites = 5;       // fewer satellites in use: implausible; 0 = not checked
  double max_hdop = 4.0;        // larger horizontal dilution of precision: implausible; 0 = not checked
  double max_speed_mps = 20.0;  // a position jump faster than this between fixes is impossible for a tractor
};

// What makes AHRS data implausible (AhrsCheck).
struct AhrsLimits {
  double max_roll_deg = 30.0;  // a tractor tilted further is rolling over, or the AHRS is wrong
  double max_pitch_deg = 30.0;
  double max_rate_deg_s = 180.0;  // attitude changing faster than this between samples is not physical
};

struct Params {
  ZoneParams zone;
  int clear_frames = 3;               // go only after this many consecutive frames with every reason clear
  double pipeline_deadline_s = 0.3;   // a frame decided later than this after its last data: pipeline late
  double max_frame_interval_s = 0.5;  // no frame decided for this long: pipeline late (stalled)
  std::array<SensorParams, kSensorCount> sensors{{
      {true, 0.3},   // lidar: a 5-20 Hz rotation streams packets continuously
      {false, 0.2},  // scan2d: 40 scans a second
      {false, 1.5},  // gnss: 1-10 fixes a second
      {false, 0.1},  // ahrs: 100 samples a second or more
  }};
  GnssLimits gnss;
  AhrsLimits ahrs;

  [[nodiscard]] const SensorParams& sensor(Sensor s) const { return sensors[static_cast<std::size_t>(s)]; }
  [[nodiscard]] SensorParams& sensor(Sensor s) { return sensors[static_cast<std::size_t>(s)]; }
  [[nodiscard]] std::uint8_t required_mask() const;
};

// One problem of a parameter set: `key` is its path under `safety:` in the config ("zone.friction").
struct ParamProblem {
  std::string key;
  std::string message;  // what is wrong and what to do about it
};
// Every problem at once (empty = usable): non-finite, negative or zero sizes, zero frames, an empty
// zone, no accepted fix quality, ...
[[nodiscard]] std::vector<ParamProblem> validate(const Params& p);

// Stopping distance v^2 / (2 mu g) (m) at speed v (m/s) with friction mu.
[[nodiscard]] double braking_distance_m(double speed_mps, double friction);
// Zone length ahead of front_x_m (m) for a speed (m/s), or for full_speed_kmh when unknown (nullopt or not finite).
[[nodiscard]] double zone_length_m(const ZoneParams& z, std::optional<double> speed_mps);

}  // namespace fieldguard::output::safety
