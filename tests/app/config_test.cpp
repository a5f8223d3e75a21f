#include "fieldguard/config/config.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/config_issues.hpp"

namespace fieldguard::app {
namespace {

namespace fs = std::filesystem;

using testing::dump;
using testing::has_issue;

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
  EXPECT_EQ(r.config.lidar.model, lidar3d::Model::HDL32E);
  // Nothing of ours is switched on.
  EXPECT_DOUBLE_EQ(p.voxel.coarse_from_m, 0.0);
  EXPECT_EQ(p.cluster.method, perception::ClusterMethod::Fixed);
  EXPECT_EQ(p.cluster.structure, perception::ClusterStructure::KdTree);
  EXPECT_DOUBLE_EQ(p.filters.min_height_m, 0.0);
  EXPECT_DOUBLE_EQ(p.filters.min_points_full_range_m, 0.0);
  EXPECT_EQ(p.cluster.absorb_max_points, 0);
  EXPECT_EQ(p.cluster.join_float_height_m, 0.0);
  EXPECT_EQ(p.cluster.split_min_length_m, 0.0);
  EXPECT_FALSE(p.near_field.enabled);  // the published method had no 2D LiDAR
  EXPECT_FALSE(p.hold.enabled);        // nor carried anything from one rotation to the next
  // And it is what the perception module calls the published method.
  const auto pub = perception::published_params();
  EXPECT_EQ(p.ground.method, pub.ground.method);
  EXPECT_EQ(p.ground.ransac.iterations, pub.ground.ransac.iterations);
  EXPECT_EQ(p.cluster.method, pub.cluster.method);
  EXPECT_EQ(p.cluster.absorb_max_points, pub.cluster.absorb_max_points);
  EXPECT_EQ(p.cluster.join_float_height_m, pub.cluster.join_float_height_m);
  EXPECT_EQ(p.cluster.split_min_length_m, pub.cluster.split_min_length_m);
  EXPECT_EQ(p.filters.max_points, pub.filters.max_points);
  EXPECT_DOUBLE_EQ(p.filters.min_volume_m3, pub.filters.min_volume_m3);
  EXPECT_EQ(p.near_field.enabled, pub.near_field.enabled);
  EXPECT_EQ(p.hold.enabled, pub.hold.enabled);
}

TEST(ConfigFiles, FieldguardUsesTheFieldMethods) {
  const auto r = load_config_file(std::string(FIELDGUARD_SOURCE_DIR) + "/config/fieldguard.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& p = r.config.perception;
  EXPECT_EQ(p.ground.method, perception::GroundMethod::Zones);
  EXPECT_EQ(p.cluster.method, perception::ClusterMethod::Anisotropic);
  EXPECT_EQ(p.cluster.structure, perception::ClusterStructure::Grid);
  EXPECT_GT(p.filters.min_height_m, 0.0);
  EXPECT_DOUBLE_EQ(p.ground.zones.sensor_height_m, r.config.lidar.mounting.z_m);
  EXPECT_EQ(p.ground.zones.rings.size() + 1, p.ground.zones.edges_m.size());
}

// The perception module's defaults are fieldguard.yaml's (tests and benchmarks use PipelineParams{}): every
// value the file sets equals the default.
TEST(ConfigFiles, FieldguardIsThePerceptionDefaults) {
  const auto r = load_config_file(std::string(FIELDGUARD_SOURCE_DIR) + "/config/fieldguard.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& p = r.config.perception;
  const perception::PipelineParams d;
  EXPECT_EQ(p.voxel.leaf_m, d.voxel.leaf_m);
  EXPECT_EQ(p.voxel.coarse_from_m, d.voxel.coarse_from_m);
  EXPECT_EQ(p.voxel.max_leaf_m, d.voxel.max_leaf_m);
  EXPECT_EQ(p.roi.min, d.roi.min);
  EXPECT_EQ(p.roi.max, d.roi.max);
  EXPECT_EQ(p.body.min, d.body.min);
  EXPECT_EQ(p.body.max, d.body.max);
  EXPECT_EQ(p.ground.method, d.ground.method);
  EXPECT_EQ(p.ground.ransac.iterations, d.ground.ransac.iterations);
  EXPECT_EQ(p.ground.ransac.distance_m, d.ground.ransac.distance_m);
  EXPECT_EQ(p.ground.ransac.seed, d.ground.ransac.seed);
  const auto &z = p.ground.zones, &dz = d.ground.zones;
  EXPECT_EQ(z.edges_m, dz.edges_m);
  EXPECT_EQ(z.rings, dz.rings);
  EXPECT_EQ(z.sectors, dz.sectors);
  EXPECT_EQ(z.min_bin_points, dz.min_bin_points);
  EXPECT_EQ(z.seed_lowest, dz.seed_lowest);
  EXPECT_EQ(z.seed_margin_m, dz.seed_margin_m);
  EXPECT_EQ(z.fit_distance_m, dz.fit_distance_m);
  EXPECT_EQ(z.fit_iterations, dz.fit_iterations);
  EXPECT_EQ(z.ground_threshold_m, dz.ground_threshold_m);
  EXPECT_EQ(z.max_slope_deg, dz.max_slope_deg);
  EXPECT_EQ(z.max_tilt_deg, dz.max_tilt_deg);
  EXPECT_EQ(z.max_step_m, dz.max_step_m);
  EXPECT_EQ(z.max_slope_change_deg, dz.max_slope_change_deg);
  EXPECT_EQ(z.min_spread_m, dz.min_spread_m);
  EXPECT_EQ(z.max_extrapolation_m, dz.max_extrapolation_m);
  EXPECT_EQ(z.max_below_m, dz.max_below_m);
  EXPECT_EQ(z.sensor_height_m, dz.sensor_height_m);  // lidar.mounting.z_m 0.95
  EXPECT_EQ(p.ground.context_m, d.ground.context_m);
  EXPECT_EQ(p.cluster.method, d.cluster.method);
  EXPECT_EQ(p.cluster.structure, d.cluster.structure);
  EXPECT_EQ(p.cluster.tolerance_m, d.cluster.tolerance_m);
  EXPECT_EQ(p.cluster.beam_spacing_deg, d.cluster.beam_spacing_deg);
  EXPECT_EQ(p.cluster.beam_factor, d.cluster.beam_factor);
  EXPECT_EQ(p.cluster.max_tolerance_m, d.cluster.max_tolerance_m);
  EXPECT_EQ(p.cluster.horizontal_beam_factor, d.cluster.horizontal_beam_factor);
  EXPECT_EQ(p.cluster.horizontal_max_tolerance_m, d.cluster.horizontal_max_tolerance_m);
  EXPECT_EQ(p.cluster.absorb_max_points, d.cluster.absorb_max_points);
  EXPECT_EQ(p.cluster.absorb_margin_m, d.cluster.absorb_margin_m);
  EXPECT_EQ(p.cluster.join_float_height_m, d.cluster.join_float_height_m);
  EXPECT_EQ(p.cluster.join_fragment_factor, d.cluster.join_fragment_factor);
  EXPECT_EQ(p.cluster.join_fragment_gap_m, d.cluster.join_fragment_gap_m);
  EXPECT_EQ(p.cluster.join_gap_m, d.cluster.join_gap_m);
  EXPECT_EQ(p.cluster.join_stacked, d.cluster.join_stacked);
  EXPECT_EQ(p.cluster.join_stack_margin_m, d.cluster.join_stack_margin_m);
  EXPECT_EQ(p.cluster.split_min_length_m, d.cluster.split_min_length_m);
  EXPECT_EQ(p.cluster.split_min_part_m, d.cluster.split_min_part_m);
  EXPECT_EQ(p.cluster.split_gap_ratio, d.cluster.split_gap_ratio);
  EXPECT_EQ(p.cluster.split_min_part_points, d.cluster.split_min_part_points);
  EXPECT_EQ(p.cluster.split_full_range_m, d.cluster.split_full_range_m);
  EXPECT_EQ(p.filters.min_points, d.filters.min_points);
  EXPECT_EQ(p.filters.max_points, d.filters.max_points);
  EXPECT_EQ(p.filters.min_volume_m3, d.filters.min_volume_m3);
  EXPECT_EQ(p.filters.max_volume_m3, d.filters.max_volume_m3);
  EXPECT_EQ(p.filters.min_height_m, d.filters.min_height_m);
  EXPECT_EQ(p.filters.min_points_full_range_m, d.filters.min_points_full_range_m);
  EXPECT_EQ(p.filters.min_points_floor, d.filters.min_points_floor);
  EXPECT_EQ(p.filters.min_height_growth_from_m, d.filters.min_height_growth_from_m);
  EXPECT_EQ(p.filters.min_height_growth_per_m, d.filters.min_height_growth_per_m);
  EXPECT_EQ(p.filters.min_height_growth_max_m, d.filters.min_height_growth_max_m);
  EXPECT_EQ(p.filters.float_min_height_m, d.filters.float_min_height_m);
  EXPECT_EQ(p.filters.float_min_points, d.filters.float_min_points);
  EXPECT_EQ(p.filters.canopy_max_height_m, d.filters.canopy_max_height_m);
  EXPECT_EQ(p.filters.canopy_min_jitter_m, d.filters.canopy_min_jitter_m);
  EXPECT_EQ(p.filters.canopy_min_triples, d.filters.canopy_min_triples);
  EXPECT_EQ(p.filters.canopy_max_gap_m, d.filters.canopy_max_gap_m);
  EXPECT_EQ(p.filters.canopy_needle_depth_m, d.filters.canopy_needle_depth_m);
  EXPECT_EQ(p.filters.canopy_needle_ratio, d.filters.canopy_needle_ratio);
  EXPECT_EQ(p.filters.canopy_surroundings_m, d.filters.canopy_surroundings_m);
  EXPECT_EQ(p.near_field.enabled, d.near_field.enabled);
  EXPECT_EQ(p.near_field.zone.min, d.near_field.zone.min);
  EXPECT_EQ(p.near_field.zone.max, d.near_field.zone.max);
  EXPECT_EQ(p.near_field.max_gap_m, d.near_field.max_gap_m);
  EXPECT_EQ(p.near_field.min_points, d.near_field.min_points);
  EXPECT_EQ(p.near_field.min_height_m, d.near_field.min_height_m);
  EXPECT_EQ(p.hold.enabled, d.hold.enabled);
  EXPECT_EQ(p.hold.max_age_s, d.hold.max_age_s);
  EXPECT_EQ(p.hold.gate_m, d.hold.gate_m);
  EXPECT_EQ(p.hold.min_points, d.hold.min_points);
}

TEST(ConfigLoad, ReadsEveryPerceptionKey) {
  const auto r = load_config_text(R"(
lidar:
  mounting: {z_m: 1.8}
perception:
  voxel: {leaf_m: 0.1, coarse_from_m: 20, max_leaf_m: 0.3}
  ground:
    method: zones
    ransac: {iterations: 100, distance_m: 0.2, seed: 7}
    zones:
      edges_m: [1, 5, 40]
      rings: [3, 6]
      sectors: [8, 24]
      min_bin_points: 5
      seed_lowest: 12
      seed_margin_m: 0.1
      fit_distance_m: 0.12
      fit_iterations: 2
      ground_threshold_m: 0.25
      max_slope_deg: 20
      max_tilt_deg: 8
      max_step_m: 0.3
      max_slope_change_deg: 4
      min_spread_m: 0.7
      max_extrapolation_m: 20
  cluster: {method: adaptive, structure: kdtree, tolerance_m: 0.5, beam_spacing_deg: 2.0, beam_factor: 1.5, max_tolerance_m: 1.0}
  filters: {min_points: 8, max_points: 0, min_volume_m3: 0.01, max_volume_m3: 0, min_height_m: 0.4,
            min_points_full_range_m: 15, min_points_floor: 2}
  near_field: {enabled: false, zone: {min: [1, -3, -2.5], max: [10, 3, 0.5]}, max_gap_m: 0.25, min_points: 4,
               min_height_m: 0.2}
  hold: {enabled: false, max_age_s: 0.25, gate_m: 0.8, min_points: 4}
)",
                                  "t.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& p = r.config.perception;
  EXPECT_DOUBLE_EQ(p.voxel.leaf_m, 0.1);
  EXPECT_DOUBLE_EQ(p.voxel.coarse_from_m, 20.0);
  EXPECT_DOUBLE_EQ(p.voxel.max_leaf_m, 0.3);
  EXPECT_EQ(p.ground.method, perception::GroundMethod::Zones);
  EXPECT_EQ(p.ground.ransac.iterations, 100);
  EXPECT_DOUBLE_EQ(p.ground.ransac.distance_m, 0.2);
  EXPECT_EQ(p.ground.ransac.seed, 7U);
  const auto& z = p.ground.zones;
  EXPECT_EQ(z.edges_m, (std::vector<double>{1, 5, 40}));
  EXPECT_EQ(z.rings, (std::vector<int>{3, 6}));
  EXPECT_EQ(z.sectors, (std::vector<int>{8, 24}));
  EXPECT_EQ(z.min_bin_points, 5);
  EXPECT_EQ(z.seed_lowest, 12);
  EXPECT_DOUBLE_EQ(z.seed_margin_m, 0.1);
  EXPECT_DOUBLE_EQ(z.fit_distance_m, 0.12);
  EXPECT_EQ(z.fit_iterations, 2);
  EXPECT_DOUBLE_EQ(z.ground_threshold_m, 0.25);
  EXPECT_DOUBLE_EQ(z.max_slope_deg, 20.0);
  EXPECT_DOUBLE_EQ(z.max_tilt_deg, 8.0);
  EXPECT_DOUBLE_EQ(z.max_step_m, 0.3);
  EXPECT_DOUBLE_EQ(z.max_slope_change_deg, 4.0);
  EXPECT_DOUBLE_EQ(z.min_spread_m, 0.7);
  EXPECT_DOUBLE_EQ(z.max_extrapolation_m, 20.0);
  EXPECT_DOUBLE_EQ(z.sensor_height_m, 1.8);  // from lidar.mounting.z_m
  const auto& c = p.cluster;
  EXPECT_EQ(c.method, perception::ClusterMethod::Adaptive);
  EXPECT_EQ(c.structure, perception::ClusterStructure::KdTree);
  EXPECT_DOUBLE_EQ(c.tolerance_m, 0.5);
  EXPECT_DOUBLE_EQ(c.beam_spacing_deg, 2.0);
  EXPECT_DOUBLE_EQ(c.beam_factor, 1.5);
  EXPECT_DOUBLE_EQ(c.max_tolerance_m, 1.0);
  const auto& f = p.filters;
  EXPECT_EQ(f.min_points, 8);
  EXPECT_EQ(f.max_points, 0);
  EXPECT_DOUBLE_EQ(f.min_volume_m3, 0.01);
  EXPECT_DOUBLE_EQ(f.max_volume_m3, 0.0);
  EXPECT_DOUBLE_EQ(f.min_height_m, 0.4);
  EXPECT_DOUBLE_EQ(f.min_points_full_range_m, 15.0);
  EXPECT_EQ(f.min_points_floor, 2);
  const auto& nf = p.near_field;
  EXPECT_FALSE(nf.enabled);
  EXPECT_EQ(nf.zone.min, (std::array<double, 3>{1, -3, -2.5}));
  EXPECT_EQ(nf.zone.max, (std::array<double, 3>{10, 3, 0.5}));
  EXPECT_DOUBLE_EQ(nf.max_gap_m, 0.25);
  EXPECT_EQ(nf.min_points, 4);
  EXPECT_DOUBLE_EQ(nf.min_height_m, 0.2);
  const auto& h = p.hold;
  EXPECT_FALSE(h.enabled);
  EXPECT_DOUBLE_EQ(h.max_age_s, 0.25);
  EXPECT_DOUBLE_EQ(h.gate_m, 0.8);
  EXPECT_EQ(h.min_points, 4);
}

// The hold (obstacle_hold.hpp): left out, fieldguard.yaml's values; out of range, each with its line.
TEST(ConfigLoad, TheHoldKeys) {
  const auto d = load_config_text("perception: {}\n", "t.yaml");
  ASSERT_TRUE(d.ok()) << dump(d);
  EXPECT_TRUE(d.config.perception.hold.enabled);
  EXPECT_EQ(d.config.perception.hold.max_age_s, 0.35);
  EXPECT_EQ(d.config.perception.hold.gate_m, 0.3);
  EXPECT_EQ(d.config.perception.hold.min_points, 2);
  const std::string text =
      "perception:\n"          // 1
      "  hold:\n"              // 2
      "    enabled: maybe\n"   // 3 not true or false
      "    max_age_s: -0.1\n"  // 4 out of range
      "    gate_m: 4\n"        // 5 out of range
      "    min_points: 0\n"    // 6 out of range
      "    max_age: 1\n";      // 7 unknown
  const auto r = load_config_text(text, "bad.yaml");
  EXPECT_TRUE(has_issue(r, "perception.hold.enabled", "is not one of", 3)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.hold.max_age_s", "out of range", 4)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.hold.gate_m", "out of range", 5)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.hold.min_points", "out of range", 6)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.hold.max_age", "unknown key", 7)) << dump(r);
  EXPECT_EQ(r.issues.size(), 5U) << dump(r);
}

// 0 switches the upper limits off, so a large minimum with a zero maximum is no contradiction.
TEST(ConfigLoad, ZeroMaximumIsNoLimit) {
  const auto r = load_config_text(
      "perception: {filters: {min_points: 300, max_points: 0, min_volume_m3: 5, max_volume_m3: 0}}\n", "t.yaml");
  EXPECT_TRUE(r.ok()) << dump(r);
}

// Every perception problem at once, each with its line.
TEST(ConfigLoad, ReportsEveryPerceptionProblemWithLine) {
  const std::string text =
      "perception:\n"                                                 // 1
      "  ground:\n"                                                   // 2
      "    method: zones\n"                                           // 3
      "    zones:\n"                                                  // 4
      "      edges_m: [2, 10, 6]\n"                                   // 5  not increasing
      "      rings: [2, 4, 4]\n"                                      // 6  three counts for two zones
      "      sectors: [16, x]\n"                                      // 7  not a number
      "      max_slope_deg: 95\n"                                     // 8  out of range
      "  cluster:\n"                                                  // 9
      "    method: adaptive\n"                                        // 10
      "    tolerance_m: 0.8\n"                                        // 11
      "    max_tolerance_m: 0.5\n"                                    // 12 below tolerance_m
      "    beam_spacing_deg: 5\n"                                     // 13
      "    beam_factor: 9\n"                                          // 14 9 * tan(5 deg): grows too fast
      "  voxel: {leaf_m: 0.2, coarse_from_m: 10, max_leaf_m: 0.1}\n"  // 15 max_leaf < leaf
      "  filters: {min_height_m: -1}\n";                              // 16 out of range
  const auto r = load_config_text(text, "bad.yaml");
  EXPECT_TRUE(has_issue(r, "perception.ground.zones.edges_m", "must increase", 5)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.ground.zones.rings", "one ring count per zone", 6)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.ground.zones.sectors[1]", "expected a whole number", 7)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.ground.zones.max_slope_deg", "out of range", 8)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.cluster.max_tolerance_m", "must not be less than tolerance_m", 12)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.cluster.beam_factor", "below 0.5", 14)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.voxel.max_leaf_m", "must not be less than leaf_m", 15)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.filters.min_height_m", "out of range", 16)) << dump(r);
  EXPECT_EQ(r.issues.size(), 8U) << dump(r);
}

