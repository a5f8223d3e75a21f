// The ROS velodyne_pointcloud calibration YAML (velodyne_pointcloud/params/32db.yaml, VLP16db.yaml):
//   num_lasers: 32
//   distance_resolution: 0.002            (m; absent from older files, 0.002 then)
//   lasers:
//   - {laser_id: 0, rot_correction: 0.0, vert_correction: -0.5352924815866609, dist_correction: 0.0,
//      dist_correction_x: 0.0, dist_correction_y: 0.0, vert_offset_correction: 0.0,
//      horiz_offset_correction: 0.0, focal_distance: 0.0, focal_slope: 0.0, min_intensity: 0, max_intensity: 255}
// Angles in radians, distances in metres. Like the ROS driver, the first num_lasers entries are used
// (32db.yaml lists 64 with num_lasers: 32) and each is stored at its laser_id. Unlike the ROS driver,
// fields we do not use may be absent; a field that is present must be a number.

#include <yaml-cpp/yaml.h>

#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>

#include "drivers/velodyne_calibration_detail.hpp"
#include "fieldguard/drivers/velodyne_calibration.hpp"

namespace fieldguard::velodyne {
namespace {

using detail::Issues;

constexpr double kRadToDeg = 180.0 / std::numbers::pi;
constexpr double kDefaultResolutionM = 0.002;
constexpr double kMaxResolutionM = 0.01;  // Velodyne sensors use 2 mm (4 mm on some); more is a unit error

// Fields that must be there.
constexpr std::array<std::string_view, 4> kRequired = {"rot_correction", "vert_correction", "dist_correction",
                                                       "vert_offset_correction"};
// Fields that may be absent: the first three then read as 0, the rest are not used. Checked when present.
constexpr std::array<std::string_view, 7> kOptional = {
    "horiz_offset_correction", "dist_correction_x", "dist_correction_y", "focal_distance", "focal_slope",
    "min_intensity",           "max_intensity"};

[[nodiscard]] std::string line_of(const YAML::Node& node) {
  const YAML::Mark m = node.Mark();
  if (m.is_null()) return {};
  return " (line " + std::to_string(m.line + 1) + ")";
}

// A number field of one laser entry; adds an issue and returns nullopt if it is missing or not a number.
std::optional<double> number_field(const YAML::Node& entry, std::string_view key, const std::string& where,
                                   bool required, Issues& issues) {
  const YAML::Node node = entry[std::string(key)];
  if (!node.IsDefined()) {
    if (required) issues.add(where + ": " + std::string(key) + " missing" + line_of(entry));
    return std::nullopt;
  }
  if (node.IsNull()) {
    issues.add(where + ": " + std::string(key) + " is empty" + line_of(node));
    return std::nullopt;
  }
  if (!node.IsScalar()) {
    issues.add(where + ": " + std::string(key) + " is not a number but a list or map" + line_of(node));
    return std::nullopt;
  }
  auto v = detail::parse_number(node.Scalar());
  if (!v)
    issues.add(where + ": " + std::string(key) + " is not a number: " + detail::quoted(node.Scalar()) + line_of(node));
  return v;
}

// One entry of `lasers`; stores it at its laser_id in the table.
void read_laser(const YAML::Node& entry, std::size_t index, detail::LaserTable& table, Issues& issues) {
  const std::string where = "laser " + std::to_string(index);
  if (!entry.IsMap()) {
    issues.add(where + ": not a map of corrections {laser_id: ..., vert_correction: ...}" + line_of(entry));
    return;
  }
  std::optional<std::size_t> id;
  const YAML::Node id_node = entry["laser_id"];
  if (!id_node.IsDefined()) {
    issues.add(where + ": laser_id missing" + line_of(entry));
  } else if (const auto v = id_node.IsScalar() ? detail::parse_index(id_node.Scalar()) : std::nullopt; !v) {
    issues.add(where + ": laser_id is not a laser number: " +
               detail::quoted(id_node.IsScalar() ? id_node.Scalar() : "(not a scalar)") + line_of(id_node));
  } else if (static_cast<std::size_t>(*v) >= table.by_id.size()) {
    issues.add(where + ": laser_id " + std::to_string(*v) + " is out of range 0.." +
               std::to_string(table.by_id.size() - 1) + line_of(id_node));
  } else if (table.by_id[static_cast<std::size_t>(*v)]) {
    issues.add(where + ": laser_id " + std::to_string(*v) + " appears twice" + line_of(id_node));
  } else {
    id = static_cast<std::size_t>(*v);
  }

  std::array<std::optional<double>, kRequired.size()> req{};
  for (std::size_t k = 0; k < kRequired.size(); ++k) req[k] = number_field(entry, kRequired[k], where, true, issues);
  std::array<std::optional<double>, kOptional.size()> opt{};
  for (std::size_t k = 0; k < kOptional.size(); ++k) opt[k] = number_field(entry, kOptional[k], where, false, issues);

  const auto& [rot, vert, dist, vert_offset] = req;
  if (vert && std::abs(*vert) > std::numbers::pi / 2) {
    issues.add(where + ": vert_correction " + entry["vert_correction"].Scalar() +
               " is beyond +-pi/2: ROS calibration files give angles in radians, not degrees" +
               line_of(entry["vert_correction"]));
    return;
  }
  if (!id || !rot || !vert || !dist || !vert_offset) return;
  table.by_id[*id] = LaserCorrection{
      .vert_deg = *vert * kRadToDeg,
      .rot_deg = *rot * kRadToDeg,
      .dist_m = *dist,
      .vert_offset_m = *vert_offset,
      .horiz_offset_m = opt[0].value_or(0.0),
      .dist_x_m = opt[1].value_or(0.0),
      .dist_y_m = opt[2].value_or(0.0),
  };
}

Expected<Calibration, std::string> parse_ros(std::string_view yaml_text) {
  const YAML::Node root = YAML::Load(std::string(yaml_text));
  if (!root.IsMap()) {
    return Unexpected{
        std::string("not a ROS calibration YAML: the top level must be a map with num_lasers and lasers (like "
                    "velodyne_pointcloud/params/32db.yaml)")};
  }
  Issues issues;

  std::optional<Model> model;
  const YAML::Node count_node = root["num_lasers"];
  if (!count_node.IsDefined()) {
    issues.add("num_lasers missing: add num_lasers: 32 (HDL-32E) or 16 (VLP-16)");
  } else if (const auto n = count_node.IsScalar() ? detail::parse_index(count_node.Scalar()) : std::nullopt; !n) {
    issues.add("num_lasers is not a count" + line_of(count_node));
  } else if (model = detail::model_for_laser_count(static_cast<std::size_t>(*n)); !model) {
    issues.add("num_lasers " + std::to_string(*n) + ": " + detail::supported_counts() + line_of(count_node));
  }

  double resolution_m = kDefaultResolutionM;
  if (const YAML::Node res = root["distance_resolution"]; res.IsDefined()) {
    const auto v = res.IsScalar() ? detail::parse_number(res.Scalar()) : std::nullopt;
    if (!v || *v <= 0.0 || *v > kMaxResolutionM) {
      issues.add("distance_resolution " + detail::quoted(res.IsScalar() ? res.Scalar() : "") +
                 " is not a distance in metres between 0 and 0.01 (Velodyne: 0.002)" + line_of(res));
    } else {
      resolution_m = *v;
    }
  }

  const YAML::Node lasers = root["lasers"];
  if (!lasers.IsDefined()) {
    issues.add("lasers missing: the file must list the lasers as lasers: [{laser_id: 0, ...}, ...]");
  } else if (!lasers.IsSequence()) {
    issues.add("lasers is not a list" + line_of(lasers));
  }
  if (!issues.empty() || !model) return Unexpected{issues.message()};

  detail::LaserTable table(model == Model::HDL32E ? 32 : 16);
  if (lasers.size() < table.by_id.size()) {
    return Unexpected{detail::count_mismatch(*model, lasers.size()) + line_of(lasers)};
  }
  for (std::size_t i = 0; i < table.by_id.size(); ++i) read_laser(lasers[i], i, table, issues);
  Calibration cal = detail::finish(*model, resolution_m, table, issues);
  if (!issues.empty()) return Unexpected{issues.message()};
  return cal;
}

}  // namespace

Expected<Calibration, std::string> parse_ros_calibration(std::string_view yaml_text) {
  try {
    return parse_ros(yaml_text);
  } catch (const YAML::Exception& e) {
    // e.msg without yaml-cpp's own "yaml-cpp: error at line" prefix; our line numbers count from 1.
    if (e.mark.is_null()) return Unexpected{"not valid YAML: " + e.msg};
    return Unexpected{"not valid YAML: line " + std::to_string(e.mark.line + 1) + ", column " +
                      std::to_string(e.mark.column + 1) + ": " + e.msg};
  } catch (const std::exception& e) {
    return Unexpected{std::string("cannot read the ROS calibration YAML: ") + e.what()};
  }
}

}  // namespace fieldguard::velodyne
