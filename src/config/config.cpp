#include "fieldguard/config/config.hpp"

#include <yaml-cpp/yaml.h>

#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <type_traits>
#include <utility>
#include <vector>

#include "config/config_safety.hpp"
#include "config/config_sensors.hpp"
#include "config/section_readers.hpp"
#include "config/yaml_reader.hpp"

namespace fieldguard::app {
namespace {

namespace fs = std::filesystem;

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

// The Velodyne calibration file (ROS .yaml, VeloView .xml) or the RS-32's angle.csv.
void load_calibration(YamlReader& r, const YAML::Node& lidar, const std::string& config_dir, LidarConfig& c) {
  if (c.calibration_file.empty()) return;
  const int line = YamlReader::line_of(lidar, "calibration_file");
  fs::path p(c.calibration_file);
  if (p.is_relative() && !config_dir.empty()) p = fs::path(config_dir) / p;
  std::string err;
  const std::string text = read_text_file(p, err);
  if (!err.empty()) {
    r.issues().push_back({r.file(), line, "lidar.calibration_file",
                          err + "; give a path to a ROS calibration .yaml or a VeloView .xml (Velodyne) or the "
                                "unit's angle.csv (RS-32; relative paths are taken from the config file's folder), "
                                "or leave it empty for the built-in table"});
    return;
  }
  const auto ext = p.extension().string();
  if (ext == ".csv") {
    auto rs = robosense::parse_angle_csv(text);
    if (!rs) {
      r.issues().push_back({r.file(), line, "lidar.calibration_file", p.string() + ": " + rs.error()});
    } else if (c.model != lidar3d::Model::RS32) {
      r.issues().push_back({r.file(), line, "lidar.calibration_file",
                            p.string() + " is an RS-32 angle table; it needs lidar.model: RS-32 (auto cannot know "
                                         "the table fits the sensor it finds)"});
    } else {
      c.rs32_calibration = std::move(rs).value();
    }
    return;
  }
  auto parsed = (ext == ".xml") ? velodyne::parse_veloview_calibration(text) : velodyne::parse_ros_calibration(text);
  if (!parsed) {
    r.issues().push_back({r.file(), line, "lidar.calibration_file", p.string() + ": " + parsed.error()});
    return;
  }
  c.calibration = std::move(parsed).value();
  c.has_calibration = true;
  const auto file_model =
      c.calibration.model == velodyne::Model::VLP16 ? lidar3d::Model::VLP16 : lidar3d::Model::HDL32E;
  if (c.model != lidar3d::Model::Auto && file_model != c.model) {
    r.issues().push_back({r.file(), line, "lidar.calibration_file",
                          p.string() + " is a " + std::string(velodyne::to_string(c.calibration.model)) +
                              " calibration but lidar.model is " + std::string(lidar3d::to_string(c.model)) +
                              "; use the file that came with this sensor"});
  }
}

void read_lidar(YamlReader& r, const YAML::Node& n, const std::string& config_dir, LidarConfig& c) {
  const std::string path = "lidar";
  if (!r.section(n, path,
                 {"model", "calibration_file", "data_port", "position_port", "msop_port", "difop_port",
                  "timestamp_reference", "min_range_m", "max_range_m", "rotation_cut_deg", "mounting"})) {
    return;
  }
  if (auto m = r.choice(n, path, "model", {"auto", "HDL-32E", "VLP-16", "RS-32"})) {
    static constexpr std::array<lidar3d::Model, 4> kModels = {lidar3d::Model::Auto, lidar3d::Model::HDL32E,
                                                              lidar3d::Model::VLP16, lidar3d::Model::RS32};
    c.model = kModels.at(static_cast<std::size_t>(*m));
  }
  r.text(n, path, "calibration_file", c.calibration_file);
  r.port(n, path, "data_port", c.data_port);
  r.port(n, path, "position_port", c.position_port);
  r.port(n, path, "msop_port", c.msop_port);
  r.port(n, path, "difop_port", c.difop_port);
  if (auto t = r.choice(n, path, "timestamp_reference", {"first_firing", "last_firing"})) {
    c.timestamp_reference =
        *t == 0 ? velodyne::TimestampReference::FirstFiring : velodyne::TimestampReference::LastFiring;
  }
  r.number(n, path, "min_range_m", c.min_range_m, 0.0, 300.0, "m");
  r.number(n, path, "max_range_m", c.max_range_m, 0.0, 300.0, "m");
  r.number(n, path, "rotation_cut_deg", c.rotation_cut_deg, 0.0, 359.99, "degrees");
  read_mounting(r, n["mounting"], "lidar.mounting", c.mounting);

  if (c.min_range_m >= c.max_range_m) {
    r.issue(n["max_range_m"] ? n["max_range_m"] : n, "lidar.max_range_m",
            "must be greater than lidar.min_range_m; returns between the two are kept");
  }
  // Every port its own (0 = the kernel chooses one, live): the sensors send each kind to its own port.
  const std::array<std::pair<const char*, std::uint16_t>, 4> ports = {{{"data_port", c.data_port},
                                                                       {"position_port", c.position_port},
                                                                       {"msop_port", c.msop_port},
                                                                       {"difop_port", c.difop_port}}};
  for (std::size_t i = 1; i < ports.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (ports[i].second == 0 || ports[i].second != ports[j].second) continue;
      r.issue(n[ports[i].first] ? n[ports[i].first] : n, std::string("lidar.") + ports[i].first,
              std::string("is the same as lidar.") + ports[j].first +
                  "; each kind of datagram has its own port (Velodyne data 2368, position 8308; RS-32 MSOP 6699, "
                  "DIFOP 7788 by default)");
    }
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

// Lists of numbers, each item checked like YamlReader::number / integer. `out` is left alone unless every
// item is good; each bad item is its own issue, with its line and path ("...edges_m[2]").
template <class T>
bool list_of(YamlReader& r, const YAML::Node& map, const std::string& path, const char* key, std::vector<T>& out, T lo,
             T hi, const char* what, std::size_t min_items, std::size_t max_items) {
  if (!map.IsMap() || !map[key]) return true;
  const std::string p = join_path(path, key);
  const YAML::Node v = map[key];
  if (!v.IsSequence() || v.size() < min_items || v.size() > max_items) {
    r.issue(v, p,
            "expected a list of " + std::to_string(min_items) + " to " + std::to_string(max_items) + " " + what +
                (v.IsSequence() ? ", got " + std::to_string(v.size()) : ""));
    return false;
  }
  std::vector<T> items;
  bool good = true;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string ip = p + "[" + std::to_string(i) + "]";
    const std::string text = v[i].IsScalar() ? v[i].Scalar() : std::string();
    T value{};
    const char* end = text.data() + text.size();
    const auto [ptr, ec] = std::from_chars(text.data(), end, value);
    if (!v[i].IsScalar() || ec != std::errc() || ptr != end || !std::isfinite(static_cast<double>(value))) {
      r.issue(
          v[i], ip,
          std::string("expected ") + (std::is_integral_v<T> ? "a whole number" : "a number") + ", got '" + text + "'");
      good = false;
    } else if (value < lo || value > hi) {
      std::ostringstream m;
      m << value << " is out of range; use a value from " << lo << " to " << hi;
      r.issue(v[i], ip, m.str());
      good = false;
    }
    items.push_back(value);
  }
  if (good) out = std::move(items);
  return good;
}

YAML::Node value_or(const YAML::Node& map, const char* key) { return map[key] ? map[key] : map; }

void read_voxel(YamlReader& r, const YAML::Node& v, perception::VoxelParams& p) {
  const std::string path = "perception.voxel";
  if (!r.section(v, path, {"leaf_m", "coarse_from_m", "max_leaf_m"})) return;
  r.number(v, path, "leaf_m", p.leaf_m, 0.01, 2.0, "m");
  r.number(v, path, "coarse_from_m", p.coarse_from_m, 0.0, 500.0, "m");
  r.number(v, path, "max_leaf_m", p.max_leaf_m, 0.01, 5.0, "m");
  if (p.coarse_from_m > 0.0) {
    if (p.max_leaf_m < p.leaf_m) {
      r.issue(v["max_leaf_m"] ? v["max_leaf_m"] : v, path + ".max_leaf_m",
              "must not be less than leaf_m when coarse_from_m is set; the leaf only grows with range");
    } else if (p.max_leaf_m > 15.0 * p.leaf_m) {
      r.issue(v["max_leaf_m"] ? v["max_leaf_m"] : v, path + ".max_leaf_m",
              "must be at most 15 times leaf_m (the leaf grows in at most 15 whole-multiple bands)");
    }
  }
}

void read_zones(YamlReader& r, const YAML::Node& z, perception::ZoneParams& p) {
  const std::string path = "perception.ground.zones";
  if (!r.section(z, path,
                 {"edges_m", "rings", "sectors", "min_bin_points", "seed_lowest", "seed_margin_m", "fit_distance_m",
                  "fit_iterations", "ground_threshold_m", "max_slope_deg", "max_tilt_deg", "max_step_m",
                  "max_slope_change_deg", "min_spread_m", "max_extrapolation_m", "blend_radial", "max_below_m"})) {
    return;
  }
  // The lists are checked against each other only when each was read (a bad list has its own issue).
  const bool edges_ok = list_of(r, z, path, "edges_m", p.edges_m, 0.0, 500.0, "numbers (m)", 2, 17);
  const bool rings_ok = list_of(r, z, path, "rings", p.rings, 1, 64, "whole numbers", 1, 16);
  const bool sectors_ok = list_of(r, z, path, "sectors", p.sectors, 1, 720, "whole numbers", 1, 16);
  r.integer(z, path, "min_bin_points", p.min_bin_points, 3, 100000);
  r.integer(z, path, "seed_lowest", p.seed_lowest, 1, 100000);
  r.number(z, path, "seed_margin_m", p.seed_margin_m, 0.0, 5.0, "m");
  r.number(z, path, "fit_distance_m", p.fit_distance_m, 0.01, 5.0, "m");
  r.integer(z, path, "fit_iterations", p.fit_iterations, 0, 100);
  r.number(z, path, "ground_threshold_m", p.ground_threshold_m, 0.01, 5.0, "m");
  r.number(z, path, "max_slope_deg", p.max_slope_deg, 0.0, 80.0, "degrees");
  r.number(z, path, "max_tilt_deg", p.max_tilt_deg, 0.0, 45.0, "degrees");
  r.number(z, path, "max_step_m", p.max_step_m, 0.0, 10.0, "m");
  r.number(z, path, "max_slope_change_deg", p.max_slope_change_deg, 0.0, 80.0, "degrees");
  r.number(z, path, "min_spread_m", p.min_spread_m, 0.0, 100.0, "m");
  r.number(z, path, "max_extrapolation_m", p.max_extrapolation_m, 0.0, 500.0, "m");
  if (auto e = r.choice(z, path, "blend_radial", {"false", "true"})) p.blend_radial = *e == 1;
  r.number(z, path, "max_below_m", p.max_below_m, 0.0, 10.0, "m");
  for (std::size_t i = 1; i < p.edges_m.size(); ++i) {
    if (!(p.edges_m[i] > p.edges_m[i - 1])) {
      r.issue(value_or(z, "edges_m"), path + ".edges_m", "zone edges must increase from the sensor outwards");
      break;
    }
  }
  if (!edges_ok) return;
  const std::size_t zones = p.edges_m.size() - 1;
  if (rings_ok && p.rings.size() != zones) {
    r.issue(value_or(z, "rings"), path + ".rings",
            "needs one ring count per zone: " + std::to_string(zones) + " (one fewer than edges_m)");
  }
  if (sectors_ok && p.sectors.size() != zones) {
    r.issue(value_or(z, "sectors"), path + ".sectors",
            "needs one sector count per zone: " + std::to_string(zones) + " (one fewer than edges_m)");
  }
}

void read_ground(YamlReader& r, const YAML::Node& g, perception::GroundParams& p) {
  const std::string path = "perception.ground";
  if (!r.section(g, path, {"method", "context_m", "ransac", "zones"})) return;
  if (auto m = r.choice(g, path, "method", {"ransac", "zones"})) {
    p.method = *m == 0 ? perception::GroundMethod::Ransac : perception::GroundMethod::Zones;
  }
  r.number(g, path, "context_m", p.context_m, 0.0, 100.0, "m");
  const YAML::Node rs = g["ransac"];
  const std::string rp = path + ".ransac";
  if (r.section(rs, rp, {"iterations", "distance_m", "seed"})) {
    r.integer(rs, rp, "iterations", p.ransac.iterations, 1, 100000);
    r.number(rs, rp, "distance_m", p.ransac.distance_m, 0.001, 5.0, "m");
    int seed = static_cast<int>(p.ransac.seed);
    r.integer(rs, rp, "seed", seed, 0, 2147483647);
    p.ransac.seed = static_cast<std::uint32_t>(seed);
  }
  read_zones(r, g["zones"], p.zones);
}

void read_cluster(YamlReader& r, const YAML::Node& c, perception::ClusterParams& p) {
  const std::string path = "perception.cluster";
  if (!r.section(c, path,
                 {"method",
                  "structure",
                  "tolerance_m",
                  "beam_spacing_deg",
                  "beam_factor",
                  "max_tolerance_m",
                  "horizontal_beam_factor",
                  "horizontal_max_tolerance_m",
                  "absorb_max_points",
                  "absorb_margin_m",
                  "join_float_height_m",
                  "join_fragment_factor",
                  "join_fragment_gap_m",
                  "join_gap_m",
                  "join_stacked",
                  "join_stack_margin_m",
                  "split_min_length_m",
                  "split_min_part_m",
                  "split_gap_ratio",
                  "split_min_part_points",
                  "split_full_range_m"})) {
    return;
  }
  if (auto m = r.choice(c, path, "method", {"fixed", "adaptive", "anisotropic"})) {
    p.method = *m == 0   ? perception::ClusterMethod::Fixed
               : *m == 1 ? perception::ClusterMethod::Adaptive
                         : perception::ClusterMethod::Anisotropic;
  }
  if (auto s = r.choice(c, path, "structure", {"kdtree", "grid"})) {
    p.structure = *s == 0 ? perception::ClusterStructure::KdTree : perception::ClusterStructure::Grid;
  }
  r.number(c, path, "tolerance_m", p.tolerance_m, 0.01, 10.0, "m");
  // auto (0): each sensor's own rings, from its decoder's table; a number: that spacing whatever the sensor.
  if (c.IsMap() && c["beam_spacing_deg"] && c["beam_spacing_deg"].IsScalar() &&
      c["beam_spacing_deg"].Scalar() == "auto") {
    p.beam_spacing_deg = 0.0;
  } else {
    r.number(c, path, "beam_spacing_deg", p.beam_spacing_deg, 0.01, 10.0, "degrees (or auto)");
  }
  r.number(c, path, "beam_factor", p.beam_factor, 0.0, 10.0, "");
  r.number(c, path, "max_tolerance_m", p.max_tolerance_m, 0.01, 10.0, "m");
  r.number(c, path, "horizontal_beam_factor", p.horizontal_beam_factor, 0.0, 10.0, "");
  r.number(c, path, "horizontal_max_tolerance_m", p.horizontal_max_tolerance_m, 0.01, 10.0, "m");
  r.integer(c, path, "absorb_max_points", p.absorb_max_points, 0, 1000000);
  r.number(c, path, "absorb_margin_m", p.absorb_margin_m, 0.0, 10.0, "m");
  r.number(c, path, "join_float_height_m", p.join_float_height_m, 0.0, 10.0, "m");
  r.number(c, path, "join_fragment_factor", p.join_fragment_factor, 1.0, 10.0, "");
  r.number(c, path, "join_fragment_gap_m", p.join_fragment_gap_m, 0.0, 10.0, "m");
  r.number(c, path, "join_gap_m", p.join_gap_m, 0.0, 10.0, "m");
  if (auto j = r.choice(c, path, "join_stacked", {"false", "true"})) p.join_stacked = *j == 1;
  r.number(c, path, "join_stack_margin_m", p.join_stack_margin_m, 0.0, 10.0, "m");
  r.number(c, path, "split_min_length_m", p.split_min_length_m, 0.0, 100.0, "m");
  r.number(c, path, "split_min_part_m", p.split_min_part_m, 0.0, 100.0, "m");
  r.number(c, path, "split_gap_ratio", p.split_gap_ratio, 0.05, 10.0, "");
  r.integer(c, path, "split_min_part_points", p.split_min_part_points, 0, 1000000);
  r.number(c, path, "split_full_range_m", p.split_full_range_m, 0.1, 500.0, "m");
  // A radius that grows with range: from tolerance_m up to its cap, by factor * tan(beam_spacing) per metre.
  const auto check_growth = [&](const char* cap_key, double cap, const char* factor_key, double factor,
                                const char* which) {
    if (cap < p.tolerance_m) {
      r.issue(
          value_or(c, cap_key), path + "." + cap_key,
          std::string("must not be less than tolerance_m; the ") + which + " radius grows from tolerance_m up to it");
    }
    if (factor * std::tan(p.beam_spacing_deg * std::numbers::pi / 180.0) >= 0.5) {
      r.issue(value_or(c, factor_key), path + "." + factor_key,
              std::string(factor_key) +
                  " * tan(beam_spacing_deg) must be below 0.5 (the radius would grow half a "
                  "metre per metre of range); lower " +
                  factor_key);
    }
  };
  if (p.method == perception::ClusterMethod::Anisotropic) {
    check_growth("horizontal_max_tolerance_m", p.horizontal_max_tolerance_m, "horizontal_beam_factor",
                 p.horizontal_beam_factor, "horizontal");
  }
  if (p.method != perception::ClusterMethod::Fixed) {
    check_growth("max_tolerance_m", p.max_tolerance_m, "beam_factor", p.beam_factor, "adaptive");
  }
}

void read_filters(YamlReader& r, const YAML::Node& f, perception::FilterParams& p) {
  const std::string fp = "perception.filters";
  if (!r.section(f, fp,
                 {"min_points", "max_points", "min_volume_m3", "max_volume_m3", "min_height_m",
                  "min_points_full_range_m", "min_points_floor", "canopy_max_height_m", "canopy_min_jitter_m",
                  "canopy_min_triples", "canopy_max_gap_m", "canopy_needle_depth_m", "canopy_needle_ratio",
                  "float_min_height_m", "float_min_points", "canopy_surroundings_m", "min_height_growth_from_m",
                  "min_height_growth_per_m", "min_height_growth_max_m"})) {
    return;
  }
  r.integer(f, fp, "min_points", p.min_points, 1, 10000000);
  r.integer(f, fp, "max_points", p.max_points, 0, 10000000);
  r.number(f, fp, "min_volume_m3", p.min_volume_m3, 0.0, 1e6, "m^3");
  r.number(f, fp, "max_volume_m3", p.max_volume_m3, 0.0, 1e6, "m^3");
  r.number(f, fp, "min_height_m", p.min_height_m, 0.0, 10.0, "m");
  r.number(f, fp, "min_height_growth_from_m", p.min_height_growth_from_m, 0.0, 500.0, "m");
  r.number(f, fp, "min_height_growth_per_m", p.min_height_growth_per_m, 0.0, 1.0, "m/m");
  r.number(f, fp, "min_height_growth_max_m", p.min_height_growth_max_m, 0.0, 10.0, "m");
  r.number(f, fp, "min_points_full_range_m", p.min_points_full_range_m, 0.0, 500.0, "m");
  r.integer(f, fp, "min_points_floor", p.min_points_floor, 1, 10000000);
  r.number(f, fp, "canopy_max_height_m", p.canopy_max_height_m, 0.0, 3.0, "m");
  r.number(f, fp, "canopy_min_jitter_m", p.canopy_min_jitter_m, 0.01, 2.0, "m");
  r.integer(f, fp, "canopy_min_triples", p.canopy_min_triples, 1, 100000);
  r.number(f, fp, "canopy_max_gap_m", p.canopy_max_gap_m, 0.05, 5.0, "m");
  r.number(f, fp, "canopy_needle_depth_m", p.canopy_needle_depth_m, 0.0, 10.0, "m");
  r.number(f, fp, "canopy_needle_ratio", p.canopy_needle_ratio, 1.0, 100.0, "");
  r.number(f, fp, "canopy_surroundings_m", p.canopy_surroundings_m, 0.0, 10.0, "m");
  r.number(f, fp, "float_min_height_m", p.float_min_height_m, 0.0, 10.0, "m");
  r.integer(f, fp, "float_min_points", p.float_min_points, 1, 10000000);
  if (p.max_points > 0 && p.min_points > p.max_points) {
    r.issue(value_or(f, "max_points"), fp + ".max_points", "must not be less than min_points (0 = no upper limit)");
  }
  if (p.max_volume_m3 > 0.0 && p.min_volume_m3 > p.max_volume_m3) {
    r.issue(value_or(f, "max_volume_m3"), fp + ".max_volume_m3",
            "must not be less than min_volume_m3 (0 = no upper limit)");
  }
  // A cap below min_height_m would lower the threshold far out instead of raising it.
  if (p.min_height_growth_max_m > 0.0 && p.min_height_growth_max_m < p.min_height_m) {
    r.issue(value_or(f, "min_height_growth_max_m"), fp + ".min_height_growth_max_m",
            "must not be less than min_height_m (0 = no cap)");
  }
}

void read_near_field(YamlReader& r, const YAML::Node& n, perception::NearFieldParams& p) {
  const std::string path = "perception.near_field";
  if (!r.section(n, path, {"enabled", "zone", "max_gap_m", "min_points", "min_height_m"})) return;
  if (auto e = r.choice(n, path, "enabled", {"false", "true"})) p.enabled = *e == 1;
  read_box(r, n["zone"], path + ".zone", p.zone);
  r.number(n, path, "max_gap_m", p.max_gap_m, 0.01, 5.0, "m");
  r.integer(n, path, "min_points", p.min_points, 1, 1081);  // a scan has 1081 steps
  r.number(n, path, "min_height_m", p.min_height_m, 0.0, 2.0, "m");
}

void read_hold(YamlReader& r, const YAML::Node& n, perception::HoldParams& p) {
  const std::string path = "perception.hold";
  if (!r.section(n, path, {"enabled", "max_age_s", "gate_m", "min_points"})) return;
  if (auto e = r.choice(n, path, "enabled", {"false", "true"})) p.enabled = *e == 1;
  r.number(n, path, "max_age_s", p.max_age_s, 0.0, 2.0, "s");
  r.number(n, path, "gate_m", p.gate_m, 0.0, 3.0, "m");
  r.integer(n, path, "min_points", p.min_points, 1, 1000);
}

void read_perception(YamlReader& r, const YAML::Node& n, perception::PipelineParams& p) {
  const std::string path = "perception";
  if (!r.section(n, path, {"voxel", "roi", "body", "ground", "cluster", "filters", "near_field", "hold"})) return;

  read_voxel(r, n["voxel"], p.voxel);
  read_box(r, n["roi"], "perception.roi", p.roi);
  read_box(r, n["body"], "perception.body", p.body);
  if (n["roi"] && n["body"] && !p.roi.contains(p.body)) {
    r.issue(n["body"], "perception.body",
            "the tractor body box reaches outside perception.roi; shrink the body box or grow the ROI so that the "
            "body lies inside it");
  }
  read_ground(r, n["ground"], p.ground);
  read_cluster(r, n["cluster"], p.cluster);
  read_filters(r, n["filters"], p.filters);
  read_near_field(r, n["near_field"], p.near_field);
  read_hold(r, n["hold"], p.hold);
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
  if (r.section(root, "",
                {"lidar", "scan2d", "gnss", "ahrs", "sync", "geo", "perception", "safety", "pipeline", "realtime",
                 "can", "view"})) {
    read_lidar(r, root["lidar"], config_dir, result.config.lidar);
    read_scan2d(r, root["scan2d"], result.config.scan2d);
    read_gnss(r, root["gnss"], result.config.gnss);
    read_ahrs(r, root["ahrs"], result.config.ahrs);
    read_sync(r, root["sync"], result.config.sync);
    read_geo(r, root["geo"], result.config.geo);
    read_perception(r, root["perception"], result.config.perception);
    read_safety(r, root["safety"], result.config);
    read_pipeline(r, root["pipeline"], result.config.pipeline);
    read_realtime(r, root["realtime"], result.config.realtime);
    read_can(r, root["can"], config_dir, result.config.can);
    read_view(r, root["view"], config_dir, result.config.view);
    // The zone ground starts from the ground below the sensor: the LiDAR's mounting height when the file
    // gives one (otherwise ZoneParams' default, 0.95 m).
    auto& cfg = result.config;
    const YAML::Node lidar = root["lidar"];
    const YAML::Node mount = lidar && lidar.IsMap() ? lidar["mounting"] : YAML::Node();
    if (mount && mount.IsMap() && mount["z_m"]) {
      if (cfg.lidar.mounting.z_m > 0.0) {
        cfg.perception.ground.zones.sensor_height_m = cfg.lidar.mounting.z_m;
      } else if (cfg.perception.ground.method == perception::GroundMethod::Zones) {
        r.issue(mount["z_m"], "lidar.mounting.z_m",
                "perception.ground.method zones needs the LiDAR's height above the ground; give a positive z_m");
      }
    }
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
    const char* why = !fs::exists(path, ec)
                          ? "no such file; give the path of a fieldguard YAML file (see config/fieldguard.yaml)"
                      : fs::is_directory(path, ec) ? "is a directory; give the path of a fieldguard YAML file"
                                                   : "cannot read the file; check its permissions";
    r.issues.push_back({path, 0, "", why});
    return r;
  }
  return load(text, path, fs::path(path).parent_path().string());
}

LoadResult load_config_text(const std::string& text, const std::string& name) { return load(text, name, ""); }

}  // namespace fieldguard::app
