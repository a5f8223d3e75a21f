// VeloView / Velodyne db.xml: a boost::serialization XML archive.
//   boost_serialization/DB/distLSB_                      distance LSB, cm (absent: 0.2 cm, as VeloView)
//   boost_serialization/DB/enabled_/item*                1 for each laser the sensor has, 0 for unused slots
//   boost_serialization/DB/points_/item*/px/{id_, rotCorrection_ (deg), vertCorrection_ (deg),
//       distCorrection_, distCorrectionX_, distCorrectionY_, vertOffsetCorrection_, horizOffsetCorrection_ (cm),
//       focalDistance_, focalSlope_}
// The files VeloView ships have 64 slots whatever the sensor: HDL-32.xml enables 32 and leaves 32..63 at
// zero; VLP-16.xml enables 16 and repeats lasers 0..15 in slots 16..31 (the VLP-16's second firing
// sequence). The laser count is the number of enabled slots (the number of points_ items if there is no
// enabled_ list), and only ids below it are read.

#include <algorithm>
#include <boost/property_tree/ptree.hpp>
#include <boost/property_tree/xml_parser.hpp>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>

#include "drivers/velodyne_calibration_detail.hpp"
#include "fieldguard/drivers/velodyne_calibration.hpp"

namespace fieldguard::velodyne {
namespace {

namespace pt = boost::property_tree;
using detail::Issues;

constexpr double kCmToM = 0.01;
constexpr double kDefaultLsbCm = 0.2;
constexpr double kMaxLsbCm = 1.0;

// The number stored in child `key` of `node`; adds an issue if it is missing (when required) or not a number.
std::optional<double> number_child(const pt::ptree& node, const char* key, const std::string& where, bool required,
                                   Issues& issues) {
  const auto child = node.get_child_optional(key);
  if (!child) {
    if (required) issues.add(where + ": " + key + " missing");
    return std::nullopt;
  }
  auto v = detail::parse_number(child->data());
  if (!v) issues.add(where + ": " + key + " is not a number: " + detail::quoted(child->data()));
  return v;
}

// Laser count from enabled_ (a leading run of 1s), or nullopt if there is no enabled_ list.
std::optional<std::size_t> enabled_count(const pt::ptree& db, Issues& issues) {
  const auto enabled = db.get_child_optional("enabled_");
  if (!enabled) return std::nullopt;
  std::size_t index = 0;
  std::size_t count = 0;
  std::optional<std::size_t> first_disabled;
  for (const auto& [key, item] : *enabled) {
    if (key != "item") continue;
    const auto v = detail::parse_index(item.data());
    if (!v || *v > 1) {
      issues.add("enabled_ item " + std::to_string(index) + " is not 0 or 1: " + detail::quoted(item.data()));
    } else if (*v == 1) {
      if (first_disabled) {
        issues.add("enabled_ item " + std::to_string(index) + " is enabled after disabled laser " +
                   std::to_string(*first_disabled) + ": only lasers 0..n-1 may be enabled");
      }
      ++count;
    } else if (!first_disabled) {
      first_disabled = index;
    }
    ++index;
  }
  return count;
}

// One points_ item, stored at its id_ if that is below the laser count.
void read_point(const pt::ptree& item, std::size_t index, detail::LaserTable& table, Issues& issues) {
  const std::string where = "laser " + std::to_string(index);
  const auto px = item.get_child_optional("px");
  if (!px) {
    issues.add(where + ": no px element in points_ item");
    return;
  }
  const auto id_node = px->get_child_optional("id_");
  if (!id_node) {
    issues.add(where + ": id_ missing");
    return;
  }
  const auto id = detail::parse_index(id_node->data());
  if (!id) {
    issues.add(where + ": id_ is not a laser number: " + detail::quoted(id_node->data()));
    return;
  }
  const auto slot = static_cast<std::size_t>(*id);
  if (slot >= table.by_id.size()) return;  // an unused slot beyond the enabled lasers
  if (table.by_id[slot]) {
    issues.add(where + ": id_ " + std::to_string(slot) + " appears twice");
    return;
  }
  const auto rot = number_child(*px, "rotCorrection_", where, true, issues);
  const auto vert = number_child(*px, "vertCorrection_", where, true, issues);
  const auto dist = number_child(*px, "distCorrection_", where, true, issues);
  const auto vert_offset = number_child(*px, "vertOffsetCorrection_", where, true, issues);
  const auto horiz_offset = number_child(*px, "horizOffsetCorrection_", where, true, issues);
  const auto dist_x = number_child(*px, "distCorrectionX_", where, false, issues);
  const auto dist_y = number_child(*px, "distCorrectionY_", where, false, issues);
  (void)number_child(*px, "focalDistance_", where, false, issues);
  (void)number_child(*px, "focalSlope_", where, false, issues);
  if (vert && std::abs(*vert) > 90.0) {
    issues.add(where + ": vertCorrection_ " + px->get_child("vertCorrection_").data() + " is beyond +-90 degrees");
    return;
  }
  if (!rot || !vert || !dist || !vert_offset || !horiz_offset) return;
  table.by_id[slot] = LaserCorrection{
      .vert_deg = *vert,
      .rot_deg = *rot,
      .dist_m = *dist * kCmToM,
      .vert_offset_m = *vert_offset * kCmToM,
      .horiz_offset_m = *horiz_offset * kCmToM,
      .dist_x_m = dist_x.value_or(0.0) * kCmToM,
      .dist_y_m = dist_y.value_or(0.0) * kCmToM,
  };
}

// Deepest element nesting in the text, counted over tags; Boost's XML reader recurses once per level, so a
// hostile file could exhaust the stack. A real db.xml nests 6 deep.
std::size_t nesting_depth(std::string_view xml) {
  std::size_t depth = 0;
  std::size_t deepest = 0;
  for (std::size_t i = 0; i + 1 < xml.size(); ++i) {
    if (xml[i] != '<') continue;
    const char next = xml[i + 1];
    if (next == '/') {
      depth = depth > 0 ? depth - 1 : 0;
    } else if (next != '?' && next != '!') {
      const auto close = xml.find('>', i);
      if (close == std::string_view::npos) break;
      if (xml[close - 1] != '/') deepest = std::max(deepest, ++depth);
      i = close;
    }
  }
  return deepest;
}

constexpr std::size_t kMaxNesting = 64;

Expected<Calibration, std::string> parse_db(std::string_view xml_text) {
  if (nesting_depth(xml_text) > kMaxNesting) {
    return Unexpected{"elements nest more than " + std::to_string(kMaxNesting) +
                      " deep: not a db.xml (a VeloView calibration nests 6 deep)"};
  }
  pt::ptree tree;
  std::istringstream in{std::string(xml_text)};
  pt::read_xml(in, tree, pt::xml_parser::trim_whitespace);

  auto db = tree.get_child_optional("boost_serialization.DB");
  if (!db) db = tree.get_child_optional("DB");
  const auto points = db ? db->get_child_optional("points_") : boost::none;
  if (!points) {
    return Unexpected{
        std::string("not a db.xml: no DB/points_ element (expected a VeloView calibration: "
                    "boost_serialization/DB/points_/item/px/...)")};
  }
  Issues issues;

  double lsb_cm = kDefaultLsbCm;
  if (const auto lsb = db->get_child_optional("distLSB_")) {
    const auto v = detail::parse_number(lsb->data());
    if (!v || *v <= 0.0 || *v > kMaxLsbCm) {
      issues.add("distLSB_ " + detail::quoted(lsb->data()) +
                 " is not a distance in cm between 0 and 1 (Velodyne: 0.2)");
    } else {
      lsb_cm = *v;
    }
  }

  std::size_t item_count = 0;
  for (const auto& entry : *points) item_count += entry.first == "item" ? 1U : 0U;
  const std::size_t lasers = enabled_count(*db, issues).value_or(item_count);
  const auto model = detail::model_for_laser_count(lasers);
  if (!model) {
    issues.add("db.xml has " + std::to_string(lasers) + " enabled lasers: " + detail::supported_counts());
  }
  if (!issues.empty() || !model) return Unexpected{issues.message()};

  detail::LaserTable table(lasers);
  std::size_t index = 0;
  for (const auto& [key, item] : *points) {
    if (key == "item") read_point(item, index++, table, issues);
  }
  Calibration cal = detail::finish(*model, lsb_cm * kCmToM, table, issues);
  if (!issues.empty()) return Unexpected{issues.message()};
  return cal;
}

}  // namespace

Expected<Calibration, std::string> parse_veloview_calibration(std::string_view xml_text) {
  try {
    return parse_db(xml_text);
  } catch (const pt::xml_parser_error& e) {
    return Unexpected{"not valid XML: line " + std::to_string(e.line()) + ": " + e.message()};
  } catch (const std::exception& e) {
    return Unexpected{std::string("cannot read the db.xml: ") + e.what()};
  }
}

}  // namespace fieldguard::velodyne
