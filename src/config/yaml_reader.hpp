#pragma once
// Walks a yaml-cpp tree for the config loader, collecting every problem with its line and key path
// instead of stopping at the first. Private to the app module.

#include <yaml-cpp/yaml.h>

#include <array>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/config/config.hpp"

namespace fieldguard::app {

class YamlReader {
 public:
  explicit YamlReader(std::string file) : file_(std::move(file)) {}

  void issue(const YAML::Node& at, const std::string& path, std::string message);
  void issue_no_line(const std::string& path, std::string message);

  // A mapping section: reports unknown keys (with the list of known ones) and duplicate keys.
  // Returns false (after reporting) when `node` is present but not a mapping.
  bool section(const YAML::Node& node, const std::string& path, std::initializer_list<const char*> known);

  // Optional scalars: absent keys leave `out` (the default) alone.
  void number(const YAML::Node& map, const std::string& path, const char* key, double& out, double lo, double hi,
              const char* unit);
  void integer(const YAML::Node& map, const std::string& path, const char* key, int& out, int lo, int hi);
  void port(const YAML::Node& map, const std::string& path, const char* key, std::uint16_t& out);
  void text(const YAML::Node& map, const std::string& path, const char* key, std::string& out);
  // One of a fixed set of words; returns the index into `choices` or nullopt when absent or wrong.
  std::optional<std::size_t> choice(const YAML::Node& map, const std::string& path, const char* key,
                                    std::initializer_list<const char*> choices);
  void vec3(const YAML::Node& map, const std::string& path, const char* key, std::array<double, 3>& out, double lo,
            double hi, const char* unit);

  // Line of a key's value (or of the map) for consistency errors found after reading.
  [[nodiscard]] static int line_of(const YAML::Node& map, const char* key);

  std::vector<ConfigIssue>& issues() { return issues_; }
  [[nodiscard]] const std::string& file() const { return file_; }

 private:
  std::optional<double> as_number(const YAML::Node& v, const std::string& path, const char* unit);
  std::string file_;
  std::vector<ConfigIssue> issues_;
};

[[nodiscard]] inline std::string join_path(const std::string& base, const char* key) {
  return base.empty() ? std::string(key) : base + "." + key;
}

}  // namespace fieldguard::app
