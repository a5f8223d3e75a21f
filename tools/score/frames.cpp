#include "score/frames.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <string_view>

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

using Json = nlohmann::json;

// One line as one JSON value. A key repeated in an object keeps its first value, as the scorer's readers always
// have (RFC 8259 leaves it open; nlohmann would keep the last): the parser's callback drops the repeats,
// remembering the keys of each open object by its depth (an object's start clears its level).
Json parse_line(const std::string& text) {
  std::vector<std::set<std::string, std::less<>>> keys;
  const auto first_key_wins = [&keys](int depth, Json::parse_event_t event, Json& parsed) {
    const auto level = static_cast<std::size_t>(depth);
    if (event == Json::parse_event_t::object_start) {
      keys.resize(std::max(keys.size(), level + 2));
      keys[level + 1].clear();
    } else if (event == Json::parse_event_t::key) {
      keys.resize(std::max(keys.size(), level + 1));
      return keys[level].insert(parsed.get<std::string>()).second;
    }
    return true;
  };
  return Json::parse(text, first_key_wins);
}

// nlohmann's message without its "[json.exception.parse_error.101] parse error at line 1, column 7: " head.
std::string json_message(const Json::exception& e) {
  std::string_view m = e.what();
  if (const auto head = m.find("] "); m.starts_with("[json.exception.") && head != std::string_view::npos) {
    m.remove_prefix(head + 2);
  }
  if (const auto at = m.find("column "); at != std::string_view::npos) {
    if (const auto colon = m.find(": ", at); colon != std::string_view::npos) m.remove_prefix(colon + 2);
  }
  return std::string(m);
}

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
    std::string why;
    try {
      const Json line = parse_line(text);
      if (!line.is_object()) {
        why = "a line must be one JSON object";
      } else {
        take(line, n, why);
      }
    } catch (const Json::parse_error& e) {
      why = "not valid JSON at column " + std::to_string(e.byte) + ": " + json_message(e);
    } catch (const Json::exception& e) {  // a number too large for a double
      why = "not valid JSON: " + json_message(e);
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

// The member `key` of an object, or nullptr.
const Json* member(const Json& obj, std::string_view key) {
  const auto it = obj.find(key);
  return it == obj.end() ? nullptr : &*it;
}

bool get_number(const Json& obj, std::string_view key, double& out, std::string& why, bool required = true) {
  const Json* v = member(obj, key);
  if (v == nullptr) {
    if (required) why = "missing \"" + std::string(key) + "\"";
    return !required;
  }
  if (!v->is_number()) {
    why = "\"" + std::string(key) + "\" must be a number";
    return false;
  }
  out = v->get<double>();
  return true;
}

bool get_box(const Json& obj, Box& box, std::string& why, const std::string& where) {
  for (const auto* key : {"min", "max"}) {
    const Json* v = member(obj, key);
    if (v == nullptr || !v->is_array() || v->size() != 3 ||
        !std::all_of(v->begin(), v->end(), [](const Json& e) { return e.is_number(); })) {
      why = where + ": \"" + key + "\" must be an array of 3 numbers";
      return false;
    }
    auto& dst = std::string_view(key) == "min" ? box.min : box.max;
    for (std::size_t i = 0; i < 3; ++i) dst[i] = (*v)[i].get<double>();
  }
  for (std::size_t i = 0; i < 3; ++i) {
    if (box.min[i] > box.max[i]) {
      why = where + ": min is greater than max";
      return false;
    }
  }
  return true;
}

const Json* get_array(const Json& obj, std::string_view key, std::string& why, bool required) {
  const Json* v = member(obj, key);
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

bool get_items(const Json& obj, std::string_view key, bool required, std::vector<TruthItem>& out, std::string& why) {
  const Json* list = get_array(obj, key, why, required);
  if (list == nullptr) return why.empty();
  for (std::size_t i = 0; i < list->size(); ++i) {
    const Json& o = (*list)[i];
    const std::string where = std::string(key) + "[" + std::to_string(i) + "]";
    if (!o.is_object()) {
      why = where + " must be an object";
      return false;
    }
    TruthItem t;
    const Json* cls = member(o, "class");
    if (cls == nullptr || !cls->is_string()) {
      why = where + ": \"class\" must be a string";
      return false;
    }
    t.cls = cls->get<std::string>();
    const Json* id = member(o, "id");
    t.id = id != nullptr && id->is_string() ? id->get<std::string>() : t.cls + "#" + std::to_string(i);
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
    if (member(o, "raised_hits") != nullptr && !(raised >= 0.0 && raised <= hits)) {
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
  return read_lines(path, error, [&](const Json& line, std::size_t n, std::string& why) {
    DetectionFrame f;
    f.line = n;
    double frame = static_cast<double>(out.size());
    if (!get_number(line, "frame", frame, why, false) || !get_number(line, "stamp", f.stamp, why)) return;
    f.frame = std::lround(frame);
    if (const Json* p = member(line, "partial"); p != nullptr) {
      if (!p->is_boolean()) {
        why = "\"partial\" must be true or false";
        return;
      }
      f.partial = p->get<bool>();
    }
    const Json* list = get_array(line, "obstacles", why, true);
    if (list == nullptr) return;
    for (std::size_t i = 0; i < list->size(); ++i) {
      const Json& o = (*list)[i];
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
  return read_lines(path, error, [&](const Json& line, std::size_t n, std::string& why) {
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