TEST(ConfigLoad, ReadsEveryLidarKey) {
  const auto r = load_config_text(R"(
lidar:
  model: VLP-16
  data_port: 2369
  position_port: 8309
  msop_port: 6700
  difop_port: 7789
  timestamp_reference: first_firing
  min_range_m: 1.0
  max_range_m: 90
  rotation_cut_deg: 180
  mounting: {x_m: 1, y_m: -0.5, z_m: 2, roll_deg: 1, pitch_deg: -2, yaw_deg: 3}
)",
                                  "t.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& l = r.config.lidar;
  EXPECT_EQ(l.model, lidar3d::Model::VLP16);
  EXPECT_EQ(l.data_port, 2369);
  EXPECT_EQ(l.position_port, 8309);
  EXPECT_EQ(l.msop_port, 6700);
  EXPECT_EQ(l.difop_port, 7789);
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
      "lidar:\n"                             // 1
      "  model: HDL-64\n"                    // 2  not one of the choices
      "  data_port: 70000\n"                 // 3  out of range
      "  min_range_m: fast\n"                // 4  wrong type
      "  colour: red\n"                      // 5  unknown key
      "perception:\n"                        // 6
      "  roi:\n"                             // 7
      "    min: [10, -10, -1.5]\n"           // 8
      "    max: [5, 10, 6]\n"                // 9  min x > max x
      "  body:\n"                            // 10
      "    min: [-5, -1.5, -1.5]\n"          // 11
      "    max: [0.4, 1.5, 9]\n"             // 12 body outside the ROI
      "  filters:\n"                         // 13
      "    min_points: 300\n"                // 14
      "    max_points: 240\n"                // 15 min > max
      "  cluster: {tolerance_m: [1, 2]}\n";  // 16 a list where a number belongs
  const auto r = load_config_text(text, "bad.yaml");
  EXPECT_TRUE(has_issue(r, "lidar.model", "not one of auto, HDL-32E, VLP-16, RS-32", 2)) << dump(r);
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
        BadCase{"not_yaml", "lidar: [1, 2\n", "", "not valid YAML"}, BadCase{"empty", "", "", "empty"},
        BadCase{"top_level_list", "- 1\n- 2\n", "", "expected a mapping"},
        BadCase{"unknown_top", "lidr: {}\n", "lidr",
                "unknown key; known keys here: lidar, scan2d, gnss, ahrs, sync, geo, perception"},
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
                "not one of ransac, zones"},
        BadCase{"cluster_method", "perception: {cluster: {method: dbscan}}\n", "perception.cluster.method",
                "not one of fixed, adaptive"},
        BadCase{"cluster_structure", "perception: {cluster: {structure: octree}}\n", "perception.cluster.structure",
                "not one of kdtree, grid"},
        BadCase{"zone_key", "perception: {ground: {zones: {bins: 3}}}\n", "perception.ground.zones.bins",
                "unknown key"},
        BadCase{"zone_edges_short", "perception: {ground: {zones: {edges_m: [2]}}}\n",
                "perception.ground.zones.edges_m", "list of 2 to 17"},
        BadCase{"zone_edges_scalar", "perception: {ground: {zones: {edges_m: 5}}}\n", "perception.ground.zones.edges_m",
                "list of 2 to 17"},
        BadCase{"zone_sectors_zero", "perception: {ground: {zones: {sectors: [16, 0, 48, 64]}}}\n",
                "perception.ground.zones.sectors[1]", "out of range"},
        BadCase{"zone_rings_float", "perception: {ground: {zones: {rings: [2, 4.5, 4, 4]}}}\n",
                "perception.ground.zones.rings[1]", "whole number"},
        BadCase{"zone_sensor_height", "lidar: {mounting: {z_m: 0}}\nperception: {ground: {method: zones}}\n",
                "lidar.mounting.z_m", "height above the ground"},
        BadCase{"max_leaf_bands", "perception: {voxel: {leaf_m: 0.1, coarse_from_m: 10, max_leaf_m: 2}}\n",
                "perception.voxel.max_leaf_m", "15 times"},
        BadCase{"floor_zero", "perception: {filters: {min_points_floor: 0}}\n", "perception.filters.min_points_floor",
                "out of range"},
        BadCase{"full_range_negative", "perception: {filters: {min_points_full_range_m: -3}}\n",
                "perception.filters.min_points_full_range_m", "out of range"},
        BadCase{"surroundings_negative", "perception: {filters: {canopy_surroundings_m: -1}}\n",
                "perception.filters.canopy_surroundings_m", "out of range"},
        BadCase{"ransac_iter", "perception: {ground: {ransac: {iterations: 0}}}\n",
                "perception.ground.ransac.iterations", "out of range"},
        BadCase{"missing_calibration", "lidar: {calibration_file: /nonexistent/cal.xml}\n", "lidar.calibration_file",
                "cannot read"},
        BadCase{"mount_key", "lidar: {mounting: {height: 2}}\n", "lidar.mounting.height", "unknown key"},
        BadCase{"near_gap_zero", "perception: {near_field: {max_gap_m: 0}}\n", "perception.near_field.max_gap_m",
                "out of range"},
        BadCase{"near_points_zero", "perception: {near_field: {min_points: 0}}\n", "perception.near_field.min_points",
                "out of range"},
        BadCase{"near_height_negative", "perception: {near_field: {min_height_m: -0.1}}\n",
                "perception.near_field.min_height_m", "out of range"},
        BadCase{"near_zone_order", "perception: {near_field: {zone: {min: [12, -4, -3], max: [0.4, 4, 1]}}}\n",
                "perception.near_field.zone", "min x must be less than max x"},
        BadCase{"near_enabled", "perception: {near_field: {enabled: yes}}\n", "perception.near_field.enabled",
                "false, true"},
        BadCase{"near_key", "perception: {near_field: {max_gap: 0.3}}\n", "perception.near_field.max_gap",
                "unknown key"}),
    [](const ::testing::TestParamInfo<BadCase>& p) { return std::string(p.param.name); });

