#include "sim/truth_writer.hpp"

#include <cstdio>

namespace fieldguard::sim {

namespace {

void append_number(std::string& s, double v, int decimals) {
  char buf[64];
  const int n = std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string num(buf, static_cast<std::size_t>(n > 0 ? n : 0));
  if (num.rfind("-0.", 0) == 0 && num.find_first_not_of("-0.") == std::string::npos) num.erase(0, 1);
  s += num;
}

void append_vec(std::string& s, Vec3 v) {
  s += '[';
  append_number(s, v.x, 3);
  s += ", ";
  append_number(s, v.y, 3);
  s += ", ";
  append_number(s, v.z, 3);
  s += ']';
}

void append_objects(std::string& s, const std::vector<ObjectTruth>& list) {
  s += '[';
  for (std::size_t i = 0; i < list.size(); ++i) {
    const ObjectTruth& o = list[i];
    if (i > 0) s += ", ";
    s += R"({"id": ")" + o.id + R"(", "class": ")" + std::string(to_string(o.cls)) + R"(", "min": )";
    append_vec(s, o.box.min);
    s += ", \"max\": ";
    append_vec(s, o.box.max);
    s += ", \"hits\": " + std::to_string(o.hits) + ", \"raised_hits\": " + std::to_string(o.raised_hits) +
         ", \"distance_m\": ";
    append_number(s, o.distance_m, 3);
    s += '}';
  }
  s += ']';
}

}  // namespace

std::string truth_json_line(const FrameTruth& t) {
  std::string s = "{\"frame\": " + std::to_string(t.frame) + ", \"stamp\": ";
  {
    // Exact microseconds (a double would round some of them).
    const long long us = t.stamp_ns / 1000;
    char buf[40];
    const int n = std::snprintf(buf, sizeof buf, "%lld.%06lld", us / 1000000, us % 1000000);
    s.append(buf, static_cast<std::size_t>(n > 0 ? n : 0));
  }
  s += ", \"period_s\": ";
  append_number(s, t.period_s, 6);
  s += R"(, "sensor": ")" + std::string(t.sensor) + '"';
  s += ", \"roll_deg\": ";
  append_number(s, t.roll_deg, 3);
  s += ", \"pitch_deg\": ";
  append_number(s, t.pitch_deg, 3);
  s += ", \"sensor_world\": ";
  append_vec(s, t.sensor_world);
  s += ", \"returns\": " + std::to_string(t.returns) + ", \"objects\": ";
  append_objects(s, t.objects);
  s += ", \"terrain\": ";
  append_objects(s, t.terrain);
  s += '}';
  return s;
}

}  // namespace fieldguard::sim
