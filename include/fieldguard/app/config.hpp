#pragma once
// The daemon's configuration: one YAML file, loaded and validated here and nowhere else. Modules get
// their typed structs; they never see the parse tree.

#include <cstdint>
#include <string>
#include <vector>

#include "fieldguard/core/mounting.hpp"
#include "fieldguard/drivers/velodyne_calibration.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::app {

struct LidarConfig {
  velodyne::Model model = velodyne::Model::Unknown;  // Unknown = detect from the stream ("auto")
  std::string calibration_file;                      // "" = built-in table; .yaml (ROS) or .xml (VeloView)
  std::uint16_t data_port = 2368;
  std::uint16_t position_port = 8308;
  velodyne::TimestampReference timestamp_reference = velodyne::TimestampReference::LastFiring;
  double min_range_m = 0.5;
  double max_range_m = 130.0;
  double rotation_cut_deg = 0.0;
  Mounting mounting;

  // Filled by the loader when calibration_file is set and readable.
  velodyne::Calibration calibration;
  bool has_calibration = false;
};

struct Config {
  std::string source_file;  // the file it was loaded from
  LidarConfig lidar;
  perception::PipelineParams perception;
};

// One problem found in a configuration file.
struct ConfigIssue {
  std::string file;
  int line = 0;           // 1-based; 0 when the problem is not tied to a line
  std::string key_path;   // "perception.roi.min"
  std::string message;    // what is wrong and what to do about it
  [[nodiscard]] std::string to_string() const;  // "file:line: key.path: message"
};

struct LoadResult {
  Config config;
  std::vector<ConfigIssue> issues;  // empty = valid
  [[nodiscard]] bool ok() const { return issues.empty(); }
};

// Loads and validates a file: every problem is collected (unknown keys, wrong types, out-of-range and
// inconsistent values), none stops the others from being found. Never throws.
[[nodiscard]] LoadResult load_config_file(const std::string& path);
// Same from text (tests); `name` is used in the issues' file field.
[[nodiscard]] LoadResult load_config_text(const std::string& text, const std::string& name);

}  // namespace fieldguard::app
