#include "score/frames.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>

#include "score/json.hpp"

namespace fieldguard::score {

double horizontal_distance(const Box& b) {
  const double dx = std::max({b.min[0], 0.0, -b.max[0]});
  const double dy = std::max({b.min[1], 0.0, -b.max[1]});
  return std::hypot(dx, dy);
}

bool matches(const Box& obstacle, const Box& truth, double margin, double min_fraction) {
  constexpr double kSlack = 0.05;
  for (std::size_t i = 0; i < 3; ++i) {
    const double lo = std::max(obstacle.min[i], truth.min[i] - margin);
    const double hi = std::min(obstacle.max[i], truth.max[i] + margin);
    if (hi < lo) return false;
    if (i == 2) continue;
    const double shorter = std::min(obstacle.max[i] - obstacle.min[i], truth.max[i] - truth.min[i]);
    if (hi - lo + kSlack < min_fraction * (shorter + kSlack)) return false;
  }
  return true;
}

namespace {

// Reads JSON lines, calling `take(value, line_number, error)` for each; stops at the first problem.
template <typename Take>
bool read_lines(const std::string& path, std::string& error, Take take) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = "cannot open " + path + ": " + std::strerror(errno);
    return false;
  }
  std::string text;
  std::size_t n = 0;
  while (std::getline(in, text)) {
    ++n;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (text.find_first_not_of(" \t") == std::string::npos) continue;
    const JsonResult r = parse_json(text);
    std::string why;
    if (!r.value) {
      why = "not valid JSON at column " + std::to_string(r.error.offset + 1) + ": " + r.error.message;
    } else if (!r.value->is_object()) {
      why = "a line must be one JSON object";
    } else {
      take(*r.value, n, why);
    }
    if (!why.empty()) {
      error = path + ":" + std::to_string(n) + ": " + why;
      return false;
    }
  }
  if (in.bad()) {
    error = "cannot read " + path;
    return false;
  }
  return true;
}

bool get_number(const JsonValue& obj, std::string_view key, double& out, std::string& why, bool required = true) {
  const JsonValue* v = obj.find(key);
  if (v == nullptr) {
    if (required) why = "missing \"" + std::string(key) + "\"";
    return !required;
  }
  if (!v->is_number()) {
    why = "\"" + std::string(key) + "\" must be a number";
    return false;
  }
  out = v->number;
  return true;
}

bool get_box(const JsonValue& obj, Box& box, std::string& why, const std::string& where) {
  for (const auto* key : {"min", "max"}) {
    const JsonValue* v = obj.find(key);
    if (v == nullptr || !v->is_array() || v->items.size() != 3 ||
        !std::all_of(v->items.begin(), v->items.end(), [](const JsonValue& e) { return e.is_number(); })) {
      why = where + ": \"" + key + "\" must be an array of 3 numbers";
      return false;
    }
    auto& dst = std::string_view(key) == "min" ? box.min : box.max;
    for (std::size_t i = 0; i < 3; ++i) dst[i] = v->items[i].number;
  }
  for (std::size_t i = 0; i < 3; ++i) {
    if (box.min[i] > box.max[i]) {
      why = where + ": min is greater than max";
      return false;
    }
  }
  return true;
}

const JsonValue* get_array(const JsonValue& obj, std::string_view key, std::string& why, bool required) {
  const JsonValue* v = obj.find(key);
  if (v == nullptr) {
    if (required) why = "missing \"" + std::string(key) + "\"";
    return nullptr;
  }
  if (!v->is_array()) {
    why = "\"" + std::string(key) + "\" must be an array";
    return nullptr;
  }
  return v;
}

bool get_items(const JsonValue& obj, std::string_view key, bool required, std::vector<TruthItem>& out,
               std::string& why) {
  const JsonValue* list = get_array(obj, key, why, required);
  if (list == nullptr) return why.empty();
  for (std::size_t i = 0; i < list->items.size(); ++i) {
    const JsonValue& o = list->items[i];
    const std::string where = std::string(key) + "[" + std::to_string(i) + "]";
    if (!o.is_object()) {
      why = where + " must be an object";
      return false;
    }
    TruthItem t;
    const JsonValue* cls = o.find("class");
    if (cls == nullptr || cls->kind != JsonValue::Kind::String) {
      why = where + ": \"class\" must be a string";
      return false;
    }
    t.cls = cls->string;
    const JsonValue* id = o.find("id");
    t.id = id != nullptr && id->kind == JsonValue::Kind::String ? id->string : t.cls + "#" + std::to_string(i);
    if (!get_box(o, t.box, why, where)) return false;
    double hits = 0.0;
    if (!get_number(o, "hits", hits, why)) {
      why = where + ": " + why;
      return false;
    }
    t.hits = std::lround(hits);
    double raised = -1.0;
    if (!get_number(o, "raised_hits", raised, why, false)) {
      why = where + ": " + why;
      return false;
    }
    if (o.find("raised_hits") != nullptr && !(raised >= 0.0 && raised <= hits)) {
      why = where + ": \"raised_hits\" must be from 0 to \"hits\"";
      return false;
    }
    t.raised_hits = std::lround(raised);
    t.distance_m = horizontal_distance(t.box);
    if (!get_number(o, "distance_m", t.distance_m, why, false)) {
      why = where + ": " + why;
      return false;
    }
    out.push_back(std::move(t));
  }
  return true;
}

}  // namespace

bool read_detections(const std::string& path, std::vector<DetectionFrame>& out, std::string& error) {
  return read_lines(path, error, [&](const JsonValue& line, std::size_t n, std::string& why) {
    DetectionFrame f;
    f.line = n;
    double frame = static_cast<double>(out.size());
    if (!get_number(line, "frame", frame, why, false) || !get_number(line, "stamp", f.stamp, why)) return;
    f.frame = std::lround(frame);
    if (const JsonValue* p = line.find("partial"); p != nullptr) {
      if (p->kind != JsonValue::Kind::Bool) {
        why = "\"partial\" must be true or false";
        return;
      }
      f.partial = p->boolean;
    }
    const JsonValue* list = get_array(line, "obstacles", why, true);
    if (list == nullptr) return;
    for (std::size_t i = 0; i < list->items.size(); ++i) {
      const JsonValue& o = list->items[i];
      const std::string where = "obstacles[" + std::to_string(i) + "]";
      if (!o.is_object()) {
        why = where + " must be an object";
        return;
      }
      Obstacle ob;
      if (!get_box(o, ob.box, why, where)) return;
      double points = 0.0;
      if (!get_number(o, "points", points, why, false)) {
        why = where + ": " + why;
        return;
      }
      ob.points = std::lround(points);
      f.obstacles.push_back(ob);
    }
    out.push_back(std::move(f));
  });
}

bool read_truth(const std::string& path, std::vector<TruthFrame>& out, std::string& error) {
  return read_lines(path, error, [&](const JsonValue& line, std::size_t n, std::string& why) {
    TruthFrame f;
    f.line = n;
    double frame = static_cast<double>(out.size());
    if (!get_number(line, "frame", frame, why, false) || !get_number(line, "stamp", f.stamp, why) ||
        !get_number(line, "period_s", f.period_s, why, false)) {
      return;
    }
    f.frame = std::lround(frame);
    if (!get_items(line, "objects", true, f.objects, why) || !get_items(line, "terrain", false, f.terrain, why)) return;
    out.push_back(std::move(f));
  });
}

}  // namespace fieldguard::score
