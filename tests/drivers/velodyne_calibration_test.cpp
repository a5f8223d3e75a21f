// Built-in tables, ring assignment and the real calibration files (tests/data/PROVENANCE.txt).
// Synthetic files and the error messages: velodyne_calibration_synthetic_test.cpp.

#include "fieldguard/drivers/velodyne_calibration.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace fieldguard::velodyne {
namespace {

using ::testing::HasSubstr;

std::string read_text(const std::string& name) {
  std::ifstream in(std::string(FIELDGUARD_TEST_DATA) + "/" + name, std::ios::binary);
  EXPECT_TRUE(in) << "cannot open " << name;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<double> vert_of(const Calibration& cal) {
  std::vector<double> v;
  for (const auto& l : cal.lasers) v.push_back(l.vert_deg);
  return v;
}

// ---- defaults and rings ----

TEST(VelodyneCalibration, Hdl32eDefaultFollowsTheManualTable) {
  const Calibration cal = default_calibration(Model::HDL32E);
  EXPECT_EQ(cal.model, Model::HDL32E);
  EXPECT_DOUBLE_EQ(cal.distance_resolution_m, 0.002);
  ASSERT_EQ(cal.lasers.size(), 32U);
  // Slots alternate between the lower and the upper half of the fan (protocols.md §1.5).
  EXPECT_DOUBLE_EQ(cal.lasers[0].vert_deg, -30.67);
  EXPECT_DOUBLE_EQ(cal.lasers[1].vert_deg, -9.33);
  EXPECT_DOUBLE_EQ(cal.lasers[14].vert_deg, -21.33);
  EXPECT_DOUBLE_EQ(cal.lasers[15].vert_deg, 0.0);
  EXPECT_DOUBLE_EQ(cal.lasers[16].vert_deg, -20.0);
  EXPECT_DOUBLE_EQ(cal.lasers[30].vert_deg, -10.67);
  EXPECT_DOUBLE_EQ(cal.lasers[31].vert_deg, 10.67);
  for (const auto& l : cal.lasers) {
    EXPECT_EQ(l.rot_deg, 0.0);
    EXPECT_EQ(l.dist_m, 0.0);
  }
  ASSERT_EQ(cal.ring_of_laser.size(), 32U);
  // Even slots are the 16 lowest lasers in order, odd slots the 16 upper ones.
  for (std::size_t slot = 0; slot < 32; ++slot) {
    const int expected = slot % 2 == 0 ? static_cast<int>(slot / 2) : 16 + static_cast<int>(slot / 2);
    EXPECT_EQ(cal.ring_of_laser[slot], expected) << "slot " << slot;
  }
}

TEST(VelodyneCalibration, Vlp16DefaultFollowsTheManualTable) {
  const Calibration cal = default_calibration(Model::VLP16);
  EXPECT_EQ(cal.model, Model::VLP16);
  EXPECT_EQ(vert_of(cal), (std::vector<double>{-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15}));
  EXPECT_EQ(cal.ring_of_laser, (std::vector<int>{0, 8, 1, 9, 2, 10, 3, 11, 4, 12, 5, 13, 6, 14, 7, 15}));
}

TEST(VelodyneCalibration, NoDefaultForAnUnknownModel) {
  EXPECT_THROW((void)default_calibration(Model::Unknown), std::invalid_argument);
}

TEST(VelodyneCalibration, RingsRankTheAnglesAndBreakTiesByLaserIndex) {
  Calibration cal;
  for (const double v : {1.0, 0.0, 1.0, -1.0, 0.0}) cal.lasers.push_back(LaserCorrection{.vert_deg = v});
  assign_rings(cal);
  EXPECT_EQ(cal.ring_of_laser, (std::vector<int>{3, 1, 4, 0, 2}));
}

// ---- real files ----

TEST(VelodyneCalibration, VeloViewHdl32XmlMatchesTheDefaultTable) {
  const auto cal = parse_veloview_calibration(read_text("HDL-32.xml"));
  ASSERT_TRUE(cal) << cal.error();
  const Calibration def = default_calibration(Model::HDL32E);
  EXPECT_EQ(cal->model, Model::HDL32E);
  EXPECT_DOUBLE_EQ(cal->distance_resolution_m, 0.002);  // distLSB_ 0.2 cm
  ASSERT_EQ(cal->lasers.size(), 32U);
  for (std::size_t i = 0; i < 32; ++i) {
    EXPECT_NEAR(cal->lasers[i].vert_deg, def.lasers[i].vert_deg, 0.01) << "laser " << i;
    EXPECT_EQ(cal->lasers[i].rot_deg, 0.0);
    EXPECT_EQ(cal->lasers[i].dist_m, 0.0);
    EXPECT_EQ(cal->lasers[i].vert_offset_m, 0.0);
  }
  EXPECT_NEAR(cal->lasers[1].vert_deg, -9.3299999, 1e-12);  // the file's value, not the table's
  EXPECT_EQ(cal->ring_of_laser, def.ring_of_laser);
}

TEST(VelodyneCalibration, VeloViewVlp16XmlUsesOnlyTheEnabledLasers) {
  // 64 slots, 16 enabled; slots 16..31 repeat 0..15 and 32..63 are zero.
  const auto cal = parse_veloview_calibration(read_text("VLP-16.xml"));
  ASSERT_TRUE(cal) << cal.error();
  const Calibration def = default_calibration(Model::VLP16);
  EXPECT_EQ(cal->model, Model::VLP16);
  EXPECT_EQ(vert_of(*cal), vert_of(def));
  EXPECT_EQ(cal->ring_of_laser, def.ring_of_laser);
}

TEST(VelodyneCalibration, RosYamlFixtureMatchesTheDefaultTable) {
  const auto cal = parse_ros_calibration(read_text("hdl32e_ros_calibration.yaml"));
  ASSERT_TRUE(cal) << cal.error();
  const Calibration def = default_calibration(Model::HDL32E);
  EXPECT_EQ(cal->model, Model::HDL32E);
  EXPECT_DOUBLE_EQ(cal->distance_resolution_m, 0.002);
  ASSERT_EQ(cal->lasers.size(), 32U);
  for (std::size_t i = 0; i < 32; ++i) EXPECT_NEAR(cal->lasers[i].vert_deg, def.lasers[i].vert_deg, 1e-9) << i;
  EXPECT_EQ(cal->ring_of_laser, def.ring_of_laser);
}

TEST(VelodyneCalibration, FilesOfTheOtherFormatAreRejected) {
  const auto yaml_as_xml = parse_veloview_calibration(read_text("hdl32e_ros_calibration.yaml"));
  ASSERT_FALSE(yaml_as_xml);
  EXPECT_THAT(yaml_as_xml.error(), HasSubstr("XML"));
  const auto xml_as_yaml = parse_ros_calibration(read_text("HDL-32.xml"));
  ASSERT_FALSE(xml_as_yaml);
  EXPECT_THAT(xml_as_yaml.error(), HasSubstr("YAML"));
}

}  // namespace
}  // namespace fieldguard::velodyne
