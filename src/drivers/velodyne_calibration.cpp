// Built-in calibration tables, ring assignment and the helpers both calibration file parsers share.
// The parsers themselves: velodyne_calibration_ros.cpp (YAML), velodyne_calibration_db.cpp (db.xml).

#include "fieldguard/drivers/velodyne_calibration.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "drivers/velodyne_calibration_detail.hpp"

namespace fieldguard::velodyne {
namespace {

// protocols.md §1.5: HDL-32E vertical angles by slot (= laser id, firing order), degrees.
constexpr std::array<double, 32> kHdl32eVertDeg = {-30.67, -9.33, -29.33, -8.00, -28.00, -6.67, -26.67, -5.33,  //
                                                   -25.33, -4.00, -24.00, -2.67, -22.67, -1.33, -21.33, 0.00,   //
                                                   -20.00, 1.33,  -18.67, 2.67,  -17.33, 4.00,  -16.00, 5.33,   //
                                                   -14.67, 6.67,  -13.33, 8.00,  -12.00, 9.33,  -10.67, 10.67};

// protocols.md §1.10: VLP-16 vertical angles by laser id, degrees.
constexpr std::array<double, 16> kVlp16VertDeg = {-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15};

constexpr double kDefaultDistanceResolutionM = 0.002;
constexpr std::size_t kIssuesShown = 5;

[[nodiscard]] std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return s.substr(first, last - first + 1);
}

}  // namespace

Calibration default_calibration(Model model) {
  Calibration cal;
  cal.model = model;
  cal.distance_resolution_m = kDefaultDistanceResolutionM;
  switch (model) {
    case Model::HDL32E:
      for (const double v : kHdl32eVertDeg) cal.lasers.push_back(LaserCorrection{.vert_deg = v});
      break;
    case Model::VLP16:
      for (const double v : kVlp16VertDeg) cal.lasers.push_back(LaserCorrection{.vert_deg = v});
      break;
    case Model::Unknown:
      throw std::invalid_argument("default_calibration: the model must be HDL-32E or VLP-16, not unknown");
  }
  assign_rings(cal);
  return cal;
}

void assign_rings(Calibration& cal) {
  std::vector<std::size_t> order(cal.lasers.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  // Stable: equal angles keep the lower laser index on the lower ring.
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return cal.lasers[a].vert_deg < cal.lasers[b].vert_deg; });
  cal.ring_of_laser.assign(cal.lasers.size(), 0);
  for (std::size_t rank = 0; rank < order.size(); ++rank) {
    cal.ring_of_laser[order[rank]] = static_cast<int>(rank);
  }
}

namespace detail {

std::string Issues::message() const {
  std::string out;
  const std::size_t shown = std::min(items_.size(), kIssuesShown);
  for (std::size_t i = 0; i < shown; ++i) {
    if (i > 0) out += "; ";
    out += items_[i];
  }
  if (items_.size() > shown) out += "; and " + std::to_string(items_.size() - shown) + " more";
  return out;
}

std::optional<double> parse_number(std::string_view text) {
  std::string_view s = trim(text);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return std::nullopt;
  // from_chars would also take "inf", "nan" and hex floats with the right flags; general format
  // takes "inf"/"nan", which isfinite() rejects below.
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::general);
  if (ec != std::errc{} || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<int> parse_index(std::string_view text) {
  std::string_view s = trim(text);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return std::nullopt;
  int v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size() || v < 0) return std::nullopt;
  return v;
}

std::optional<Model> model_for_laser_count(std::size_t n) {
  if (n == kHdl32eVertDeg.size()) return Model::HDL32E;
  if (n == kVlp16VertDeg.size()) return Model::VLP16;
  return std::nullopt;
}

std::string supported_counts() { return "only 32 (HDL-32E) and 16 (VLP-16) lasers are supported"; }

std::string count_mismatch(Model model, std::size_t found) {
  const std::size_t expected = model == Model::HDL32E ? kHdl32eVertDeg.size() : kVlp16VertDeg.size();
  return std::to_string(expected) + " lasers expected for " + std::string(to_string(model)) + ", found " +
         std::to_string(found);
}

std::string quoted(std::string_view text) {
  constexpr std::size_t kMax = 40;
  std::string out = "'";
  if (text.size() > kMax) {
    out.append(text.substr(0, kMax));
    out += "...";
  } else {
    out.append(text);
  }
  out += "'";
  return out;
}

Calibration finish(Model model, double distance_resolution_m, const LaserTable& table, Issues& issues) {
  const auto present = static_cast<std::size_t>(
      std::count_if(table.by_id.begin(), table.by_id.end(), [](const auto& l) { return l.has_value(); }));
  if (present != table.by_id.size()) {
    constexpr std::size_t kIdsShown = 8;
    std::string missing;
    std::size_t listed = 0;
    for (std::size_t id = 0; id < table.by_id.size(); ++id) {
      if (table.by_id[id]) continue;
      if (listed++ == kIdsShown) {
        missing += ", ...";
        break;
      }
      missing += (missing.empty() ? "" : ", ") + std::to_string(id);
    }
    issues.add(count_mismatch(model, present) + " (missing laser id " + missing + ")");
  }
  if (!issues.empty()) return {};
  Calibration cal;
  cal.model = model;
  cal.distance_resolution_m = distance_resolution_m;
  for (const auto& l : table.by_id) cal.lasers.push_back(*l);
  assign_rings(cal);
  return cal;
}

}  // namespace detail
}  // namespace fieldguard::velodyne
