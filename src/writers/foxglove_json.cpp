#include "fieldguard/writers/foxglove_json.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <tuple>

namespace fieldguard::app::foxglove {
namespace {

// --- The schemas: JSON Schema (draft 2020-12) of exactly the fields written below ---------------------------

std::string object(std::string_view properties, std::string_view required) {
  return std::string(R"({"type":"object","properties":{)") + std::string(properties) + R"(},"required":[)" +
         std::string(required) + "]}";
}
const std::string kNumber = R"({"type":"number"})";
const std::string kString = R"({"type":"string"})";
const std::string kBool = R"({"type":"boolean"})";
const std::string kTime =
    object(R"("sec":{"type":"integer","minimum":0},"nsec":{"type":"integer","minimum":0,"maximum":999999999})",
           R"("sec","nsec")");
const std::string kVector3 =
    object(R"("x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"})", R"("x","y","z")");
const std::string kQuaternion = object(
    R"("x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"})", R"("x","y","z","w")");
const std::string kPose =
    object(R"("position":)" + kVector3 + R"(,"orientation":)" + kQuaternion, R"("position","orientation")");
const std::string kColor = object(
    R"("r":{"type":"number"},"g":{"type":"number"},"b":{"type":"number"},"a":{"type":"number"})", R"("r","g","b","a")");
std::string array_of(const std::string& item) { return R"({"type":"array","items":)" + item + "}"; }

std::string with_title(std::string_view title, std::string_view schema_json) {
  // {"$schema":...,"title":...,<the object's members>}
  return std::string(R"({"$schema":"https://json-schema.org/draft/2020-12/schema","title":")") + std::string(title) +
         "\"," + std::string(schema_json.substr(1));
}

std::string point_cloud_schema() {
  const std::string field = object(
      R"("name":{"type":"string"},"offset":{"type":"integer","minimum":0},"type":{"type":"integer","minimum":0,"maximum":8})",
      R"("name","offset","type")");
  return with_title("foxglove.PointCloud",
                    object(R"("timestamp":)" + kTime + R"(,"frame_id":)" + kString + R"(,"pose":)" + kPose +
                               R"(,"point_stride":{"type":"integer","minimum":0},"fields":)" + array_of(field) +
                               R"(,"data":{"type":"string","contentEncoding":"base64"})",
                           R"("timestamp","frame_id","pose","point_stride","fields","data")"));
}

std::string scene_update_schema() {
  const std::string cube =
      object(R"("pose":)" + kPose + R"(,"size":)" + kVector3 + R"(,"color":)" + kColor, R"("pose","size","color")");
  const std::string text =
      object(R"("pose":)" + kPose + R"(,"billboard":)" + kBool + R"(,"font_size":)" + kNumber +
                 R"(,"scale_invariant":)" + kBool + R"(,"color":)" + kColor + R"(,"text":)" + kString,
             R"("pose","billboard","font_size","scale_invariant","color","text")");
  const std::string line =
      object(R"("type":{"type":"integer","minimum":0,"maximum":2},"pose":)" + kPose + R"(,"thickness":)" + kNumber +
                 R"(,"scale_invariant":)" + kBool + R"(,"points":)" + array_of(kVector3) + R"(,"color":)" + kColor +
                 R"(,"colors":)" + array_of(kColor) + R"(,"indices":{"type":"array","items":{"type":"integer"}})",
             R"("type","pose","thickness","scale_invariant","points","color","colors","indices")");
  const std::string none = R"({"type":"array","maxItems":0})";  // primitives fieldguard never draws
  const std::string metadata =
      array_of(object(R"("key":{"type":"string"},"value":{"type":"string"})", R"("key","value")"));
  const std::string entity = object(
      R"("timestamp":)" + kTime + R"(,"frame_id":)" + kString + R"(,"id":)" + kString + R"(,"lifetime":)" + kTime +
          R"(,"frame_locked":)" + kBool + R"(,"metadata":)" + metadata + R"(,"arrows":)" + none + R"(,"cubes":)" +
          array_of(cube) + R"(,"spheres":)" + none + R"(,"cylinders":)" + none + R"(,"lines":)" + array_of(line) +
          R"(,"triangles":)" + none + R"(,"texts":)" + array_of(text) + R"(,"models":)" + none,
      R"("timestamp","frame_id","id","lifetime","frame_locked","metadata","arrows","cubes","spheres","cylinders","lines","triangles","texts","models")");
  return with_title("foxglove.SceneUpdate",
                    object(R"("deletions":{"type":"array","maxItems":0},"entities":)" + array_of(entity),
                           R"("deletions","entities")"));
}

std::string frame_transform_schema() {
  return with_title("foxglove.FrameTransform",
                    object(R"("timestamp":)" + kTime + R"(,"parent_frame_id":)" + kString + R"(,"child_frame_id":)" +
                               kString + R"(,"translation":)" + kVector3 + R"(,"rotation":)" + kQuaternion,
                           R"("timestamp","parent_frame_id","child_frame_id","translation","rotation")"));
}

std::string location_fix_schema() {
  return with_title(
      "foxglove.LocationFix",
      object(
          R"("timestamp":)" + kTime + R"(,"frame_id":)" + kString +
              R"(,"latitude":{"type":"number","minimum":-90,"maximum":90},"longitude":{"type":"number","minimum":-180,"maximum":180},"altitude":)" +
              kNumber +
              R"(,"position_covariance":{"type":"array","items":{"type":"number"},"minItems":9,"maxItems":9},"position_covariance_type":{"type":"integer","minimum":0,"maximum":3})",
          R"("timestamp","frame_id","latitude","longitude","altitude","position_covariance","position_covariance_type")"));
}

std::string decision_schema() {
  std::string reasons = R"({"enum":[)";
  bool first = true;
  for (const auto r : output::safety::kReasonPriority) {
    reasons += first ? "\"" : ",\"";
    reasons += output::safety::to_string(r);
    reasons += '"';
    first = false;
  }
  reasons += R"(,"none"]})";
  const std::string zone = object(
      R"("x_min":{"type":"number"},"x_max":{"type":"number"},"half_width":{"type":"number"},"speed_known":)" + kBool,
      R"("x_min","x_max","half_width","speed_known")");
  return with_title(
      "fieldguard.Decision",
      object(
          R"("timestamp":)" + kTime + R"(,"frame":{"type":"integer","minimum":0},"stop":)" + kBool + R"(,"reason":)" +
              reasons + R"(,"reasons":)" + array_of(reasons) + R"(,"headline":)" + kString +
              R"(,"nearest_m":{"type":["number","null"]},"obstacles_in_zone":{"type":"integer","minimum":0},"zone":)" +
              zone,
          R"("timestamp","frame","on","stop","reason","reasons","headline","nearest_m","obstacles_in_zone","zone")"));
}

std::string health_schema() {
  const std::string sensor =
      object(R"("name":{"type":"string"},"state":{"type":"string"},"rate_hz":{"type":"number","minimum":0})",
             R"("name","state","rate_hz")");
  return with_title("fieldguard.Health",
                    object(R"("timestamp":)" + kTime + R"(,"sensors":)" + array_of(sensor) + R"(,"status":)" + kString,
                           R"("timestamp","sensors","status")"));
}

struct SchemaTable {
  std::array<std::string, 6> texts{point_cloud_schema(),  scene_update_schema(), frame_transform_schema(),
                                   location_fix_schema(), decision_schema(),     health_schema()};
  std::array<Schema, 6> schemas{Schema{"foxglove.PointCloud", texts[0]},     Schema{"foxglove.SceneUpdate", texts[1]},
                                Schema{"foxglove.FrameTransform", texts[2]}, Schema{"foxglove.LocationFix", texts[3]},
                                Schema{"fieldguard.Decision", texts[4]},     Schema{"fieldguard.Health", texts[5]}};
};
const SchemaTable& table() {
  static const SchemaTable t;
  return t;
}

// --- JSON pieces ----------------------------------------------------------------------------------------------

void num(std::string& s, double v, int decimals = 3) {
  if (!std::isfinite(v)) v = 0.0;  // JSON has no NaN; nothing written here is non-finite but for a bad input
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, decimals);
  s.append(buf, r.ptr);
}
void integer(std::string& s, std::int64_t v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  s.append(buf, r.ptr);
}
void time(std::string& s, std::int64_t ns) {
  if (ns < 0) ns = 0;
  s += R"({"sec":)";
  integer(s, ns / 1'000'000'000);
  s += R"(,"nsec":)";
  integer(s, ns % 1'000'000'000);
  s += '}';
}
void vec3(std::string& s, double x, double y, double z) {
  s += R"({"x":)";
  num(s, x);
  s += R"(,"y":)";
  num(s, y);
  s += R"(,"z":)";
  num(s, z);
  s += '}';
}
void yaw_pose(std::string& s, double x, double y, double z, double yaw_rad) {
  s += R"({"position":)";
  vec3(s, x, y, z);
  s += R"(,"orientation":{"x":0,"y":0,"z":)";
  num(s, std::sin(yaw_rad / 2), 6);
  s += R"(,"w":)";
  num(s, std::cos(yaw_rad / 2), 6);
  s += "}}";
}
constexpr std::string_view kIdentityPose =
    R"({"position":{"x":0,"y":0,"z":0},"orientation":{"x":0,"y":0,"z":0,"w":1}})";
struct Color {
  double r, g, b, a;
};
void color(std::string& s, Color c) {
  s += R"({"r":)";
  num(s, c.r, 2);
  s += R"(,"g":)";
  num(s, c.g, 2);
  s += R"(,"b":)";
  num(s, c.b, 2);
  s += R"(,"a":)";
  num(s, c.a, 2);
  s += '}';
}
// Our strings are fixed words, sensor names and numbers: nothing JSON must escape.
void str(std::string& s, std::string_view v) {
  s += '"';
  s += v;
  s += '"';
}

// foxglove.NumericType
enum Numeric : int { kUint8 = 1, kInt8 = 2, kUint16 = 3, kInt16 = 4, kFloat32 = 7 };

void cloud_head(std::string& out, std::int64_t stamp_ns, std::string_view fields, int stride) {
  out.clear();
  out += R"({"timestamp":)";
  time(out, stamp_ns);
  out += R"(,"frame_id":)";
  str(out, kLidarFrame);
  out += R"(,"pose":)";
  out += kIdentityPose;
  out += R"(,"point_stride":)";
  integer(out, stride);
  out += R"(,"fields":[)";
  out += fields;
  out += R"(],"data":")";
}

template <class T>
void store(std::byte* p, T v) {
  std::memcpy(p, &v, sizeof v);
}

// An entity's head up to its primitives' lists: {"timestamp":..,"frame_id":..,"id":..,"lifetime":0,...
void entity_head(std::string& s, std::int64_t stamp_ns, std::string_view id) {
  s += R"({"timestamp":)";
  time(s, stamp_ns);
  s += R"(,"frame_id":)";
  str(s, kLidarFrame);
  s += R"(,"id":)";
  str(s, id);
  // lifetime 0: the entity stays until the next update of the same id replaces it.
  s +=
      R"(,"lifetime":{"sec":0,"nsec":0},"frame_locked":false,"metadata":[],"arrows":[],"spheres":[],"cylinders":[],"triangles":[],"models":[])";
}

void text(std::string& s, double x, double y, double z, double size, Color c, std::string_view t) {
  s += R"({"pose":)";
  yaw_pose(s, x, y, z, 0.0);
  s += R"(,"billboard":true,"font_size":)";
  num(s, size, 1);
  s += R"(,"scale_invariant":true,"color":)";
  color(s, c);
  s += R"(,"text":)";
  str(s, t);
  s += '}';
}

// A closed rectangle at height z as a LINE_LOOP (type 1).
void rectangle(std::string& s, double x0, double y0, double x1, double y1, double z, Color c, double thickness) {
  s += R"({"type":1,"pose":)";
  s += kIdentityPose;
  s += R"(,"thickness":)";
  num(s, thickness, 2);
  s += R"(,"scale_invariant":false,"points":[)";
  vec3(s, x0, y0, z);
  s += ',';
  vec3(s, x1, y0, z);
  s += ',';
  vec3(s, x1, y1, z);
  s += ',';
  vec3(s, x0, y1, z);
  s += R"(],"color":)";
  color(s, c);
  s += R"(,"colors":[],"indices":[]})";
}

constexpr Color kStopRed{0.90, 0.10, 0.10, 1.0};
constexpr Color kGoGreen{0.10, 0.75, 0.20, 1.0};
constexpr Color kOrange{1.00, 0.55, 0.00, 0.5};
constexpr Color kRedBox{0.90, 0.10, 0.10, 0.6};
constexpr Color kBlueBox{0.20, 0.40, 1.00, 0.5};
constexpr Color kGrey{0.6, 0.6, 0.6, 1.0};
constexpr Color kWhite{1.0, 1.0, 1.0, 1.0};

}  // namespace

std::span<const Schema> schemas() { return table().schemas; }

const Schema& schema(std::string_view name) {
  for (const Schema& s : table().schemas) {
    if (s.name == name) return s;
  }
  throw std::out_of_range("no Foxglove schema " + std::string(name));
}

void base64(std::string& out, std::span<const std::byte> bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const std::size_t n = bytes.size();
  const std::size_t start = out.size();
  out.resize(start + (n + 2) / 3 * 4);
  char* o = out.data() + start;
  std::size_t i = 0;
  for (; i + 3 <= n; i += 3) {
    const auto v = (std::to_integer<std::uint32_t>(bytes[i]) << 16U) |
                   (std::to_integer<std::uint32_t>(bytes[i + 1]) << 8U) | std::to_integer<std::uint32_t>(bytes[i + 2]);
    *o++ = kAlphabet[(v >> 18U) & 63U];
    *o++ = kAlphabet[(v >> 12U) & 63U];
    *o++ = kAlphabet[(v >> 6U) & 63U];
    *o++ = kAlphabet[v & 63U];
  }
  if (i < n) {
    std::uint32_t v = std::to_integer<std::uint32_t>(bytes[i]) << 16U;
    if (i + 1 < n) v |= std::to_integer<std::uint32_t>(bytes[i + 1]) << 8U;
    *o++ = kAlphabet[(v >> 18U) & 63U];
    *o++ = kAlphabet[(v >> 12U) & 63U];
    *o++ = i + 1 < n ? kAlphabet[(v >> 6U) & 63U] : '=';
    *o++ = '=';
  }
}

void raw_cloud(std::string& out, std::int64_t stamp_ns, const LidarFrame& frame) {
  static const std::string fields = [] {
    std::string f;
    const std::tuple<const char*, int, int> kFields[] = {{"x", 0, kFloat32},     {"y", 4, kFloat32},
                                                         {"z", 8, kFloat32},     {"intensity", 12, kUint8},
                                                         {"source", 13, kUint8}, {"ring", 14, kUint16}};
    for (const auto& [name, offset, type] : kFields) {
      if (!f.empty()) f += ',';
      f += R"({"name":")" + std::string(name) + R"(","offset":)" + std::to_string(offset) + R"(,"type":)" +
           std::to_string(type) + "}";
    }
    return f;
  }();
  constexpr int kStride = 16;
  cloud_head(out, stamp_ns, fields, kStride);
  std::vector<std::byte> data(frame.points.size() * kStride);
  std::byte* p = data.data();
  for (const LidarPoint& pt : frame.points) {
    store(p, pt.x);
    store(p + 4, pt.y);
    store(p + 8, pt.z);
    store(p + 12, static_cast<std::uint8_t>(std::clamp(pt.intensity, 0.F, 255.F)));
    store(p + 13, pt.source);
    store(p + 14, pt.ring);
    p += kStride;
  }
  base64(out, data);
  out += "\"}";
}

void labelled_cloud(std::string& out, std::int64_t stamp_ns, std::span<const perception::LabeledPoint> points,
                    std::span<const perception::Obstacle> obstacles) {
  static const std::string fields =
      R"({"name":"x","offset":0,"type":7},{"name":"y","offset":4,"type":7},{"name":"z","offset":8,"type":7},)"
      R"({"name":"label","offset":12,"type":1},{"name":"obstacle","offset":14,"type":4})";
  constexpr int kStride = 16;
  cloud_head(out, stamp_ns, fields, kStride);
  std::vector<std::byte> data(points.size() * kStride);
  std::byte* p = data.data();
  for (const perception::LabeledPoint& pt : points) {
    std::int16_t box = -1;
    if (pt.label == perception::PointLabel::Obstacle) {
      for (std::size_t i = 0; i < obstacles.size() && i < 32767; ++i) {
        const perception::Obstacle& o = obstacles[i];
        if (pt.x >= o.min[0] && pt.x <= o.max[0] && pt.y >= o.min[1] && pt.y <= o.max[1] && pt.z >= o.min[2] &&
            pt.z <= o.max[2]) {
          box = static_cast<std::int16_t>(i);
          break;
        }
      }
    }
    store(p, pt.x);
    store(p + 4, pt.y);
    store(p + 8, pt.z);
    store(p + 12, static_cast<std::uint8_t>(pt.label));
    store(p + 13, std::uint8_t{0});
    store(p + 14, box);
    p += kStride;
  }
  base64(out, data);
  out += "\"}";
}

void obstacles_scene(std::string& out, std::int64_t stamp_ns, std::span<const perception::Obstacle> obstacles,
                     const output::safety::Zone* zone) {
  out.clear();
  out += R"({"deletions":[],"entities":[)";
  entity_head(out, stamp_ns, "obstacles");
  out += R"(,"cubes":[)";
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const perception::Obstacle& o = obstacles[i];
    if (i != 0) out += ',';
    const auto z0 = static_cast<double>(o.min[2]);
    const double h = std::max(0.05, static_cast<double>(o.max[2]) - z0);
    out += R"({"pose":)";
    yaw_pose(out, static_cast<double>(o.obb_center[0]), static_cast<double>(o.obb_center[1]), z0 + h / 2,
             static_cast<double>(o.obb_yaw_rad));
    out += R"(,"size":)";
    vec3(out, std::max(0.05, static_cast<double>(o.obb_length_m)), std::max(0.05, static_cast<double>(o.obb_width_m)),
         h);
    out += R"(,"color":)";
    color(out, o.held ? kBlueBox : (zone != nullptr && output::safety::overlaps(o, *zone)) ? kRedBox : kOrange);
    out += '}';
  }
  out += R"(],"lines":[],"texts":[)";
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const perception::Obstacle& o = obstacles[i];
    if (i != 0) out += ',';
    char label[64];
    std::snprintf(label, sizeof label, "%.1f m%s, %.1f m high", static_cast<double>(o.distance_m),
                  o.held ? " (held)" : "", static_cast<double>(o.height_above_ground_m));
    text(out, static_cast<double>(o.obb_center[0]), static_cast<double>(o.obb_center[1]),
         static_cast<double>(o.max[2]) + 0.3, 12.0, kWhite, label);
  }
  out += "]}]}";
}

