#include "fieldguard/app/config.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

namespace fieldguard::app {
namespace {

namespace fs = std::filesystem;

bool has_issue(const LoadResult& r, const std::string& key_path, const std::string& words, int line = -1) {
  return std::any_of(r.issues.begin(), r.issues.end(), [&](const ConfigIssue& i) {
    return i.key_path == key_path && i.message.find(words) != std::string::npos && (line < 0 || i.line == line);
  });
}

std::string dump(const LoadResult& r) {
  std::string s;
  for (const auto& i : r.issues) s += i.to_string() + "\n";
  return s;
}

TEST(ConfigFiles, EveryShippedFileIsValid) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(FIELDGUARD_SOURCE_DIR) / "config")) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    const auto r = load_config_file(entry.path().string());
    EXPECT_TRUE(r.ok()) << entry.path() << "\n" << dump(r);
  }
  EXPECT_GE(count, 2);
}

TEST(ConfigFiles, PublishedReproducesThePublishedPipeline) {
  const auto r = load_config_file(std::string(FIELDGUARD_SOURCE_DIR) + "/config/published.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& p = r.config.perception;
  EXPECT_DOUBLE_EQ(p.voxel.leaf_m, 0.15);
  EXPECT_EQ(p.roi.min, (std::array<double, 3>{-10, -10, -1.5}));
  EXPECT_EQ(p.roi.max, (std::array<double, 3>{50, 10, 6}));
  EXPECT_EQ(p.body.min, (std::array<double, 3>{-5, -1.5, -1.5}));
  EXPECT_EQ(p.body.max, (std::array<double, 3>{0.4, 1.5, 1.5}));
  EXPECT_EQ(p.ground.method, perception::GroundMethod::Ransac);
  EXPECT_EQ(p.ground.ransac.iterations, 60);
  EXPECT_DOUBLE_EQ(p.ground.ransac.distance_m, 0.3);
  EXPECT_DOUBLE_EQ(p.cluster.tolerance_m, 0.6);
  EXPECT_EQ(p.filters.min_points, 10);
  EXPECT_EQ(p.filters.max_points, 240);
  EXPECT_DOUBLE_EQ(p.filters.min_volume_m3, 0.06);
  EXPECT_DOUBLE_EQ(p.filters.max_volume_m3, 1.2);
  EXPECT_EQ(r.config.lidar.model, velodyne::Model::HDL32E);
}

TEST(ConfigLoad, ReadsEveryLidarKey) {
  const auto r = load_config_text(R"(
lidar:
  model: VLP-16
  data_port: 2369
  position_port: 8309
  timestamp_reference: first_firing
  min_range_m: 1.0
  max_range_m: 90
  rotation_cut_deg: 180
  mounting: {x_m: 1, y_m: -0.5, z_m: 2, roll_deg: 1, pitch_deg: -2, yaw_deg: 3}
)",
                                  "t.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& l = r.config.lidar;
  EXPECT_EQ(l.model, velodyne::Model::VLP16);
  EXPECT_EQ(l.data_port, 2369);
  EXPECT_EQ(l.position_port, 8309);
  EXPECT_EQ(l.timestamp_reference, velodyne::TimestampReference::FirstFiring);
  EXPECT_DOUBLE_EQ(l.min_range_m, 1.0);
  EXPECT_DOUBLE_EQ(l.max_range_m, 90.0);
  EXPECT_DOUBLE_EQ(l.rotation_cut_deg, 180.0);
  EXPECT_DOUBLE_EQ(l.mounting.y_m, -0.5);
  EXPECT_DOUBLE_EQ(l.mounting.yaw_deg, 3.0);
}

// Every kind of problem in one file: all are reported at once, each with its line and key path.
TEST(ConfigLoad, ReportsEveryProblemAtOnceWithLineAndKey) {
  const std::string text =
      "lidar:\n"                                   // 1
      "  model: HDL-64\n"                          // 2  not one of the choices
      "  data_port: 70000\n"                       // 3  out of range
      "  min_range_m: fast\n"                      // 4  wrong type
      "  colour: red\n"                            // 5  unknown key
      "perception:\n"                              // 6
      "  roi:\n"                                   // 7
      "    min: [10, -10, -1.5]\n"                 // 8
      "    max: [5, 10, 6]\n"                      // 9  min x > max x
      "  body:\n"                                  // 10
      "    min: [-5, -1.5, -1.5]\n"                // 11
      "    max: [0.4, 1.5, 9]\n"                   // 12 body outside the ROI
      "  filters:\n"                               // 13
      "    min_points: 300\n"                      // 14
      "    max_points: 240\n"                      // 15 min > max
      "  cluster: {tolerance_m: [1, 2]}\n";        // 16 a list where a number belongs
  const auto r = load_config_text(text, "bad.yaml");
  EXPECT_TRUE(has_issue(r, "lidar.model", "not one of auto, HDL-32E, VLP-16", 2)) << dump(r);
  EXPECT_TRUE(has_issue(r, "lidar.data_port", "out of range", 3)) << dump(r);
  EXPECT_TRUE(has_issue(r, "lidar.min_range_m", "expected a number", 4)) << dump(r);
  EXPECT_TRUE(has_issue(r, "lidar.colour", "unknown key", 5)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.roi", "min x must be less than max x", 9)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.body", "outside perception.roi", 11)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.filters.max_points", "must not be less than min_points", 15)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.cluster.tolerance_m", "expected a number", 16)) << dump(r);
  EXPECT_EQ(r.issues.size(), 8U) << dump(r);
  EXPECT_EQ(r.issues.front().to_string().rfind("bad.yaml:", 0), 0U);
}

