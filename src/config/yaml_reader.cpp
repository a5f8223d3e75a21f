#include "config/yaml_reader.hpp"

#include <charconv>
#include <cmath>
#include <set>
#include <sstream>

namespace fieldguard::app {
namespace {

int line_1based(const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  return m.line >= 0 ? m.line + 1 : 0;
}

std::string fmt_num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

const char* kind_of(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Map: return "a mapping";
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Null: return "nothing";
    case YAML::NodeType::Scalar: return "a scalar";
    case YAML::NodeType::Undefined: break;
  }
  return "nothing";
}

}  // namespace

std::string ConfigIssue::to_string() const {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line);
  s += ": ";
  if (!key_path.empty()) s += key_path + ": ";
  s += message;
  return s;
}

void YamlReader::issue(const YAML::Node& at, const std::string& path, std::string message) {
  issues_.push_back({file_, line_1based(at), path, std::move(message)});
}

void YamlReader::issue_no_line(const std::string& path, std::string message) {
  issues_.push_back({file_, 0, path, std::move(message)});
}

int YamlReader::line_of(const YAML::Node& map, const char* key) {
  if (map.IsMap() && map[key]) return line_1based(map[key]);
  return line_1based(map);
}

bool YamlReader::section(const YAML::Node& node, const std::string& path, std::initializer_list<const char*> known) {
  if (!node) return false;
  if (!node.IsMap()) {
    issue(node, path, std::string("expected a mapping of keys, got ") + kind_of(node) + "; see config/fieldguard.yaml");
    return false;
  }
  std::set<std::string> seen;
  for (const auto& kv : node) {
    const auto key = kv.first.Scalar();
    bool ok = false;
    for (const char* k : known) ok = ok || key == k;
    if (!ok) {
      std::string list;
      for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      issue(kv.first, join_path(path, key.c_str()), "unknown key; known keys here: " + list);
    }
    if (!seen.insert(key).second) {
      issue(kv.first, join_path(path, key.c_str()), "key given twice; keep one");
    }
  }
  return true;
}

std::optional<double> YamlReader::as_number(const YAML::Node& v, const std::string& path, const char* unit) {
  if (!v.IsScalar()) {
    issue(v, path, std::string("expected a number (") + unit + "), got " + kind_of(v));
    return std::nullopt;
  }
  const std::string& s = v.Scalar();
  double d = 0.0;
  const auto* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, d);
  if (ec != std::errc() || p != end || !std::isfinite(d)) {
    issue(v, path, std::string("expected a number (") + unit + "), got '" + s + "'");
    return std::nullopt;
  }
  return d;
}

void YamlReader::number(const YAML::Node& map, const std::string& path, const char* key, double& out, double lo,
                        double hi, const char* unit) {
  if (!map.IsMap() || !map[key]) return;
  const auto p = join_path(path, key);
  const auto v = as_number(map[key], p, unit);
  if (!v) return;
  if (*v < lo || *v > hi) {
    issue(map[key], p,
          fmt_num(*v) + " is out of range; use a value from " + fmt_num(lo) + " to " + fmt_num(hi) + " " + unit);
    return;
  }
  out = *v;
}

void YamlReader::integer(const YAML::Node& map, const std::string& path, const char* key, int& out, int lo, int hi) {
  if (!map.IsMap() || !map[key]) return;
  const auto p = join_path(path, key);
  const YAML::Node v = map[key];
  if (!v.IsScalar()) {
    issue(v, p, std::string("expected a whole number, got ") + kind_of(v));
    return;
  }
  const std::string& s = v.Scalar();
  long long n = 0;
  const auto* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(s.data(), end, n);
  if (ec != std::errc() || ptr != end) {
    issue(v, p, "expected a whole number, got '" + s + "'");
    return;
  }
  if (n < lo || n > hi) {
    issue(v, p,
          std::to_string(n) + " is out of range; use a value from " + std::to_string(lo) + " to " + std::to_string(hi));
    return;
  }
  out = static_cast<int>(n);
}

void YamlReader::port(const YAML::Node& map, const std::string& path, const char* key, std::uint16_t& out) {
  int v = out;
  const auto before = issues_.size();
  integer(map, path, key, v, 1, 65535);
  if (issues_.size() == before) out = static_cast<std::uint16_t>(v);
}

void YamlReader::text(const YAML::Node& map, const std::string& path, const char* key, std::string& out) {
  if (!map.IsMap() || !map[key]) return;
  const YAML::Node v = map[key];
  if (v.IsNull()) {
    out.clear();
    return;
  }
  if (!v.IsScalar()) {
    issue(v, join_path(path, key), std::string("expected text, got ") + kind_of(v));
    return;
  }
  out = v.Scalar();
}

std::optional<std::size_t> YamlReader::choice(const YAML::Node& map, const std::string& path, const char* key,
                                              std::initializer_list<const char*> choices) {
  if (!map.IsMap() || !map[key]) return std::nullopt;
  const YAML::Node v = map[key];
  std::string list;
  for (const char* c : choices) list += (list.empty() ? "" : ", ") + std::string(c);
  if (!v.IsScalar()) {
    issue(v, join_path(path, key), std::string("expected one of ") + list + ", got " + kind_of(v));
    return std::nullopt;
  }
  std::size_t i = 0;
  for (const char* c : choices) {
    if (v.Scalar() == c) return i;
    ++i;
  }
  issue(v, join_path(path, key), "'" + v.Scalar() + "' is not one of " + list);
  return std::nullopt;
}

void YamlReader::vec3(const YAML::Node& map, const std::string& path, const char* key, std::array<double, 3>& out,
                      double lo, double hi, const char* unit) {
  if (!map.IsMap() || !map[key]) return;
  const auto p = join_path(path, key);
  const YAML::Node v = map[key];
  if (!v.IsSequence() || v.size() != 3) {
    issue(v, p,
          std::string("expected a list of 3 numbers [x, y, z] (") + unit + "), got " +
              (v.IsSequence() ? std::to_string(v.size()) + " items" : kind_of(v)));
    return;
  }
  std::array<double, 3> r{};
  bool good = true;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto item = as_number(v[i], p + "[" + std::to_string(i) + "]", unit);
    if (!item) {
      good = false;
    } else if (*item < lo || *item > hi) {
      issue(v[i], p + "[" + std::to_string(i) + "]",
            fmt_num(*item) + " is out of range; use a value from " + fmt_num(lo) + " to " + fmt_num(hi) + " " + unit);
      good = false;
    } else {
      r[i] = *item;
    }
  }
  if (good) out = r;
}

}  // namespace fieldguard::app