void zones_scene(std::string& out, std::int64_t stamp_ns, const perception::Box3& roi, const perception::Box3& body,
                 double ground_z, const output::safety::Decision* decision) {
  out.clear();
  out += R"({"deletions":[],"entities":[)";
  entity_head(out, stamp_ns, "zones");
  out += R"(,"cubes":[],"lines":[)";
  rectangle(out, roi.min[0], roi.min[1], roi.max[0], roi.max[1], ground_z, kGrey, 0.05);
  out += ',';
  rectangle(out, body.min[0], body.min[1], body.max[0], body.max[1], ground_z, kGrey, 0.05);
  if (decision != nullptr) {
    const output::safety::Zone& z = decision->zone;
    out += ',';
    rectangle(out, z.x_min_m, -z.half_width_m, z.x_max_m, z.half_width_m, ground_z,
              decision->stop ? kStopRed : kGoGreen, 0.12);
  }
  out += R"(],"texts":[)";
  if (decision != nullptr) {
    const output::safety::Zone& z = decision->zone;
    text(out, z.x_max_m, 0.0, ground_z + 0.5, 14.0, decision->stop ? kStopRed : kGoGreen,
         decision->stop ? "stop zone: STOP" : "stop zone: GO");
  }
  out += "]}]}";
}

void decision(std::string& out, std::int64_t stamp_ns, std::uint64_t frame, const output::safety::Decision& d,
              int clear_frames, bool on_clock) {
  namespace safety = output::safety;
  out.clear();
  out += R"({"timestamp":)";
  time(out, stamp_ns);
  out += R"(,"frame":)";
  integer(out, static_cast<std::int64_t>(frame));
  out += on_clock ? R"(,"on":"clock")" : R"(,"on":"frame")";
  out += R"(,"stop":)";
  out += d.stop ? "true" : "false";
  out += R"(,"reason":)";
  str(out, safety::to_string(d.reason));
  out += R"(,"reasons":[)";
  bool first = true;
  for (const auto r : safety::kReasonPriority) {
    if ((d.reasons & safety::bit(r)) == 0) continue;
    if (!first) out += ',';
    str(out, safety::to_string(r));
    first = false;
  }
  out += R"(],"headline":)";
  str(out, safety::headline(d, clear_frames));
  out += R"(,"nearest_m":)";
  if (d.nearest_m) {
    num(out, static_cast<double>(*d.nearest_m), 2);
  } else {
    out += "null";
  }
  out += R"(,"obstacles_in_zone":)";
  integer(out, d.obstacles_in_zone);
  out += R"(,"zone":{"x_min":)";
  num(out, d.zone.x_min_m, 2);
  out += R"(,"x_max":)";
  num(out, d.zone.x_max_m, 2);
  out += R"(,"half_width":)";
  num(out, d.zone.half_width_m, 2);
  out += R"(,"speed_known":)";
  out += d.zone.speed_known ? "true" : "false";
  out += "}}";
}

