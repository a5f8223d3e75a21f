#include "fieldguard/writers/obstacles_jsonl.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

namespace fieldguard::app {
namespace {

void num(std::string& s, double v, int decimals) {
  char buf[48];
  // -0.000 and 0.000 are the same value: print one spelling.
  const double rounded = (v > -0.5 * std::pow(10.0, -decimals) && v < 0.5 * std::pow(10.0, -decimals)) ? 0.0 : v;
  std::snprintf(buf, sizeof buf, "%.*f", decimals, rounded);
  s += buf;
}

void vec(std::string& s, const float* v, int n) {
  s += '[';
  for (int i = 0; i < n; ++i) {
    if (i) s += ',';
    num(s, static_cast<double>(v[i]), 3);
  }
  s += ']';
}

// ,"key":number with `decimals` (`key` with its leading comma and quotes, as the line spells it).
void field(std::string& s, const char* key, double v, int decimals) {
  s += key;
  num(s, v, decimals);
}

// The names of the values of `all` whose bit is set in `mask`, as JSON strings separated by commas, in `all`'s order.
template <class Values, class Bit>
void names_in(std::string& s, const Values& all, std::uint8_t mask, Bit bit_of) {
  bool first = true;
  for (const auto v : all) {
    if ((mask & bit_of(v)) == 0) continue;
    s += first ? "\"" : ",\"";
    s += to_string(v);
    s += '"';
    first = false;
  }
}

void fusion_json(std::string& s, const FusionInfo& f) {
  s += ",\"fusion\":{\"levelling\":\"";
  s += levelling_name(f.levelling);
  s += "\",\"rotations\":" + std::to_string(f.rotations) + ",\"scan_points\":" + std::to_string(f.scan_points) +
       ",\"missing\":[";
  names_in(s, sync::kAllSensors, f.missing, [](sync::SensorKind k) { return sync::bit(k); });
  s += "],\"timed_out\":";
  s += f.timed_out ? "true" : "false";
  s += ",\"dropped_points\":" + std::to_string(f.stats.lidar.dropped() + f.stats.scan.dropped());
  if (f.attitude) {
    s += ",\"pose\":{";
    if (f.reference) {
      s += "\"easting\":";
      num(s, f.reference->easting_m, 3);
      s += ",\"northing\":";
      num(s, f.reference->northing_m, 3);
      s += ",\"up\":";
      num(s, f.reference->up_m, 3);
      s += ",\"zone\":" + std::to_string(f.reference->zone) + ",";
    }
    s += "\"roll\":";
    num(s, f.attitude->roll_deg, 3);
    s += ",\"pitch\":";
    num(s, f.attitude->pitch_deg, 3);
    s += ",\"yaw\":";
    num(s, f.attitude->yaw_deg, 3);
    s += '}';
  }
  s += '}';
}

// Our texts have no character JSON must escape (the headline is built from fixed words, sensor names and numbers).
void decision_json(std::string& s, const output::safety::Decision& d, int clear_frames) {
  namespace safety = output::safety;
  s += ",\"decision\":{\"stop\":";
  s += d.stop ? "true" : "false";
  s += ",\"reason\":\"";
  s += safety::to_string(d.reason);
  s += "\",\"reasons\":[";
  names_in(s, safety::kReasonPriority, d.reasons, [](safety::Reason r) { return safety::bit(r); });
  s += "],\"headline\":\"";
  s += safety::headline(d, clear_frames);
  s += "\"}";
}

// The detection frame's pose on the plane (detection_pose): p_plane = origin + Rz(yaw) p_detect.
void plane_json(std::string& s, const perception::Obstacle& o, const perception::FramePose& pose) {
  const double x = 0.5 * (static_cast<double>(o.min[0]) + static_cast<double>(o.max[0]));
  const double y = 0.5 * (static_cast<double>(o.min[1]) + static_cast<double>(o.max[1]));
  const double c = std::cos(pose.yaw_rad);
  const double sn = std::sin(pose.yaw_rad);
  s += ",\"plane\":[";
  num(s, pose.x_m + c * x - sn * y, 3);
  s += ',';
  num(s, pose.y_m + sn * x + c * y, 3);
  s += ',';
  num(s, pose.z_m + static_cast<double>(o.min[2]), 3);
  s += ']';
}

}  // namespace

const char* levelling_name(geo::Levelling l) {
  switch (l) {
    case geo::Levelling::Full: return "full";
    case geo::Levelling::AttitudeOnly: return "attitude_only";
    case geo::Levelling::None: return "none";
  }
  return "?";
}

std::string obstacles_json_line(const LidarFrame& frame, const perception::FrameResult& result,
                                const FusionInfo* fusion, const Mounting* lidar,
                                const output::safety::Decision* decision, int clear_frames) {
  std::string s = "{\"version\":" + std::to_string(kObstaclesJsonVersion) +
                  ",\"frame\":" + std::to_string(frame.index) + ",\"stamp\":";
  num(s, frame.host_stamp.seconds(), 6);
  s += ",\"partial\":";
  s += frame.partial ? "true" : "false";
  s += ",\"points_in\":" + std::to_string(frame.points.size());
  if (decision != nullptr) decision_json(s, *decision, clear_frames);
  if (fusion != nullptr) fusion_json(s, *fusion);
  const std::optional<perception::FramePose> pose =
      fusion != nullptr && lidar != nullptr ? detection_pose(*fusion, *lidar) : std::nullopt;
  s += ",\"obstacles\":[";
  bool first = true;
  for (const auto& o : result.obstacles) {
    if (!first) s += ',';
    first = false;
    s += "{\"min\":";
    vec(s, o.min.data(), 3);
    s += ",\"max\":";
    vec(s, o.max.data(), 3);
    s += ",\"points\":" + std::to_string(o.points) + ",\"obb\":{\"center\":";
    vec(s, o.obb_center.data(), 2);
    field(s, ",\"length\":", static_cast<double>(o.obb_length_m), 3);
    field(s, ",\"width\":", static_cast<double>(o.obb_width_m), 3);
    field(s, ",\"yaw_deg\":", static_cast<double>(o.obb_yaw_rad) * (180.0 / std::numbers::pi), 2);
    field(s, "},\"distance\":", static_cast<double>(o.distance_m), 3);
    field(s, ",\"bearing\":", static_cast<double>(o.bearing_deg), 2);
    field(s, ",\"height\":", static_cast<double>(o.height_above_ground_m), 3);
    s += ",\"class\":\"";
    s += perception::to_string(o.size_class);
    s += '"';
    // Only frames that carry a 2D scan can have it: a 3D LiDAR's output keeps its old bytes.
    if ((o.sources & perception::kSeenBy2d) != 0)
      s += (o.sources & perception::kSeenBy3d) != 0 ? ",\"seen_by\":\"3d+2d\"" : ",\"seen_by\":\"2d\"";
    // Only where the hold reported it (obstacle_hold.hpp): the filters' obstacles keep their bytes.
    if (o.held) s += ",\"held\":true";
    if (pose) plane_json(s, o, *pose);
    s += '}';
  }
  s += "]}";
  return s;
}

}  // namespace fieldguard::app
