// The `can:` section: where the CAN frames go and the J1939 addresses they carry.

#include <charconv>
#include <filesystem>

#include "config/section_readers.hpp"
#include "fieldguard/output/can_sink.hpp"

namespace fieldguard::app {
namespace {

// A J1939 address, written as a number (128) or in hex as on the tractor's documentation (0x80).
void read_address(YamlReader& r, const YAML::Node& n, const std::string& path, const char* key, std::uint8_t& out) {
  if (!n.IsMap() || !n[key]) return;
  const YAML::Node v = n[key];
  const std::string p = join_path(path, key);
  const std::string s = v.IsScalar() ? v.Scalar() : std::string();
  const bool hex = s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
  const char* begin = s.data() + (hex ? 2 : 0);
  const char* end = s.data() + s.size();
  unsigned value = 0;
  const auto [ptr, ec] = std::from_chars(begin, end, value, hex ? 16 : 10);
  if (!v.IsScalar() || s.empty() || ec != std::errc() || ptr != end) {
    r.issue(v, p, "expected a J1939 address such as 0x80 or 128, got '" + s + "'");
    return;
  }
  if (value > 0xFD) {
    r.issue(v, p, s + " is not a node address: 0xFE and 0xFF are the J1939 null and global addresses; use 0x00-0xFD");
    return;
  }
  out = static_cast<std::uint8_t>(value);
}

}  // namespace

void read_can(YamlReader& r, const YAML::Node& n, const std::string& config_dir, CanConfig& c) {
  const std::string path = "can";
  if (!r.section(n, path,
                 {"sink", "interface", "log_path", "source_address", "controller_address", "max_obstacles",
                  "heartbeat_period_s", "speed", "speed_timeout_s"})) {
    return;
  }
  if (auto s = r.choice(n, path, "sink", {"socketcan", "candump", "none"})) {
    c.sink = *s == 0 ? CanSinkKind::SocketCan : (*s == 1 ? CanSinkKind::Candump : CanSinkKind::None);
  }
  r.text(n, path, "interface", c.interface);
  r.text(n, path, "log_path", c.log_path);
  read_address(r, n, path, "source_address", c.params.source_address);
  read_address(r, n, path, "controller_address", c.params.controller_address);
  int max_obstacles = c.params.max_obstacles;
  r.integer(n, path, "max_obstacles", max_obstacles, 0, output::kMaxObstacleMessages);
  c.params.max_obstacles = static_cast<std::uint8_t>(max_obstacles);
  r.number(n, path, "heartbeat_period_s", c.heartbeat_period_s, 0.02, 1.0, "s");
  if (auto s = r.choice(n, path, "speed", {"none", "ccvs1", "iso_wheel_based"})) {
    c.speed = *s == 0 ? SpeedInput::None : (*s == 1 ? SpeedInput::Ccvs1 : SpeedInput::IsoWheelBased);
  }
  r.number(n, path, "speed_timeout_s", c.speed_timeout_s, 0.05, 10.0, "s");

  if (const std::string bad = output::check_interface_name(c.interface); !bad.empty()) {
    r.issue(n.IsMap() && n["interface"] ? n["interface"] : n, "can.interface", bad);
  }
  if (c.sink == CanSinkKind::Candump) {
    if (c.log_path.empty()) {
      r.issue(n.IsMap() && n["sink"] ? n["sink"] : n, "can.log_path",
              "sink candump writes a candump log but no log_path is given; name the file, e.g. "
              "/var/lib/fieldguard/can.log");
    } else if (std::filesystem::path(c.log_path).is_relative() && !config_dir.empty()) {
      c.log_path = (std::filesystem::path(config_dir) / c.log_path).string();
    }
  }
  if (c.params.controller_address == c.params.source_address && n.IsMap() &&
      (n["source_address"] || n["controller_address"])) {
    r.issue(n["controller_address"] ? n["controller_address"] : n["source_address"], "can.controller_address",
            "equals can.source_address; two nodes on one bus cannot share an address");
  }
}

}  // namespace fieldguard::app