void frame_transform(std::string& out, std::int64_t stamp_ns, const perception::FramePose& pose,
                     const std::array<double, 3>& origin) {
  out.clear();
  out += R"({"timestamp":)";
  time(out, stamp_ns);
  out += R"(,"parent_frame_id":)";
  str(out, kFieldFrame);
  out += R"(,"child_frame_id":)";
  str(out, kLidarFrame);
  out += R"(,"translation":)";
  vec3(out, pose.x_m - origin[0], pose.y_m - origin[1], pose.z_m - origin[2]);
  out += R"(,"rotation":{"x":0,"y":0,"z":)";
  num(out, std::sin(pose.yaw_rad / 2), 6);
  out += R"(,"w":)";
  num(out, std::cos(pose.yaw_rad / 2), 6);
  out += "}}";
}

void health(std::string& out, std::int64_t stamp_ns, std::span<const SensorState> sensors, std::string_view status) {
  out.clear();
  out += R"({"timestamp":)";
  time(out, stamp_ns);
  out += R"(,"sensors":[)";
  for (std::size_t i = 0; i < sensors.size(); ++i) {
    if (i != 0) out += ',';
    out += R"({"name":)";
    str(out, sensors[i].name);
    out += R"(,"state":)";
    str(out, sensors[i].state);
    out += R"(,"rate_hz":)";
    num(out, std::max(0.0, sensors[i].rate_hz), 1);
    out += '}';
  }
  out += R"(],"status":)";
  str(out, status);
  out += '}';
}

void location_fix(std::string& out, std::int64_t stamp_ns, const geo::Geodetic& g) {
  out.clear();
  out += R"({"timestamp":)";
  time(out, stamp_ns);
  out += R"(,"frame_id":"vehicle","latitude":)";
  num(out, g.lat_deg, 9);
  out += R"(,"longitude":)";
  num(out, g.lon_deg, 9);
  out += R"(,"altitude":)";
  num(out, g.h_m, 3);
  // The fix quality's covariance is not carried into the frame: type 0, unknown.
  out += R"(,"position_covariance":[0,0,0,0,0,0,0,0,0],"position_covariance_type":0})";
}

}  // namespace fieldguard::app::foxglove