struct BadCase {
  const char* name;
  const char* text;
  const char* key_path;
  const char* words;
};

class ConfigBad : public ::testing::TestWithParam<BadCase> {};

TEST_P(ConfigBad, GivesTheSpecificProblem) {
  const auto& c = GetParam();
  const auto r = load_config_text(c.text, "x.yaml");
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(has_issue(r, c.key_path, c.words)) << dump(r);
}

INSTANTIATE_TEST_SUITE_P(
    Kinds, ConfigBad,
    ::testing::Values(
        BadCase{"not_yaml", "lidar: [1, 2\n", "", "not valid YAML"},
        BadCase{"empty", "", "", "empty"},
        BadCase{"top_level_list", "- 1\n- 2\n", "", "expected a mapping"},
        BadCase{"unknown_top", "lidr: {}\n", "lidr", "unknown key; known keys here: lidar, perception"},
        BadCase{"duplicate", "lidar:\n  data_port: 1\n  data_port: 2\n", "lidar.data_port", "given twice"},
        BadCase{"section_scalar", "perception: 3\n", "perception", "expected a mapping"},
        BadCase{"vec_short", "perception: {roi: {min: [1, 2]}}\n", "perception.roi.min", "list of 3 numbers"},
        BadCase{"vec_item", "perception: {roi: {min: [1, a, 2]}}\n", "perception.roi.min[1]", "expected a number"},
        BadCase{"int_float", "perception: {filters: {min_points: 2.5}}\n", "perception.filters.min_points",
                "whole number"},
        BadCase{"negative_leaf", "perception: {voxel: {leaf_m: -1}}\n", "perception.voxel.leaf_m", "out of range"},
        BadCase{"volume_order", "perception: {filters: {min_volume_m3: 2, max_volume_m3: 1}}\n",
                "perception.filters.max_volume_m3", "must not be less"},
        BadCase{"ranges", "lidar: {min_range_m: 50, max_range_m: 10}\n", "lidar.max_range_m", "greater than"},
        BadCase{"same_ports", "lidar: {data_port: 2368, position_port: 2368}\n", "lidar.position_port", "same"},
        BadCase{"ground_method", "perception: {ground: {method: magic}}\n", "perception.ground.method",
                "not one of ransac"},
        BadCase{"ransac_iter", "perception: {ground: {ransac: {iterations: 0}}}\n",
                "perception.ground.ransac.iterations", "out of range"},
        BadCase{"missing_calibration", "lidar: {calibration_file: /nonexistent/cal.xml}\n", "lidar.calibration_file",
                "cannot read"},
        BadCase{"mount_key", "lidar: {mounting: {height: 2}}\n", "lidar.mounting.height", "unknown key"}),
    [](const ::testing::TestParamInfo<BadCase>& p) { return std::string(p.param.name); });

TEST(ConfigLoad, MissingFileSaysSo) {
  const auto r = load_config_file("/nonexistent/fieldguard.yaml");
  ASSERT_EQ(r.issues.size(), 1U);
  EXPECT_NE(r.issues[0].message.find("no such file"), std::string::npos);
}

TEST(ConfigLoad, DirectoryIsNotAConfig) {
  const auto r = load_config_file(FIELDGUARD_SOURCE_DIR);
  ASSERT_EQ(r.issues.size(), 1U);
  EXPECT_NE(r.issues[0].message.find("directory"), std::string::npos) << r.issues[0].message;
}

TEST(ConfigLoad, CalibrationFileRelativeToTheConfigAndCheckedAgainstTheModel) {
  const fs::path dir = fs::temp_directory_path() / "fieldguard_config_test";
  fs::create_directories(dir);
  fs::copy_file(fs::path(FIELDGUARD_TEST_DATA) / "HDL-32.xml", dir / "HDL-32.xml", fs::copy_options::overwrite_existing);
  {
    std::ofstream(dir / "good.yaml") << "lidar: {model: auto, calibration_file: HDL-32.xml}\n";
    std::ofstream(dir / "mismatch.yaml") << "lidar: {model: VLP-16, calibration_file: HDL-32.xml}\n";
  }
  const auto good = load_config_file((dir / "good.yaml").string());
  ASSERT_TRUE(good.ok()) << dump(good);
  EXPECT_TRUE(good.config.lidar.has_calibration);
  EXPECT_EQ(good.config.lidar.calibration.model, velodyne::Model::HDL32E);
  const auto bad = load_config_file((dir / "mismatch.yaml").string());
  EXPECT_TRUE(has_issue(bad, "lidar.calibration_file", "HDL-32E calibration but lidar.model is VLP-16")) << dump(bad);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace fieldguard::app