TEST(ConfigLoad, ReadsCanopySurroundingsAndDefaultsToFieldguards) {
  const auto d = load_config_text("perception: {filters: {min_points: 6}}\n", "t.yaml");
  EXPECT_EQ(d.config.perception.filters.canopy_surroundings_m, 3.0);
  const auto r = load_config_text("perception: {filters: {canopy_surroundings_m: 1.5}}\n", "t.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_EQ(r.config.perception.filters.canopy_surroundings_m, 1.5);
  const auto off = load_config_text("perception: {filters: {canopy_surroundings_m: 0}}\n", "t.yaml");
  ASSERT_TRUE(off.ok()) << dump(off);
  EXPECT_EQ(off.config.perception.filters.canopy_surroundings_m, 0.0);
}

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
  fs::copy_file(fs::path(FIELDGUARD_TEST_DATA) / "HDL-32.xml", dir / "HDL-32.xml",
                fs::copy_options::overwrite_existing);
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

// An RS-32's angle.csv: read with lidar.model RS-32 (it wins over DIFOP's table); refused for auto, which cannot
// know the table fits the sensor it finds; a malformed one names its line.
TEST(ConfigLoad, Rs32AngleTableNeedsTheModelAndNamesItsBadLine) {
  const fs::path dir = fs::temp_directory_path() / "fieldguard_config_rs32_test";
  fs::create_directories(dir);
  {
    std::ofstream csv(dir / "angle.csv");
    for (int c = 0; c < 32; ++c) csv << (-25.0 + 1.25 * c) << "," << (c % 2 == 0 ? 0.2 : -0.2) << "\n";
    std::ofstream bad(dir / "bad.csv");
    for (int c = 0; c < 32; ++c) bad << (c == 7 ? "ten" : "1.5") << ",0\n";
    std::ofstream(dir / "good.yaml") << "lidar: {model: RS-32, calibration_file: angle.csv}\n";
    std::ofstream(dir / "auto.yaml") << "lidar: {model: auto, calibration_file: angle.csv}\n";
    std::ofstream(dir / "bad.yaml") << "lidar: {model: RS-32, calibration_file: bad.csv}\n";
    std::ofstream(dir / "ports.yaml") << "lidar: {msop_port: 2368}\n";
  }
  const auto good = load_config_file((dir / "good.yaml").string());
  ASSERT_TRUE(good.ok()) << dump(good);
  ASSERT_TRUE(good.config.lidar.rs32_calibration.has_value());
  EXPECT_DOUBLE_EQ(good.config.lidar.rs32_calibration->vert_deg[31], -25.0 + 1.25 * 31);
  EXPECT_DOUBLE_EQ(good.config.lidar.rs32_calibration->horiz_deg[1], -0.2);
  EXPECT_FALSE(good.config.lidar.has_calibration);
  const auto for_auto = load_config_file((dir / "auto.yaml").string());
  EXPECT_TRUE(has_issue(for_auto, "lidar.calibration_file", "it needs lidar.model: RS-32")) << dump(for_auto);
  const auto bad = load_config_file((dir / "bad.yaml").string());
  EXPECT_TRUE(has_issue(bad, "lidar.calibration_file", "angle.csv line 8: 'ten' is not an angle")) << dump(bad);
  const auto ports = load_config_file((dir / "ports.yaml").string());
  EXPECT_TRUE(has_issue(ports, "lidar.msop_port", "is the same as lidar.data_port")) << dump(ports);
  fs::remove_all(dir);
}

// The anisotropic clustering's keys and the small-cluster absorption (cluster_absorb.hpp).
TEST(ConfigLoad, ReadsTheAnisotropicClusterKeys) {
  const auto r = load_config_text(R"(
perception:
  cluster: {method: anisotropic, tolerance_m: 0.3, beam_factor: 3.0, max_tolerance_m: 2.5,
            horizontal_beam_factor: 1.2, horizontal_max_tolerance_m: 0.9, absorb_max_points: 7, absorb_margin_m: 0.2}
)",
                                  "t.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& c = r.config.perception.cluster;
  EXPECT_EQ(c.method, perception::ClusterMethod::Anisotropic);
  EXPECT_DOUBLE_EQ(c.beam_factor, 3.0);
  EXPECT_DOUBLE_EQ(c.max_tolerance_m, 2.5);
  EXPECT_DOUBLE_EQ(c.horizontal_beam_factor, 1.2);
  EXPECT_DOUBLE_EQ(c.horizontal_max_tolerance_m, 0.9);
  EXPECT_EQ(c.absorb_max_points, 7);
  EXPECT_DOUBLE_EQ(c.absorb_margin_m, 0.2);
}

TEST(ConfigLoad, ReportsBadAnisotropicClusterKeys) {
  const std::string text =
      "perception:\n"                          // 1
      "  cluster:\n"                           // 2
      "    method: anisotropic\n"              // 3
      "    tolerance_m: 0.8\n"                 // 4
      "    beam_spacing_deg: 5\n"              // 5
      "    horizontal_max_tolerance_m: 0.5\n"  // 6 below tolerance_m
      "    horizontal_beam_factor: 9\n"        // 7 9 * tan(5 deg): grows too fast
      "    absorb_max_points: -1\n"            // 8 out of range
      "    absorb_margin_m: 20\n"              // 9 out of range
      "    absorb_points: 3\n";                // 10 unknown key
  const auto r = load_config_text(text, "bad.yaml");
  EXPECT_TRUE(has_issue(r, "perception.cluster.horizontal_max_tolerance_m", "must not be less than tolerance_m", 6))
      << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.cluster.horizontal_beam_factor", "below 0.5", 7)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.cluster.absorb_max_points", "out of range", 8)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.cluster.absorb_margin_m", "out of range", 9)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.cluster.absorb_points", "unknown key", 10)) << dump(r);
  EXPECT_EQ(r.issues.size(), 5U) << dump(r);
}

