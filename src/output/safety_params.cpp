#include "fieldguard/output/safety_params.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace fieldguard::output::safety {

std::string_view to_string(Sensor s) {
  switch (s) {
    case Sensor::Lidar: return "lidar";
    case Sensor::Scan2d: return "scan2d";
    case Sensor::Gnss: return "gnss";
    case Sensor::Ahrs: return "ahrs";
  }
  return "unknown sensor";
}

std::uint8_t Params::required_mask() const {
  std::uint8_t m = 0;
  for (std::size_t i = 0; i < kSensorCount; ++i) {
    if (sensors[i].required) m = static_cast<std::uint8_t>(m | bit(static_cast<Sensor>(i)));
  }
  return m;
}

double braking_distance_m(double speed_mps, double friction) {
  return speed_mps * speed_mps / (2.0 * friction * kGravity_mps2);
}

double zone_length_m(const ZoneParams& z, std::optional<double> speed_mps) {
  // Reversing is not the forward zone's business; the magnitude keeps a sign error from shrinking the zone.
  const double v = (speed_mps && std::isfinite(*speed_mps)) ? std::abs(*speed_mps) : z.full_speed_kmh / 3.6;
  const double stopping = z.reaction_time_s * v + braking_distance_m(v, z.friction) + z.margin_m;
  return std::max(z.min_length_m, stopping);
}

namespace {

class Problems {
 public:
  void add(std::string key, std::string message) { list_.push_back({std::move(key), std::move(message)}); }
  // `value` must be finite and at least `lo` (strictly above it when `strict`).
  void at_least(const std::string& key, double value, double lo, bool strict, const char* unit) {
    std::ostringstream m;
    if (!std::isfinite(value)) {
      m << "is not a number; give a value in " << unit;
    } else if (strict ? !(value > lo) : !(value >= lo)) {
      m << value << " " << unit << " must be " << (strict ? "greater than " : "at least ") << lo;
    } else {
      return;
    }
    add(key, m.str());
  }
  std::vector<ParamProblem> take() { return std::move(list_); }

 private:
  std::vector<ParamProblem> list_;
};

}  // namespace

std::vector<ParamProblem> validate(const Params& p) {
  Problems out;
  const ZoneParams& z = p.zone;
  out.at_least("zone.half_width_m", z.half_width_m, 0.0, true, "m");
  out.at_least("zone.margin_m", z.margin_m, 0.0, false, "m");
  out.at_least("zone.min_length_m", z.min_length_m, 0.0, true, "m");
  out.at_least("zone.full_speed_kmh", z.full_speed_kmh, 0.0, true, "km/h");
  out.at_least("zone.friction", z.friction, 0.0, true, "(no unit)");
  out.at_least("zone.reaction_time_s", z.reaction_time_s, 0.0, false, "s");
  if (!std::isfinite(z.front_x_m)) out.add("zone.front_x_m", "is not a number; give the tractor's front in m");
  if (!std::isfinite(z.rear_x_m)) out.add("zone.rear_x_m", "is not a number; give a position in m");
  if (std::isfinite(z.front_x_m) && std::isfinite(z.rear_x_m) && !(z.rear_x_m <= z.front_x_m)) {
    out.add("zone.rear_x_m",
            "must not be ahead of zone.front_x_m; the zone beside the tractor reaches back from its front");
  }
  if (std::isfinite(z.friction) && z.friction > 1.5) {
    out.add("zone.friction", "above 1.5 is not a tyre on the ground; a field is 0.3 to 0.6");
  }
  if (p.clear_frames < 1)
    out.add("clear_frames", "must be at least 1 frame; 0 would let the tractor go on a frame it has not seen");
  out.at_least("pipeline_deadline_s", p.pipeline_deadline_s, 0.0, true, "s");
  out.at_least("max_frame_interval_s", p.max_frame_interval_s, 0.0, true, "s");
  for (std::size_t i = 0; i < kSensorCount; ++i) {
    const std::string key = "sensors." + std::string(to_string(static_cast<Sensor>(i))) + ".timeout_s";
    out.at_least(key, p.sensors[i].timeout_s, 0.0, true, "s");
  }
  if (!p.sensor(Sensor::Lidar).required && !p.sensor(Sensor::Scan2d).required) {
    out.add("sensors.lidar.required",
            "no LiDAR is required; the monitor would let the tractor drive without "
            "seeing anything: require the lidar (or the scan2d)");
  }
  if ((p.gnss.accepted_fix_mask & 0x3FEU) == 0) {
    out.add("gnss.accepted_fix",
            "accepts no fix quality from 1 to 9; list the qualities that may drive, e.g. [4, 5] (RTK)");
  }
  if ((p.gnss.accepted_fix_mask & 1U) != 0) out.add("gnss.accepted_fix", "0 means no fix and cannot be accepted");
  if (p.gnss.min_satellites < 0) out.add("gnss.min_satellites", "must not be negative (0 = not checked)");
  out.at_least("gnss.max_hdop", p.gnss.max_hdop, 0.0, false, "(no unit)");
  out.at_least("gnss.max_speed_mps", p.gnss.max_speed_mps, 0.0, true, "m/s");
  out.at_least("ahrs.max_roll_deg", p.ahrs.max_roll_deg, 0.0, true, "degrees");
  out.at_least("ahrs.max_pitch_deg", p.ahrs.max_pitch_deg, 0.0, true, "degrees");
  out.at_least("ahrs.max_rate_deg_s", p.ahrs.max_rate_deg_s, 0.0, true, "degrees/s");
  return out.take();
}

}  // namespace fieldguard::output::safety
