#pragma once
// The daemon's configuration: one YAML file, loaded and validated here and nowhere else. Modules get
// their typed structs; they never see the parse tree.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/config/config_fusion.hpp"
#include "fieldguard/config/config_output.hpp"
#include "fieldguard/core/mounting.hpp"
#include "fieldguard/drivers/lidar3d_stream.hpp"
#include "fieldguard/drivers/robosense.hpp"
#include "fieldguard/drivers/velodyne_calibration.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"
#include "fieldguard/output/safety_params.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::app {

struct LidarConfig {
  lidar3d::Model model = lidar3d::Model::Auto;  // Auto = from the datagrams
  // "" = built-in table (Velodyne), DIFOP's (RS-32); .yaml (ROS) or .xml (VeloView) for a Velodyne, the unit's
  // angle.csv for an RS-32.
  std::string calibration_file;
  std::uint16_t data_port = 2368;      // Velodyne data packets
  std::uint16_t position_port = 8308;  // Velodyne position packets
  std::uint16_t msop_port = 6699;      // RS-32 MSOP (points)
  std::uint16_t difop_port = 7788;     // RS-32 DIFOP (device info: angles, return mode)
  velodyne::TimestampReference timestamp_reference = velodyne::TimestampReference::LastFiring;
  double min_range_m = 0.5;
  double max_range_m = 130.0;
  double rotation_cut_deg = 0.0;
  Mounting mounting;

  // Filled by the loader when calibration_file is set and readable: a Velodyne table, or an RS-32 one.
  velodyne::Calibration calibration;
  bool has_calibration = false;
  std::optional<robosense::Calibration> rs32_calibration;
};

// Hokuyo UTM-30LX-EW over SCIP 2.0 (TCP): covers the near blind zone in front of the 3D LiDAR.
struct Scan2dConfig {
  bool enabled = false;
  std::string host = "192.168.0.10";
  std::uint16_t port = 10940;
  int start_step = 0;  // 0..1080, front at 540
  int end_step = 1080;
  bool intensity = false;  // ME (range + intensity) instead of MD
  double connect_timeout_s = 2.0;
  double silence_timeout_s = 0.5;  // a UTM-30LX-EW streams 40 scans a second
  double backoff_max_s = 5.0;
  Mounting mounting;
};

// A serial sensor link (GNSS NMEA, Xsens MTi).
struct SerialConfig {
  bool enabled = false;
  std::string device;
  unsigned baud = 115200;
  unsigned data_bits = 8;
  char parity = 'N';
  unsigned stop_bits = 1;
  double silence_timeout_s = 1.0;
  double reopen_interval_s = 1.0;
};

struct GnssConfig {
  SerialConfig serial;
};

struct AhrsConfig {
  SerialConfig serial;
  Mounting mounting;  // the AHRS's axes in the vehicle frame
};

struct Config {
  std::string source_file;  // the file it was loaded from
  LidarConfig lidar;
  Scan2dConfig scan2d;
  GnssConfig gnss;
  AhrsConfig ahrs;
  SyncConfig sync;  // frames from the sensors' streams
  GeoConfig geo;    // pose compensation
  perception::PipelineParams perception;
  output::safety::Params safety;  // the stop decision
  PipelineConfig pipeline;        // the perception worker pool
  RealtimeConfig realtime;        // the daemon's threads: scheduling, affinity, locked memory, latency budget
  CanConfig can;                  // the CAN output
  ViewConfig view;                // the MCAP recording and the live server (off by default)
};

// One problem found in a configuration file.
struct ConfigIssue {
  std::string file;
  int line = 0;                                 // 1-based; 0 when the problem is not tied to a line
  std::string key_path;                         // "perception.roi.min"
  std::string message;                          // what is wrong and what to do about it
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