// The floating-cluster rules (cluster_join.hpp, cluster_filter.hpp): read; left out, fieldguard.yaml's values.
TEST(ConfigLoad, ReadsTheFloatingClusterKeys) {
  const auto r = load_config_text(R"(
perception:
  cluster: {join_float_height_m: 0.9, join_fragment_factor: 2.0, join_fragment_gap_m: 1.3, join_gap_m: 0.7,
            join_stacked: false, join_stack_margin_m: 0.5}
  filters: {float_min_height_m: 1.2, float_min_points: 4}
)",
                                  "t.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& c = r.config.perception.cluster;
  EXPECT_DOUBLE_EQ(c.join_float_height_m, 0.9);
  EXPECT_DOUBLE_EQ(c.join_fragment_factor, 2.0);
  EXPECT_DOUBLE_EQ(c.join_fragment_gap_m, 1.3);
  EXPECT_DOUBLE_EQ(c.join_gap_m, 0.7);
  EXPECT_FALSE(c.join_stacked);
  EXPECT_DOUBLE_EQ(c.join_stack_margin_m, 0.5);
  EXPECT_DOUBLE_EQ(r.config.perception.filters.float_min_height_m, 1.2);
  EXPECT_EQ(r.config.perception.filters.float_min_points, 4);
  const auto d = load_config_text("perception: {}\n", "t.yaml");
  ASSERT_TRUE(d.ok()) << dump(d);
  EXPECT_EQ(d.config.perception.cluster.join_float_height_m, 0.8);
  EXPECT_EQ(d.config.perception.cluster.join_fragment_factor, 1.5);
  EXPECT_EQ(d.config.perception.cluster.join_fragment_gap_m, 1.0);
  EXPECT_EQ(d.config.perception.cluster.join_gap_m, 0.6);
  EXPECT_TRUE(d.config.perception.cluster.join_stacked);
  EXPECT_EQ(d.config.perception.cluster.join_stack_margin_m, 0.4);
  EXPECT_EQ(d.config.perception.filters.float_min_height_m, 1.0);
  EXPECT_EQ(d.config.perception.filters.float_min_points, 3);
}

