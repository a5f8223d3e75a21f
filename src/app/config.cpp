#include "fieldguard/app/config.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/yaml_reader.hpp"

namespace fieldguard::app {
namespace {

namespace fs = std::filesystem;

void read_mounting(YamlReader& r, const YAML::Node& n, const std::string& path, Mounting& m) {
  if (!r.section(n, path, {"x_m", "y_m", "z_m", "roll_deg", "pitch_deg", "yaw_deg"})) return;
  r.number(n, path, "x_m", m.x_m, -20.0, 20.0, "m");
  r.number(n, path, "y_m", m.y_m, -20.0, 20.0, "m");
  r.number(n, path, "z_m", m.z_m, -5.0, 10.0, "m");
  r.number(n, path, "roll_deg", m.roll_deg, -180.0, 180.0, "degrees");
  r.number(n, path, "pitch_deg", m.pitch_deg, -90.0, 90.0, "degrees");
  r.number(n, path, "yaw_deg", m.yaw_deg, -180.0, 180.0, "degrees");
}

std::string read_text_file(const fs::path& p, std::string& error) {
  std::error_code ec;
  if (fs::is_directory(p, ec)) {
    error = p.string() + " is a directory";
    return {};
  }
  std::ifstream in(p, std::ios::binary);
  if (!in) {
    error = "cannot read " + p.string();
    return {};
  }
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void load_calibration(YamlReader& r, const YAML::Node& lidar, const std::string& config_dir, LidarConfig& c) {
  if (c.calibration_file.empty()) return;
  const int line = YamlReader::line_of(lidar, "calibration_file");
  fs::path p(c.calibration_file);
  if (p.is_relative() && !config_dir.empty()) p = fs::path(config_dir) / p;
  std::string err;
  const std::string text = read_text_file(p, err);
  if (!err.empty()) {
    r.issues().push_back({r.file(), line, "lidar.calibration_file",
                          err + "; give a path to a ROS calibration .yaml or a VeloView .xml (relative paths are "
                                "taken from the config file's folder), or leave it empty for the built-in table"});
    return;
  }
  const auto ext = p.extension().string();
  auto parsed = (ext == ".xml") ? velodyne::parse_veloview_calibration(text) : velodyne::parse_ros_calibration(text);
  if (!parsed) {
    r.issues().push_back({r.file(), line, "lidar.calibration_file", p.string() + ": " + parsed.error()});
    return;
  }
  c.calibration = std::move(parsed).value();
  c.has_calibration = true;
  if (c.model != velodyne::Model::Unknown && c.calibration.model != c.model) {
    r.issues().push_back({r.file(), line, "lidar.calibration_file",
                          p.string() + " is a " + std::string(velodyne::to_string(c.calibration.model)) +
                              " calibration but lidar.model is " + std::string(velodyne::to_string(c.model)) +
                              "; use the file that came with this sensor"});
  }
}

void read_lidar(YamlReader& r, const YAML::Node& n, const std::string& config_dir, LidarConfig& c) {
  const std::string path = "lidar";
  if (!r.section(n, path,
                 {"model", "calibration_file", "data_port", "position_port", "timestamp_reference", "min_range_m",
                  "max_range_m", "rotation_cut_deg", "mounting"})) {
    return;
  }
  if (auto m = r.choice(n, path, "model", {"auto", "HDL-32E", "VLP-16"})) {
    c.model = *m == 0 ? velodyne::Model::Unknown : (*m == 1 ? velodyne::Model::HDL32E : velodyne::Model::VLP16);
  }
  r.text(n, path, "calibration_file", c.calibration_file);
  r.port(n, path, "data_port", c.data_port);
  r.port(n, path, "position_port", c.position_port);
  if (auto t = r.choice(n, path, "timestamp_reference", {"first_firing", "last_firing"})) {
    c.timestamp_reference = *t == 0 ? velodyne::TimestampReference::FirstFiring : velodyne::TimestampReference::LastFiring;
  }
  r.number(n, path, "min_range_m", c.min_range_m, 0.0, 300.0, "m");
  r.number(n, path, "max_range_m", c.max_range_m, 0.0, 300.0, "m");
  r.number(n, path, "rotation_cut_deg", c.rotation_cut_deg, 0.0, 359.99, "degrees");
  read_mounting(r, n["mounting"], "lidar.mounting", c.mounting);

  if (c.min_range_m >= c.max_range_m) {
    r.issue(n["max_range_m"] ? n["max_range_m"] : n, "lidar.max_range_m",
            "must be greater than lidar.min_range_m; returns between the two are kept");
  }
  if (c.data_port == c.position_port) {
    r.issue(n["position_port"] ? n["position_port"] : n, "lidar.position_port",
            "is the same as lidar.data_port; the sensor sends data and position packets to different ports "
            "(2368 and 8308 by default)");
  }
  load_calibration(r, n, config_dir, c);
}

void read_box(YamlReader& r, const YAML::Node& n, const std::string& path, perception::Box3& b) {
  if (!r.section(n, path, {"min", "max"})) return;
  r.vec3(n, path, "min", b.min, -500.0, 500.0, "m");
  r.vec3(n, path, "max", b.max, -500.0, 500.0, "m");
  for (std::size_t i = 0; i < 3; ++i) {
    if (b.min[i] >= b.max[i]) {
      static constexpr const char* kAxis[] = {"x", "y", "z"};
      r.issue(n["max"] ? n["max"] : n, path,
              std::string("min ") + kAxis[i] + " must be less than max " + kAxis[i] + "; swap them");
    }
  }
}

void read_perception(YamlReader& r, const YAML::Node& n, perception::PipelineParams& p) {
  const std::string path = "perception";
  if (!r.section(n, path, {"voxel", "roi", "body", "ground", "cluster", "filters"})) return;

  if (r.section(n["voxel"], "perception.voxel", {"leaf_m"})) {
    r.number(n["voxel"], "perception.voxel", "leaf_m", p.voxel.leaf_m, 0.01, 2.0, "m");
  }
  read_box(r, n["roi"], "perception.roi", p.roi);
  read_box(r, n["body"], "perception.body", p.body);
  if (n["roi"] && n["body"] && !p.roi.contains(p.body)) {
    r.issue(n["body"], "perception.body",
            "the tractor body box reaches outside perception.roi; shrink the body box or grow the ROI so that the "
            "body lies inside it");
  }

  const YAML::Node g = n["ground"];
  if (r.section(g, "perception.ground", {"method", "ransac"})) {
    if (auto m = r.choice(g, "perception.ground", "method", {"ransac"})) {
      p.ground.method = perception::GroundMethod::Ransac;
      (void)m;
    }
    const YAML::Node rs = g["ransac"];
    if (r.section(rs, "perception.ground.ransac", {"iterations", "distance_m", "seed"})) {
      r.integer(rs, "perception.ground.ransac", "iterations", p.ground.ransac.iterations, 1, 100000);
      r.number(rs, "perception.ground.ransac", "distance_m", p.ground.ransac.distance_m, 0.001, 5.0, "m");
      int seed = static_cast<int>(p.ground.ransac.seed);
      r.integer(rs, "perception.ground.ransac", "seed", seed, 0, 2147483647);
      p.ground.ransac.seed = static_cast<std::uint32_t>(seed);
    }
  }

  if (r.section(n["cluster"], "perception.cluster", {"tolerance_m"})) {
    r.number(n["cluster"], "perception.cluster", "tolerance_m", p.cluster.tolerance_m, 0.01, 10.0, "m");
  }

  const YAML::Node f = n["filters"];
  const std::string fp = "perception.filters";
  if (r.section(f, fp, {"min_points", "max_points", "min_volume_m3", "max_volume_m3"})) {
    r.integer(f, fp, "min_points", p.filters.min_points, 1, 10000000);
    r.integer(f, fp, "max_points", p.filters.max_points, 1, 10000000);
    r.number(f, fp, "min_volume_m3", p.filters.min_volume_m3, 0.0, 1e6, "m^3");
    r.number(f, fp, "max_volume_m3", p.filters.max_volume_m3, 0.0, 1e6, "m^3");
    if (p.filters.min_points > p.filters.max_points) {
      r.issue(f["max_points"] ? f["max_points"] : f, fp + ".max_points", "must not be less than min_points");
    }
    if (p.filters.min_volume_m3 > p.filters.max_volume_m3) {
      r.issue(f["max_volume_m3"] ? f["max_volume_m3"] : f, fp + ".max_volume_m3", "must not be less than min_volume_m3");
    }
  }
}

LoadResult load(const std::string& text, const std::string& name, const std::string& config_dir) {
  LoadResult result;
  result.config.source_file = name;
  YamlReader r(name);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    result.issues.push_back({name, e.mark.line >= 0 ? e.mark.line + 1 : 0, "",
                             "not valid YAML: " + e.msg + "; fix the syntax (indentation, quotes, colons)"});
    return result;
  }
  if (!root || root.IsNull()) {
    result.issues.push_back({name, 0, "", "the file is empty; start from config/fieldguard.yaml"});
    return result;
  }
  if (r.section(root, "", {"lidar", "perception"})) {
    read_lidar(r, root["lidar"], config_dir, result.config.lidar);
    read_perception(r, root["perception"], result.config.perception);
  }
  result.issues = std::move(r.issues());
  return result;
}

}  // namespace

LoadResult load_config_file(const std::string& path) {
  std::string err;
  const std::string text = read_text_file(path, err);
  if (!err.empty()) {
    LoadResult r;
    r.config.source_file = path;
    std::error_code ec;
    const char* why = !fs::exists(path, ec)       ? "no such file; give the path of a fieldguard YAML file (see config/fieldguard.yaml)"
                      : fs::is_directory(path, ec) ? "is a directory; give the path of a fieldguard YAML file"
                                                   : "cannot read the file; check its permissions";
    r.issues.push_back({path, 0, "", why});
    return r;
  }
  return load(text, path, fs::path(path).parent_path().string());
}

LoadResult load_config_text(const std::string& text, const std::string& name) { return load(text, name, ""); }

}  // namespace fieldguard::app
