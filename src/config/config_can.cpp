// The `can:` section: where the CAN frames go and the J1939 addresses they carry.

#include <charconv>
#include <filesystem>
#include <optional>
#include <type_traits>

#include "config/section_readers.hpp"
#include "fieldguard/output/can_sink.hpp"

namespace fieldguard::app {
namespace {

// An unsigned number in decimal (128) or, with 0x, in hex (0x80); nullopt when it is neither or too large for T.
// `hex` says which it was.
template <typename T>
std::optional<T> parse_unsigned(const std::string& s, bool& hex) {
  hex = s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
  const char* end = s.data() + s.size();
  T value = 0;
  const auto [ptr, ec] = std::from_chars(s.data() + (hex ? 2 : 0), end, value, hex ? 16 : 10);
  if (s.empty() || ec != std::errc() || ptr != end) return std::nullopt;
  return value;
}

// A J1939 address, written as a number (128) or in hex as on the tractor's documentation (0x80).
void read_address(YamlReader& r, const YAML::Node& n, const std::string& path, const char* key, std::uint8_t& out) {
  if (!n.IsMap() || !n[key]) return;
  const YAML::Node v = n[key];
  const std::string p = join_path(path, key);
  const std::string s = v.IsScalar() ? v.Scalar() : std::string();
  bool hex = false;
  const auto parsed = parse_unsigned<unsigned>(s, hex);
  if (!v.IsScalar() || !parsed) {
    r.issue(v, p, "expected a J1939 address such as 0x80 or 128, got '" + s + "'");
    return;
  }
  if (*parsed > 0xFD) {
    r.issue(v, p, s + " is not a node address: 0xFE and 0xFF are the J1939 null and global addresses; use 0x00-0xFD");
    return;
  }
  out = static_cast<std::uint8_t>(*parsed);
}

// can.j1939: the NAME's fields each in its bits, the controller's NAME as 16 hex digits.
void read_j1939(YamlReader& r, const YAML::Node& n, J1939Config& c) {
  const std::string path = "can.j1939";
  if (!r.section(n, path,
                 {"address_claim", "arbitrary_address", "identity_number", "manufacturer_code", "function",
                  "function_instance", "ecu_instance", "vehicle_system", "vehicle_system_instance", "industry_group",
                  "controller_name", "component_id"})) {
    return;
  }
  if (auto v = r.choice(n, path, "address_claim", {"false", "true"})) c.address_claim = *v == 1;
  if (auto v = r.choice(n, path, "arbitrary_address", {"false", "true"})) c.name.arbitrary_address_capable = *v == 1;
  auto field = [&](const char* key, auto& out, int hi) {
    int v = static_cast<int>(out);
    r.integer(n, path, key, v, 0, hi);
    out = static_cast<std::remove_reference_t<decltype(out)>>(v);
  };
  field("identity_number", c.name.identity_number, (1 << 21) - 1);
  field("manufacturer_code", c.name.manufacturer_code, (1 << 11) - 1);
  field("function", c.name.function, 255);
  field("function_instance", c.name.function_instance, 31);
  field("ecu_instance", c.name.ecu_instance, 7);
  field("vehicle_system", c.name.vehicle_system, 127);
  field("vehicle_system_instance", c.name.vehicle_system_instance, 15);
  field("industry_group", c.name.industry_group, 7);
  std::string controller;
  r.text(n, path, "controller_name", controller);
  if (!controller.empty()) {
    bool hex = false;
    const auto v = parse_unsigned<std::uint64_t>(controller, hex);
    if (!v || !hex) {
      r.issue(n["controller_name"], path + ".controller_name",
              "expected the controller's 64-bit NAME in hex as `inspect` prints it (0x...), got '" + controller + "'");
    } else {
      c.controller_name = *v;
    }
  }
  r.text(n, path, "component_id", c.component_id);
  if (c.component_id.size() + 1 > output::j1939::kMaxTransportBytes) {
    r.issue(n["component_id"], path + ".component_id", "longer than one J1939 transport message (1784 characters)");
  }
}

}  // namespace

void read_can(YamlReader& r, const YAML::Node& n, const std::string& config_dir, CanConfig& c) {
  const std::string path = "can";
  if (!r.section(n, path,
                 {"sink", "interface", "log_path", "source_address", "controller_address", "max_obstacles",
                  "heartbeat_period_s", "speed", "speed_timeout_s", "j1939"})) {
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
  if (n.IsMap() && n["j1939"]) read_j1939(r, n["j1939"], c.j1939);

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