TEST(ConfigLoad, ReportsBadFloatingClusterKeys) {
  const std::string text =
      "perception:\n"                    // 1
      "  cluster:\n"                     // 2
      "    join_float_height_m: -0.5\n"  // 3 out of range
      "    join_gap_m: 20\n"             // 4 out of range
      "    join_stacked: yes please\n"   // 5 not true or false
      "    join_stack_margin_m: -1\n"    // 6 out of range
      "    join_fragment_gap_m: -1\n"    // 7 out of range
      "    join_fragment_factor: 0.5\n"  // 8 out of range
      "  filters:\n"                     // 9
      "    float_min_height_m: 11\n"     // 10 out of range
      "    float_min_points: 0\n";       // 11 out of range
  const auto r = load_config_text(text, "bad.yaml");
  EXPECT_TRUE(has_issue(r, "perception.cluster.join_float_height_m", "out of range", 3)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.cluster.join_gap_m", "out of range", 4)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.cluster.join_stacked", "is not one of", 5)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.cluster.join_stack_margin_m", "out of range", 6)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.cluster.join_fragment_gap_m", "out of range", 7)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.cluster.join_fragment_factor", "out of range", 8)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.filters.float_min_height_m", "out of range", 10)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.filters.float_min_points", "out of range", 11)) << dump(r);
  EXPECT_EQ(r.issues.size(), 8U) << dump(r);
}

