// Calibration parsers on files built in the test: units, laser ids, and one specific error per kind of damage.
// The real files (VeloView's HDL-32.xml, VLP-16.xml) and the defaults: velodyne_calibration_test.cpp.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "fieldguard/drivers/velodyne_calibration.hpp"

namespace fieldguard::velodyne {
namespace {

using ::testing::HasSubstr;

using Fields = std::vector<std::pair<std::string, std::string>>;

Fields with(Fields f, const std::string& key, const std::string& value) {
  for (auto& [k, v] : f) {
    if (k == key) {
      v = value;
      return f;
    }
  }
  f.emplace_back(key, value);
  return f;
}

Fields without(Fields f, const std::string& key) {
  std::erase_if(f, [&](const auto& kv) { return kv.first == key; });
  return f;
}

std::string num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

double default_vert_deg(std::size_t id) {
  static const Calibration def = default_calibration(Model::HDL32E);
  return id < def.lasers.size() ? def.lasers[id].vert_deg : 0.0;
}

Fields ros_laser(std::size_t id) {
  return {{"laser_id", std::to_string(id)},
          {"rot_correction", "0.0"},
          {"vert_correction", num(default_vert_deg(id) * std::numbers::pi / 180.0)},
          {"dist_correction", "0.0"},
          {"dist_correction_x", "0.0"},
          {"dist_correction_y", "0.0"},
          {"vert_offset_correction", "0.0"},
          {"horiz_offset_correction", "0.0"},
          {"focal_distance", "0.0"},
          {"focal_slope", "0.0"}};
}

std::vector<Fields> ros_lasers(std::size_t n) {
  std::vector<Fields> v;
  for (std::size_t i = 0; i < n; ++i) v.push_back(ros_laser(i));
  return v;
}

std::string ros_yaml(const std::vector<Fields>& lasers, const std::string& head = "num_lasers: 32\n") {
  std::string out = head + "lasers:\n";
  for (const auto& l : lasers) {
    out += "- {";
    for (std::size_t k = 0; k < l.size(); ++k) out += (k ? ", " : "") + l[k].first + ": " + l[k].second;
    out += "}\n";
  }
  return out;
}

Fields db_point(std::size_t id) {
  return {{"id_", std::to_string(id)},
          {"rotCorrection_", "0"},
          {"vertCorrection_", num(default_vert_deg(id))},
          {"distCorrection_", "0"},
          {"distCorrectionX_", "0"},
          {"distCorrectionY_", "0"},
          {"vertOffsetCorrection_", "0"},
          {"horizOffsetCorrection_", "0"},
          {"focalDistance_", "0"},
          {"focalSlope_", "0"}};
}

std::vector<Fields> db_points(std::size_t n) {
  std::vector<Fields> v;
  for (std::size_t i = 0; i < n; ++i) v.push_back(db_point(i));
  return v;
}

// A db.xml like VeloView's; `enabled` lists the enabled_ items (none: no enabled_ element).
std::string db_xml(const std::vector<Fields>& points, const std::vector<int>& enabled) {
  std::string out =
      "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"yes\" ?>\n<!DOCTYPE boost_serialization>\n"
      "<boost_serialization signature=\"serialization::archive\" version=\"4\">\n"
      "<DB class_id=\"0\" tracking_level=\"1\" version=\"0\" object_id=\"_0\">\n<distLSB_>0.2</distLSB_>\n";
  if (!enabled.empty()) {
    out += "<enabled_><count>" + std::to_string(enabled.size()) + "</count>";
    for (const int e : enabled) out += "<item>" + std::to_string(e) + "</item>";
    out += "</enabled_>\n";
  }
  out += "<points_ class_id=\"7\" tracking_level=\"0\" version=\"0\"><count>" + std::to_string(points.size()) +
         "</count><item_version>1</item_version>\n";
  for (const auto& p : points) {
    out += "<item><px>";
    for (const auto& [k, v] : p) out += "<" + k + ">" + v + "</" + k + ">";
    out += "</px></item>\n";
  }
  return out + "</points_>\n</DB>\n</boost_serialization>\n";
}

std::vector<int> enabled_run(std::size_t on, std::size_t total) {
  std::vector<int> e(total, 0);
  std::fill_n(e.begin(), on, 1);
  return e;
}

// 16 enabled, then a hole, then slot 20 enabled.
std::vector<int> with_gap() {
  std::vector<int> e = enabled_run(16, 64);
  e[20] = 1;
  return e;
}

TEST(VelodyneCalibration, RosYamlUnitsAndLaserIds) {
  auto lasers = ros_lasers(16);
  std::reverse(lasers.begin(), lasers.end());             // stored by laser_id, not by position
  lasers[0] = with(lasers[0], "rot_correction", "-0.1");  // laser_id 15
  lasers[0] = with(lasers[0], "dist_correction", "1.25");
  lasers[0] = with(lasers[0], "vert_offset_correction", "0.0112");
  lasers[0] = without(lasers[0], "horiz_offset_correction");  // optional
  const auto cal = parse_ros_calibration(ros_yaml(lasers, "num_lasers: 16\ndistance_resolution: 0.004\n"));
  ASSERT_TRUE(cal) << cal.error();
  EXPECT_EQ(cal->model, Model::VLP16);
  EXPECT_DOUBLE_EQ(cal->distance_resolution_m, 0.004);
  EXPECT_NEAR(cal->lasers[15].rot_deg, -5.729577951308232, 1e-12);
  EXPECT_DOUBLE_EQ(cal->lasers[15].dist_m, 1.25);
  EXPECT_DOUBLE_EQ(cal->lasers[15].vert_offset_m, 0.0112);
  EXPECT_EQ(cal->lasers[15].horiz_offset_m, 0.0);
  EXPECT_NEAR(cal->lasers[15].vert_deg, default_vert_deg(15), 1e-9);
  EXPECT_NEAR(cal->lasers[0].vert_deg, default_vert_deg(0), 1e-9);
}

TEST(VelodyneCalibration, RosYamlUsesTheFirstNumLasersEntries) {
  // ROS's own 32db.yaml lists 64 lasers with num_lasers: 32.
  const auto cal = parse_ros_calibration(ros_yaml(ros_lasers(64)));
  ASSERT_TRUE(cal) << cal.error();
  EXPECT_EQ(cal->lasers.size(), 32U);
  EXPECT_DOUBLE_EQ(cal->distance_resolution_m, 0.002);  // absent from older files
}

TEST(VelodyneCalibration, DbXmlUnitsAreCentimetres) {
  auto points = db_points(32);
  points[5] = with(points[5], "distCorrection_", "120.5");
  points[5] = with(points[5], "vertOffsetCorrection_", "2.5");
  points[5] = with(points[5], "horizOffsetCorrection_", "-2.6");
  points[5] = with(points[5], "distCorrectionX_", "118");
  points[5] = with(points[5], "rotCorrection_", "-3.5");
  points[5] = without(points[5], "focalSlope_");
  const auto cal = parse_veloview_calibration(db_xml(points, {}));  // no enabled_: the item count decides
  ASSERT_TRUE(cal) << cal.error();
  EXPECT_EQ(cal->model, Model::HDL32E);
  EXPECT_NEAR(cal->lasers[5].dist_m, 1.205, 1e-12);
  EXPECT_NEAR(cal->lasers[5].vert_offset_m, 0.025, 1e-12);
  EXPECT_NEAR(cal->lasers[5].horiz_offset_m, -0.026, 1e-12);
  EXPECT_NEAR(cal->lasers[5].dist_x_m, 1.18, 1e-12);
  EXPECT_DOUBLE_EQ(cal->lasers[5].rot_deg, -3.5);
}

enum class Format { Ros, Db };

struct Malformed {
  const char* name;
  Format format;
  std::string text;
  const char* message;  // expected in the error
};

std::string repeated(const std::string& s, int n) {
  std::string out;
  for (int i = 0; i < n; ++i) out += s;
  return out;
}

std::vector<Malformed> malformed_cases() {
  auto missing_vert = ros_lasers(32);
  missing_vert[7] = without(missing_vert[7], "vert_correction");
  auto word_vert = ros_lasers(32);
  word_vert[3] = with(word_vert[3], "vert_correction", "abc");
  auto degrees = ros_lasers(32);
  degrees[0] = with(degrees[0], "vert_correction", "-30.67");
  auto dup_id = ros_lasers(32);
  dup_id[5] = with(dup_id[5], "laser_id", "4");
  auto far_id = ros_lasers(32);
  far_id[2] = with(far_id[2], "laser_id", "40");
  auto list_value = ros_lasers(32);
  list_value[9] = with(list_value[9], "dist_correction", "[1, 2]");
  auto db_missing_vert = db_points(32);
  db_missing_vert[7] = without(db_missing_vert[7], "vertCorrection_");
  auto db_word = db_points(32);
  db_word[3] = with(db_word[3], "distCorrection_", "12cm");
  auto db_dup = db_points(33);
  db_dup[32] = with(db_dup[32], "id_", "0");

  return {
      {"RosNotYaml", Format::Ros, "lasers: [{laser_id: 0,\n  vert_correction: }\n]]", "not valid YAML: line"},
      {"RosNotAMap", Format::Ros, "just some text", "not a ROS calibration YAML"},
      {"RosEmpty", Format::Ros, "", "not a ROS calibration YAML"},
      {"RosNoLasers", Format::Ros, "num_lasers: 32\ndistance_resolution: 0.002\n", "lasers missing"},
      {"RosLasersNotAList", Format::Ros, "num_lasers: 32\nlasers: 7\n", "lasers is not a list (line 2)"},
      {"RosNoNumLasers", Format::Ros, ros_yaml(ros_lasers(32), ""), "num_lasers missing"},
      {"RosUnsupportedCount", Format::Ros, ros_yaml(ros_lasers(64), "num_lasers: 64\n"),
       "num_lasers 64: only 32 (HDL-32E) and 16 (VLP-16) lasers are supported"},
      {"RosTooFewLasers", Format::Ros, ros_yaml(ros_lasers(31)), "32 lasers expected for HDL-32E, found 31"},
      {"RosMissingField", Format::Ros, ros_yaml(missing_vert), "laser 7: vert_correction missing (line 10)"},
      {"RosNonNumericField", Format::Ros, ros_yaml(word_vert), "laser 3: vert_correction is not a number: 'abc'"},
      {"RosListAsNumber", Format::Ros, ros_yaml(list_value), "laser 9: dist_correction is not a number"},
      {"RosDegreesNotRadians", Format::Ros, ros_yaml(degrees), "laser 0: vert_correction -30.67 is beyond +-pi/2"},
      {"RosDuplicateId", Format::Ros, ros_yaml(dup_id), "laser 5: laser_id 4 appears twice"},
      {"RosIdOutOfRange", Format::Ros, ros_yaml(far_id), "laser 2: laser_id 40 is out of range 0..31"},
      {"RosBadResolution", Format::Ros, ros_yaml(ros_lasers(32), "num_lasers: 32\ndistance_resolution: 0.2\n"),
       "distance_resolution '0.2' is not a distance in metres"},
      {"DbNotXml", Format::Db, "this is <not xml", "not valid XML"},
      {"DbNoDb", Format::Db, "<boost_serialization><Other/></boost_serialization>",
       "not a db.xml: no DB/points_ element"},
      {"DbNoPoints", Format::Db, "<boost_serialization><DB><distLSB_>0.2</distLSB_></DB></boost_serialization>",
       "not a db.xml: no DB/points_ element"},
      {"DbUnsupportedCount", Format::Db, db_xml(db_points(31), {}),
       "db.xml has 31 enabled lasers: only 32 (HDL-32E) and 16 (VLP-16) lasers are supported"},
      {"DbTooFewPoints", Format::Db, db_xml(db_points(31), enabled_run(32, 64)),
       "32 lasers expected for HDL-32E, found 31 (missing laser id 31)"},
      {"DbMissingField", Format::Db, db_xml(db_missing_vert, {}), "laser 7: vertCorrection_ missing"},
      {"DbNonNumericField", Format::Db, db_xml(db_word, {}), "laser 3: distCorrection_ is not a number: '12cm'"},
      {"DbDuplicateId", Format::Db, db_xml(db_dup, enabled_run(32, 33)), "laser 32: id_ 0 appears twice"},
      {"DbEnabledGap", Format::Db, db_xml(db_points(32), with_gap()),
       "enabled_ item 20 is enabled after disabled laser 16"},
      {"DbNestedTooDeep", Format::Db, repeated("<a>", 20000), "elements nest more than 64 deep"},
  };
}

class VelodyneCalibrationMalformed : public ::testing::TestWithParam<Malformed> {};

TEST_P(VelodyneCalibrationMalformed, GivesASpecificError) {
  const Malformed& c = GetParam();
  const auto cal = c.format == Format::Ros ? parse_ros_calibration(c.text) : parse_veloview_calibration(c.text);
  ASSERT_FALSE(cal) << "parsed: " << c.name;
  EXPECT_THAT(cal.error(), HasSubstr(c.message));
}

INSTANTIATE_TEST_SUITE_P(Files, VelodyneCalibrationMalformed, ::testing::ValuesIn(malformed_cases()),
                         [](const auto& tp) { return std::string(tp.param.name); });

}  // namespace
}  // namespace fieldguard::velodyne
