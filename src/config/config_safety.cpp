#include "config/config_safety.hpp"

#include <charconv>
#include <string>

namespace fieldguard::app {
namespace {

using output::safety::Sensor;

void read_bool(YamlReader& r, const YAML::Node& n, const std::string& path, const char* key, bool& out) {
  if (auto v = r.choice(n, path, key, {"false", "true"})) out = *v == 1;
}

// The node of `key` ("zone.friction") under `n`, or its nearest parent that exists: where an issue points.
// Recursive on purpose: assigning to a yaml-cpp Node rewrites the node it refers to instead of rebinding it.
YAML::Node node_at(const YAML::Node& n, const std::string& key) {
  const std::size_t dot = key.find('.');
  const std::string head = key.substr(0, dot);
  if (!n.IsMap() || !n[head]) return n;
  const YAML::Node child = n[head];
  return dot == std::string::npos ? child : node_at(child, key.substr(dot + 1));
}

void read_zone(YamlReader& r, const YAML::Node& n, output::safety::ZoneParams& z) {
  const std::string path = "safety.zone";
  if (!r.section(n, path,
                 {"front_x_m", "rear_x_m", "half_width_m", "margin_m", "min_length_m", "full_speed_kmh", "friction",
                  "reaction_time_s"})) {
    return;
  }
  r.number(n, path, "front_x_m", z.front_x_m, -50.0, 50.0, "m");
  r.number(n, path, "rear_x_m", z.rear_x_m, -50.0, 50.0, "m");
  r.number(n, path, "half_width_m", z.half_width_m, 0.1, 20.0, "m");
  r.number(n, path, "margin_m", z.margin_m, 0.0, 50.0, "m");
  r.number(n, path, "min_length_m", z.min_length_m, 0.1, 100.0, "m");
  r.number(n, path, "full_speed_kmh", z.full_speed_kmh, 0.1, 80.0, "km/h");
  r.number(n, path, "friction", z.friction, 0.05, 1.5, "(no unit)");
  r.number(n, path, "reaction_time_s", z.reaction_time_s, 0.0, 5.0, "s");
}

void read_sensors(YamlReader& r, const YAML::Node& n, output::safety::Params& p) {
  const std::string path = "safety.sensors";
  if (!r.section(n, path, {"lidar", "scan2d", "gnss", "ahrs"})) return;
  for (std::size_t i = 0; i < output::safety::kSensorCount; ++i) {
    const auto s = static_cast<Sensor>(i);
    const std::string name(to_string(s));
    const std::string sp = join_path(path, name.c_str());
    const YAML::Node sn = n[name];
    if (!r.section(sn, sp, {"required", "timeout_s"})) continue;
    read_bool(r, sn, sp, "required", p.sensor(s).required);
    r.number(sn, sp, "timeout_s", p.sensor(s).timeout_s, 0.01, 60.0, "s");
  }
}

void read_gnss_limits(YamlReader& r, const YAML::Node& n, output::safety::GnssLimits& g) {
  const std::string path = "safety.gnss";
  if (!r.section(n, path, {"accepted_fix", "min_satellites", "max_hdop", "max_speed_mps"})) return;
  if (n["accepted_fix"]) {
    const YAML::Node v = n["accepted_fix"];
    const std::string p = path + ".accepted_fix";
    if (!v.IsSequence() || v.size() == 0) {
      r.issue(v, p, "expected a list of GGA fix qualities from 1 to 9, e.g. [4, 5] for RTK fixed and float");
    } else {
      std::uint16_t mask = 0;
      bool good = true;
      for (std::size_t i = 0; i < v.size(); ++i) {
        const std::string ip = p + "[" + std::to_string(i) + "]";
        const std::string text = v[i].IsScalar() ? v[i].Scalar() : std::string();
        int q = 0;
        const char* end = text.data() + text.size();
        const auto [ptr, ec] = std::from_chars(text.data(), end, q);
        if (!v[i].IsScalar() || ec != std::errc() || ptr != end || q < 1 || q > 9) {
          r.issue(v[i], ip,
                  "'" + text + "' is not a GGA fix quality from 1 to 9 (1 GPS, 2 DGPS, 4 RTK fixed, 5 RTK float, ...)");
          good = false;
        } else {
          mask = static_cast<std::uint16_t>(mask | (1U << static_cast<unsigned>(q)));
        }
      }
      if (good) g.accepted_fix_mask = mask;
    }
  }
  r.integer(n, path, "min_satellites", g.min_satellites, 0, 64);
  r.number(n, path, "max_hdop", g.max_hdop, 0.0, 100.0, "(no unit)");
  r.number(n, path, "max_speed_mps", g.max_speed_mps, 0.1, 200.0, "m/s");
}

void read_ahrs_limits(YamlReader& r, const YAML::Node& n, output::safety::AhrsLimits& a) {
  const std::string path = "safety.ahrs";
  if (!r.section(n, path, {"max_roll_deg", "max_pitch_deg", "max_rate_deg_s"})) return;
  r.number(n, path, "max_roll_deg", a.max_roll_deg, 0.1, 180.0, "degrees");
  r.number(n, path, "max_pitch_deg", a.max_pitch_deg, 0.1, 90.0, "degrees");
  r.number(n, path, "max_rate_deg_s", a.max_rate_deg_s, 1.0, 5000.0, "degrees/s");
}

}  // namespace

void read_safety(YamlReader& r, const YAML::Node& n, Config& c) {
  const std::string path = "safety";
  if (!r.section(n, path,
                 {"zone", "clear_frames", "pipeline_deadline_s", "max_frame_interval_s", "sensors", "gnss", "ahrs"})) {
    return;
  }
  auto& p = c.safety;
  read_zone(r, n["zone"], p.zone);
  r.integer(n, path, "clear_frames", p.clear_frames, 1, 1000);
  r.number(n, path, "pipeline_deadline_s", p.pipeline_deadline_s, 0.01, 10.0, "s");
  r.number(n, path, "max_frame_interval_s", p.max_frame_interval_s, 0.01, 10.0, "s");
  read_sensors(r, n["sensors"], p);
  read_gnss_limits(r, n["gnss"], p.gnss);
  read_ahrs_limits(r, n["ahrs"], p.ahrs);

  // What the ranges above cannot see: values that contradict each other.
  for (const auto& problem : output::safety::validate(p)) {
    r.issue(node_at(n, problem.key), path + "." + problem.key, problem.message);
  }
  const struct {
    Sensor sensor;
    bool enabled;
    const char* section;
  } links[] = {{Sensor::Scan2d, c.scan2d.enabled, "scan2d"},
               {Sensor::Gnss, c.gnss.serial.enabled, "gnss"},
               {Sensor::Ahrs, c.ahrs.serial.enabled, "ahrs"}};
  for (const auto& l : links) {
    if (p.sensor(l.sensor).required && !l.enabled) {
      const std::string key = std::string("sensors.").append(to_string(l.sensor)).append(".required");
      r.issue(node_at(n, key), join_path(path, key.c_str()),
              std::string("the sensor is required but ")
                  .append(l.section)
                  .append(".enabled is false; the tractor would "
                          "never start: enable ")
                  .append(l.section)
                  .append(" or set required to false"));
    }
  }
}

}  // namespace fieldguard::app