// The least height's growth with distance (cluster_filter.hpp): read; left out, fieldguard.yaml's values.
TEST(ConfigLoad, ReadsTheHeightGrowthKeys) {
  const auto r = load_config_text(
      "perception: {filters: {min_height_growth_from_m: 20, min_height_growth_per_m: 0.04, "
      "min_height_growth_max_m: 0.8}}\n",
      "t.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& f = r.config.perception.filters;
  EXPECT_DOUBLE_EQ(f.min_height_growth_from_m, 20.0);
  EXPECT_DOUBLE_EQ(f.min_height_growth_per_m, 0.04);
  EXPECT_DOUBLE_EQ(f.min_height_growth_max_m, 0.8);
  const auto d = load_config_text("perception: {}\n", "t.yaml");
  ASSERT_TRUE(d.ok()) << dump(d);
  EXPECT_EQ(d.config.perception.filters.min_height_growth_from_m, 25.0);
  EXPECT_EQ(d.config.perception.filters.min_height_growth_per_m, 0.03);
  EXPECT_EQ(d.config.perception.filters.min_height_growth_max_m, 0.75);
}

TEST(ConfigLoad, ReportsBadHeightGrowthKeys) {
  const std::string text =
      "perception:\n"                       // 1
      "  filters:\n"                        // 2
      "    min_height_growth_from_m: -5\n"  // 3 out of range
      "    min_height_growth_per_m: 2\n";   // 4 out of range
  const auto r = load_config_text(text, "bad.yaml");
  EXPECT_TRUE(has_issue(r, "perception.filters.min_height_growth_from_m", "out of range", 3)) << dump(r);
  EXPECT_TRUE(has_issue(r, "perception.filters.min_height_growth_per_m", "out of range", 4)) << dump(r);
  EXPECT_EQ(r.issues.size(), 2U) << dump(r);
  // A cap under min_height_m would lower the threshold far out.
  const auto c = load_config_text("perception:\n  filters:\n    min_height_m: 0.5\n    min_height_growth_max_m: 0.3\n",
                                  "bad.yaml");
  EXPECT_TRUE(has_issue(c, "perception.filters.min_height_growth_max_m", "must not be less than min_height_m", 4))
      << dump(c);
  EXPECT_EQ(c.issues.size(), 1U) << dump(c);
}

// The ground stage's context beyond the ROI: read, range-checked; published.yaml keeps it off.
TEST(ConfigLoad, ReadsTheGroundContext) {
  const auto r = load_config_text("perception:\n  ground:\n    context_m: 7.5\n", "t.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_DOUBLE_EQ(r.config.perception.ground.context_m, 7.5);
  const auto bad = load_config_text("perception:\n  ground:\n    context_m: -1\n", "bad.yaml");
  EXPECT_TRUE(has_issue(bad, "perception.ground.context_m", "out of range", 3)) << dump(bad);
  EXPECT_EQ(bad.issues.size(), 1U) << dump(bad);
  const auto published = load_config_file(std::string(FIELDGUARD_SOURCE_DIR) + "/config/published.yaml");
  ASSERT_TRUE(published.ok()) << dump(published);
  EXPECT_EQ(published.config.perception.ground.context_m, 0.0);
}

// The zone ground's lower-envelope rule (zone_ground.hpp): read; left out, fieldguard.yaml's value.
TEST(ConfigLoad, ReadsTheGroundMaxBelowKey) {
  const auto r = load_config_text("perception: {ground: {zones: {max_below_m: 0.3}}}\n", "t.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_DOUBLE_EQ(r.config.perception.ground.zones.max_below_m, 0.3);
  const auto d = load_config_text("perception: {}\n", "t.yaml");
  ASSERT_TRUE(d.ok()) << dump(d);
  EXPECT_EQ(d.config.perception.ground.zones.max_below_m, 0.3);  // left out: fieldguard.yaml's value
}

TEST(ConfigLoad, ReportsABadGroundMaxBelow) {
  for (const char* bad : {"-0.1", "11", "deep"}) {
    const std::string text = std::string("perception:\n  ground:\n    zones:\n      max_below_m: ") + bad + "\n";
    const auto r = load_config_text(text, "bad.yaml");
    EXPECT_FALSE(r.ok()) << bad;
    EXPECT_TRUE(has_issue(r, "perception.ground.zones.max_below_m",
                          std::string(bad) == "deep" ? "expected a number" : "out of range", 4))
        << bad << ": " << dump(r);
    EXPECT_EQ(r.issues.size(), 1U) << dump(r);
  }
}

// The split of clusters holding two crowns (cluster_split.hpp): read; left out, fieldguard.yaml's values; bad
// values reported.
TEST(ConfigLoad, ReadsAndChecksTheClusterSplitKeys) {
  const auto r = load_config_text(R"(
perception:
  cluster: {split_min_length_m: 2.5, split_min_part_m: 0.6, split_gap_ratio: 0.7, split_min_part_points: 30,
            split_full_range_m: 12.0}
)",
                                  "t.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& c = r.config.perception.cluster;
  EXPECT_DOUBLE_EQ(c.split_min_length_m, 2.5);
  EXPECT_DOUBLE_EQ(c.split_min_part_m, 0.6);
  EXPECT_DOUBLE_EQ(c.split_gap_ratio, 0.7);
  EXPECT_EQ(c.split_min_part_points, 30);
  EXPECT_DOUBLE_EQ(c.split_full_range_m, 12.0);
  const auto d = load_config_text("perception:\n  cluster: {method: anisotropic}\n", "d.yaml");
  ASSERT_TRUE(d.ok()) << dump(d);
  EXPECT_EQ(d.config.perception.cluster.split_min_length_m, 2.0);  // left out: fieldguard.yaml's value

  const std::string text =
      "perception:\n"                    // 1
      "  cluster:\n"                     // 2
      "    split_min_length_m: -1\n"     // 3 out of range
      "    split_min_part_m: 200\n"      // 4 out of range
      "    split_gap_ratio: .nan\n"      // 5 not a number
      "    split_min_part_points: -3\n"  // 6 out of range
      "    split_full_range_m: 0\n";     // 7 out of range: the scale divides by it
  const auto bad = load_config_text(text, "bad.yaml");
  EXPECT_TRUE(has_issue(bad, "perception.cluster.split_min_length_m", "out of range", 3)) << dump(bad);
  EXPECT_TRUE(has_issue(bad, "perception.cluster.split_min_part_m", "out of range", 4)) << dump(bad);
  EXPECT_TRUE(has_issue(bad, "perception.cluster.split_gap_ratio", "expected a number", 5)) << dump(bad);
  EXPECT_TRUE(has_issue(bad, "perception.cluster.split_min_part_points", "out of range", 6)) << dump(bad);
  EXPECT_TRUE(has_issue(bad, "perception.cluster.split_full_range_m", "out of range", 7)) << dump(bad);
  EXPECT_EQ(bad.issues.size(), 5U) << dump(bad);
}

}  // namespace
}  // namespace fieldguard::app
