#include "app/obstacles_jsonl.hpp"

#include <cmath>
#include <cstdio>

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

}  // namespace

std::string obstacles_json_line(const LidarFrame& frame, const perception::FrameResult& result) {
  std::string s = "{\"frame\":" + std::to_string(frame.index) + ",\"stamp\":";
  num(s, frame.host_stamp.seconds(), 6);
  s += ",\"partial\":";
  s += frame.partial ? "true" : "false";
  s += ",\"points_in\":" + std::to_string(frame.points.size()) + ",\"obstacles\":[";
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
    s += ",\"length\":";
    num(s, static_cast<double>(o.obb_length_m), 3);
    s += ",\"width\":";
    num(s, static_cast<double>(o.obb_width_m), 3);
    s += ",\"yaw\":";
    num(s, static_cast<double>(o.obb_yaw_rad), 4);
    s += "},\"distance\":";
    num(s, static_cast<double>(o.distance_m), 3);
    s += ",\"bearing\":";
    num(s, static_cast<double>(o.bearing_deg), 2);
    s += ",\"height\":";
    num(s, static_cast<double>(o.height_above_ground_m), 3);
    s += ",\"class\":\"";
    s += perception::to_string(o.size_class);
    s += "\"}";
  }
  s += "]}";
  return s;
}

}  // namespace fieldguard::app
