#include "config/config_sensors.hpp"

namespace fieldguard::app {
namespace {

void read_bool(YamlReader& r, const YAML::Node& n, const std::string& path, const char* key, bool& out) {
  if (auto v = r.choice(n, path, key, {"false", "true"})) out = *v == 1;
}

// Serial link keys shared by gnss and ahrs.
constexpr std::initializer_list<const char*> kSerialKeys = {"enabled",           "device",           "baud", "framing",
                                                            "silence_timeout_s", "reopen_interval_s"};

void read_serial(YamlReader& r, const YAML::Node& n, const std::string& path, SerialConfig& c) {
  read_bool(r, n, path, "enabled", c.enabled);
  r.text(n, path, "device", c.device);
  if (auto b = r.choice(n, path, "baud", {"9600", "19200", "38400", "57600", "115200", "230400", "460800", "921600"})) {
    static constexpr unsigned kBauds[] = {9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600};
    c.baud = kBauds[*b];
  }
  if (n.IsMap() && n["framing"]) {
    const YAML::Node f = n["framing"];
    const std::string s = f.IsScalar() ? f.Scalar() : "";
    const bool ok = s.size() == 3 && s[0] >= '5' && s[0] <= '8' && (s[1] == 'N' || s[1] == 'E' || s[1] == 'O') &&
                    (s[2] == '1' || s[2] == '2');
    if (!ok) {
      r.issue(f, path + ".framing",
              "'" + s + "' is not a framing like 8N1 (data bits 5-8, parity N/E/O, stop bits 1-2)");
    } else {
      c.data_bits = static_cast<unsigned>(s[0] - '0');
      c.parity = s[1];
      c.stop_bits = static_cast<unsigned>(s[2] - '0');
    }
  }
  r.number(n, path, "silence_timeout_s", c.silence_timeout_s, 0.01, 60.0, "s");
  r.number(n, path, "reopen_interval_s", c.reopen_interval_s, 0.01, 60.0, "s");
  if (c.enabled && c.device.empty()) {
    r.issue(n, path + ".device",
            "the link is enabled but names no device; give e.g. /dev/ttyUSB0 or a /dev/serial/by-id/ link");
  }
}

}  // namespace

void read_mounting(YamlReader& r, const YAML::Node& n, const std::string& path, Mounting& m) {
  if (!r.section(n, path, {"x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"})) return;
  r.number(n, path, "x_m", m.x_m, -20.0, 20.0, "m");
  r.number(n, path, "y_m", m.y_m, -20.0, 20.0, "m");
  r.number(n, path, "z_m", m.z_m, -5.0, 10.0, "m");
  r.number(n, path, "roll_deg", m.roll_deg, -180.0, 180.0, "degrees");
  r.number(n, path, "pitch_deg", m.pitch_deg, -90.0, 90.0, "degrees");
  r.number(n, path, "yaw_deg", m.yaw_deg, -180.0, 180.0, "degrees");
}

void read_scan2d(YamlReader& r, const YAML::Node& n, Scan2dConfig& c) {
  const std::string path = "scan2d";
  if (!r.section(n, path,
                 {"enabled", "host", "port", "start_step", "end_step", "intensity", "connect_timeout_s",
                  "silence_timeout_s", "backoff_max_s", "mounting"})) {
    return;
  }
  read_bool(r, n, path, "enabled", c.enabled);
  r.text(n, path, "host", c.host);
  r.port(n, path, "port", c.port);
  r.integer(n, path, "start_step", c.start_step, 0, 1080);
  r.integer(n, path, "end_step", c.end_step, 0, 1080);
  read_bool(r, n, path, "intensity", c.intensity);
  r.number(n, path, "connect_timeout_s", c.connect_timeout_s, 0.05, 60.0, "s");
  r.number(n, path, "silence_timeout_s", c.silence_timeout_s, 0.05, 60.0, "s");
  r.number(n, path, "backoff_max_s", c.backoff_max_s, 0.05, 600.0, "s");
  read_mounting(r, n["mounting"], "scan2d.mounting", c.mounting);
  if (c.start_step > c.end_step) {
    r.issue(n["end_step"] ? n["end_step"] : n, "scan2d.end_step",
            "must not be less than start_step (steps 0..1080, front at 540)");
  }
  if (c.enabled && c.host.empty())
    r.issue(n, "scan2d.host", "the 2D LiDAR is enabled but has no host; the factory default is 192.168.0.10");
}

void read_gnss(YamlReader& r, const YAML::Node& n, GnssConfig& c) {
  std::initializer_list<const char*> keys = kSerialKeys;
  if (!r.section(n, "gnss", keys)) return;
  read_serial(r, n, "gnss", c.serial);
}

void read_ahrs(YamlReader& r, const YAML::Node& n, AhrsConfig& c) {
  if (!r.section(n, "ahrs",
                 {"enabled", "device", "baud", "framing", "silence_timeout_s", "reopen_interval_s", "mounting"})) {
    return;
  }
  read_serial(r, n, "ahrs", c.serial);
  read_mounting(r, n["mounting"], "ahrs.mounting", c.mounting);
}

}  // namespace fieldguard::app
