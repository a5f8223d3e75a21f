#include "fieldguard/perception/pipeline.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <set>
#include <vector>

#include "../../benchmarks/synthetic_scene.hpp"
#include "fieldguard/perception/crop.hpp"
#include "fieldguard/perception/ground.hpp"
#include "fieldguard/perception/ransac_ground.hpp"
#include "fieldguard/perception/voxel_grid.hpp"
#include "fieldguard/perception/zone_ground.hpp"
#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

bool same_bits(const Obstacle& a, const Obstacle& b) {
  return a.min == b.min && a.max == b.max && a.obb_center == b.obb_center && a.obb_length_m == b.obb_length_m &&
         a.obb_width_m == b.obb_width_m && a.obb_yaw_rad == b.obb_yaw_rad && a.points == b.points &&
         a.distance_m == b.distance_m && a.bearing_deg == b.bearing_deg &&
         a.height_above_ground_m == b.height_above_ground_m && a.size_class == b.size_class;
}

const std::vector<LidarPoint>& field_scan() {
  static const std::vector<LidarPoint> pts = sim::scan(sim::benchmark_scene(), sim::ScanSpec{});
  return pts;
}

TEST(Pipeline, EmptyInput) {
  for (const auto& params : {PipelineParams{}, published_params()}) {
    Pipeline pipe(params);
    const FrameResult r = pipe.process({});
    EXPECT_TRUE(r.obstacles.empty());
    EXPECT_EQ(r.counts.input, 0U);
    EXPECT_EQ(r.counts.after_voxel, 0U);
    EXPECT_TRUE(pipe.last_points().empty());
  }
}

TEST(Pipeline, EverythingInTheBodyBox) {
  std::vector<LidarPoint> body;
  for (int i = 0; i < 500; ++i) {
    body.push_back(testing::lidar_point(-4.5F + 0.009F * static_cast<float>(i), -1.4F + 0.005F * static_cast<float>(i),
                                        -1.0F + 0.004F * static_cast<float>(i)));
  }
  Pipeline pipe(PipelineParams{});
  const FrameResult r = pipe.process(body);
  EXPECT_EQ(r.counts.input, 500U);
  EXPECT_EQ(r.counts.after_roi, 0U);
  EXPECT_TRUE(r.obstacles.empty());
}

TEST(Pipeline, NanAndInfinityAreDroppedNotFatal) {
  std::vector<LidarPoint> pts = field_scan();
  Pipeline clean(PipelineParams{});
  const FrameResult expected = clean.process(pts);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<LidarPoint> dirty;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    dirty.push_back(pts[i]);
    if (i % 97 == 0) dirty.push_back(testing::lidar_point(nan, 1, 1, pts[i].ring));
    if (i % 101 == 0) dirty.push_back(testing::lidar_point(5, inf, 0, pts[i].ring));
    if (i % 103 == 0) dirty.push_back(testing::lidar_point(-inf, nan, inf, pts[i].ring));
  }
  Pipeline pipe(PipelineParams{});
  const FrameResult r = pipe.process(dirty);
  EXPECT_EQ(r.counts.after_roi, expected.counts.after_roi);
  ASSERT_EQ(r.obstacles.size(), expected.obstacles.size());
  for (std::size_t i = 0; i < r.obstacles.size(); ++i)
    EXPECT_TRUE(same_bits(r.obstacles[i], expected.obstacles[i])) << i;
}

// Same input, same output: twice through one pipeline (scratch reused) and through a fresh one, bit for bit.
TEST(Pipeline, Deterministic) {
  for (const auto& params : {PipelineParams{}, published_params()}) {
    Pipeline a(params), b(params);
    const FrameResult r1 = a.process(field_scan());
    const std::vector<LabeledPoint> labels1(a.last_points().begin(), a.last_points().end());
    (void)a.process(sim::scan(sim::Scene{}, sim::ScanSpec{}));  // another frame in between
    const FrameResult r2 = a.process(field_scan());
    const FrameResult r3 = b.process(field_scan());
    ASSERT_FALSE(r1.obstacles.empty());
    ASSERT_EQ(r1.obstacles.size(), r2.obstacles.size());
    ASSERT_EQ(r1.obstacles.size(), r3.obstacles.size());
    for (std::size_t i = 0; i < r1.obstacles.size(); ++i) {
      EXPECT_TRUE(same_bits(r1.obstacles[i], r2.obstacles[i])) << i;
      EXPECT_TRUE(same_bits(r1.obstacles[i], r3.obstacles[i])) << i;
    }
    ASSERT_EQ(labels1.size(), a.last_points().size());
    EXPECT_EQ(0, std::memcmp(labels1.data(), a.last_points().data(), labels1.size() * sizeof(LabeledPoint)));
  }
}

TEST(Pipeline, ObstaclesNearestFirstAndCountsAddUp) {
  Pipeline pipe(PipelineParams{});
  const FrameResult r = pipe.process(field_scan());
  ASSERT_GT(r.obstacles.size(), 5U);
  EXPECT_TRUE(std::is_sorted(r.obstacles.begin(), r.obstacles.end(),
                             [](const Obstacle& a, const Obstacle& b) { return a.distance_m < b.distance_m; }));
  EXPECT_EQ(r.counts.obstacles, r.obstacles.size());
  EXPECT_GE(r.counts.clusters, r.counts.obstacles);
  EXPECT_LE(r.counts.after_voxel, r.counts.after_roi);
  EXPECT_LE(r.counts.after_roi, r.counts.input);
  std::uint32_t ground = 0, obstacle = 0, in_obstacles = 0;
  for (const auto& p : pipe.last_points()) {
    ground += p.label == PointLabel::Ground ? 1U : 0U;
    obstacle += p.label == PointLabel::Obstacle ? 1U : 0U;
  }
  for (const auto& o : r.obstacles) in_obstacles += o.points;
  EXPECT_EQ(ground, r.counts.ground);
  EXPECT_EQ(obstacle, in_obstacles);
  EXPECT_EQ(pipe.last_points().size(), r.counts.after_voxel);
  for (const auto& o : r.obstacles) {
    EXPECT_LE(o.min[0], o.max[0]);
    EXPECT_GE(o.distance_m, 0.F);
    EXPECT_GE(o.height_above_ground_m, 0.5F);  // fieldguard.yaml's height filter
    EXPECT_GE(o.obb_length_m, o.obb_width_m);
  }
}

// The stage times: each stage that worked on the frame took some time, they add up to the whole (nothing timed
// twice or left out), and the whole is within the time the call took, seen from outside.
TEST(Pipeline, StageTimesAddUpToTheFrame) {
  Pipeline pipe(PipelineParams{});
  const auto before = std::chrono::steady_clock::now();
  const FrameResult r = pipe.process(field_scan());
  const double outside_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - before).count();
  ASSERT_GT(r.obstacles.size(), 0U);
  const StageTimes& t = r.times;
  for (const float us : {t.crop_us, t.voxel_us, t.ground_us, t.cluster_us, t.merge_us, t.boxes_us}) EXPECT_GT(us, 0.F);
  EXPECT_GE(t.near_us, 0.F);
  double sum = 0.0;
  for (const float us : {t.crop_us, t.voxel_us, t.ground_us, t.cluster_us, t.merge_us, t.boxes_us, t.near_us}) {
    sum += static_cast<double>(us);
  }
  EXPECT_NEAR(sum, static_cast<double>(t.total_us), 1e-3 * static_cast<double>(t.total_us) + 0.01);
  EXPECT_LE(static_cast<double>(t.total_us), outside_us);
}

// The labelled points are the voxels, in their order and to the bit, Ground exactly where the ground stage says
// so, and a point beyond the ROI's far end (kept as the ground stage's context only) in no cluster. (The pipeline
// writes them four at a time; the frames' voxel counts leave every remainder of four.)
TEST(Pipeline, LabelledPointsAreTheVoxelsWithTheGroundStagesLabels) {
  const auto bits = [](float v) { return std::bit_cast<std::uint32_t>(v); };
  // The field, less a few points, with a post beyond the ROI's far end (in the ground context) of as many returns.
  std::vector<std::vector<LidarPoint>> frames;
  for (std::size_t cut = 0; cut < 8; ++cut) {
    frames.emplace_back(field_scan().begin(), field_scan().end() - static_cast<std::ptrdiff_t>(97 * cut));
    for (std::size_t k = 0; k <= cut; ++k) {
      frames.back().push_back(testing::lidar_point(56.F, 0.5F * static_cast<float>(k), 0.2F * static_cast<float>(k)));
    }
  }
  std::set<std::size_t> remainders;
  for (const auto& params : {PipelineParams{}, published_params()}) {
    for (const auto& pts : frames) {
      Pipeline pipe(params);
      const FrameResult r = pipe.process(pts);
      Box3 crop = params.roi;
      crop.max[0] += params.ground.context_m;
      Cloud cropped, voxels;
      crop_box(pts, crop, params.body, cropped);
      VoxelGrid(params.voxel).filter(cropped, voxels);
      GroundLabels g;
      if (params.ground.method == GroundMethod::Ransac) {
        RansacGround(params.ground.ransac, params.ground.zones.sensor_height_m).segment(voxels, g);
      } else {
        ZoneGround(params.ground.zones).segment(voxels, g);
      }
      const auto points = pipe.last_points();
      ASSERT_EQ(points.size(), voxels.size());
      remainders.insert(points.size() % 4);
      const auto far = static_cast<float>(params.roi.max[0]);
      std::uint32_t ground = 0, beyond = 0;
      for (std::size_t i = 0; i < points.size(); ++i) {
        ASSERT_EQ(bits(points[i].x), bits(voxels.x[i])) << i;
        ASSERT_EQ(bits(points[i].y), bits(voxels.y[i])) << i;
        ASSERT_EQ(bits(points[i].z), bits(voxels.z[i])) << i;
        const bool is_ground = g.ground[i] != 0U;
        ASSERT_EQ(points[i].label == PointLabel::Ground, is_ground) << i;
        ground += is_ground ? 1U : 0U;
        if (!is_ground && voxels.x[i] > far) {
          ++beyond;
          EXPECT_EQ(points[i].label, PointLabel::Unclustered) << i;
        }
      }
      EXPECT_EQ(ground, r.counts.ground);
      if (params.ground.context_m > 0.0) {
        EXPECT_GT(beyond, 0U) << "the test needs points in the ground context";
      }
    }
  }
  EXPECT_EQ(remainders.size(), 4U) << "the frames should leave every remainder of four voxels";
}

// On a flat field, a 0.6 m high box is an obstacle and a 0.3 m clod is terrain (height above local ground).
TEST(Pipeline, HeightAboveGroundKeepsAnObjectAndDropsAClod) {
  sim::Scene scene;
  scene.boxes.push_back(sim::Box{{7.0, 2.0, 0.0}, {0.6, 0.6, 0.6}, 0.0});
  scene.boxes.push_back(sim::Box{{7.0, -2.0, 0.0}, {1.0, 1.0, 0.3}, 0.0});  // a wide clod: enough points
  Pipeline pipe(PipelineParams{});
  const FrameResult r = pipe.process(sim::scan(scene, sim::ScanSpec{}));
  ASSERT_EQ(r.obstacles.size(), 1U);
  EXPECT_NEAR(r.obstacles[0].bearing_deg, 16.F, 2.F);
  EXPECT_NEAR(r.obstacles[0].height_above_ground_m, 0.6F, 0.08F);
  EXPECT_EQ(r.obstacles[0].size_class, SizeClass::Small);
  // The clod was a cluster, rejected by the height filter: its points are labelled so.
  const auto rejected = std::count_if(pipe.last_points().begin(), pipe.last_points().end(),
                                      [](const LabeledPoint& p) { return p.label == PointLabel::Rejected; });
  EXPECT_GT(rejected, 3);
}

// A side-on pedestrian at 30 m, 10 Hz: a handful of returns on three rings. Our settings find one obstacle;
// the published ones (fixed 0.6 m radius, at least 10 points, at least 0.06 m^3) cannot.
TEST(Pipeline, PedestrianAtThirtyMetres) {
  sim::Scene scene;
  scene.cylinders.push_back(sim::person(30.0, 1.0));
  const auto pts = sim::scan(scene, sim::ScanSpec{});
  Pipeline ours(PipelineParams{});
  const FrameResult r = ours.process(pts);
  ASSERT_EQ(r.obstacles.size(), 1U);
  EXPECT_NEAR(r.obstacles[0].distance_m, 29.75F, 0.3F);
  EXPECT_NEAR(r.obstacles[0].bearing_deg, 1.9F, 0.5F);
  EXPECT_GT(r.obstacles[0].height_above_ground_m, 1.4F);
  EXPECT_EQ(r.obstacles[0].size_class, SizeClass::Small);
  Pipeline published(published_params());
  EXPECT_TRUE(published.process(pts).obstacles.empty());
}

// Far out only a ring or two reach the ground. Here the ground is flat to 38 m, then climbs 6 %; no return
// landed on it between 38 and 50 m (the ROI's far end), one ring's arc did at 50-60 m, and a 0.3 m clod
// stands on the climb at 49.4 m. Without the ground beyond the ROI the clod is measured against the flat
// plane carried on (about 1 m high: an obstacle); with it, against the climb (terrain). A 1 m box at 55 m,
// beyond the ROI, is ground context only: never an obstacle, never counted in after_roi.
TEST(Pipeline, GroundBeyondTheRegionOfInterestIsContextOnly) {
  Cloud c;
  constexpr float kSlope = 0.06F;
  constexpr float kFloor = -0.95F;
  const auto ground_at = [&](float x) { return x <= 38.F ? kFloor : kFloor + kSlope * (x - 38.F); };
  testing::add_plane(c, 0.F, 0.F, kFloor, 2.F, 38.F, -4.F, 4.F, 0.2F);
  testing::add_plane(c, kSlope, 0.F, kFloor - kSlope * 38.F, 50.5F, 60.F, -4.F, 4.F, 0.2F);
  testing::add_block(c, {49.2F, 1.0F, ground_at(49.2F) + 0.02F}, {3, 4, 4}, 0.1F);  // the clod, 0.3 m
  testing::add_block(c, {55.F, -1.F, ground_at(55.F) + 0.05F}, {4, 4, 10}, 0.1F);   // a 1 m box beyond
  const std::vector<LidarPoint> pts = testing::to_lidar(c);
  std::size_t in_roi = 0;
  for (const LidarPoint& p : pts) in_roi += p.x <= 50.F ? 1U : 0U;

  PipelineParams base;
  base.roi.max[0] = 50.0;  // the scene is laid out around a region ending at 50 m
  PipelineParams without = base;
  without.ground.context_m = 0.0;
  const FrameResult cut = Pipeline(without).process(pts);
  ASSERT_EQ(cut.obstacles.size(), 1U) << "the clod against the flat ground carried on";
  EXPECT_NEAR(cut.obstacles[0].distance_m, 49.2F, 0.3F);
  EXPECT_GT(cut.obstacles[0].height_above_ground_m, 0.8F);
  EXPECT_EQ(cut.counts.after_roi, in_roi);

  PipelineParams with = base;
  with.ground.context_m = 15.0;
  const FrameResult seen = Pipeline(with).process(pts);
  EXPECT_TRUE(seen.obstacles.empty()) << "nearest: " << (seen.obstacles.empty() ? 0.F : seen.obstacles[0].distance_m)
                                      << " m, "
                                      << (seen.obstacles.empty() ? 0.F : seen.obstacles[0].height_above_ground_m)
                                      << " m high";
  EXPECT_EQ(seen.counts.after_roi, in_roi);
  EXPECT_GT(seen.counts.after_voxel, cut.counts.after_voxel) << "the context went into the ground stage";
}

// Groups too few for the filters are the hold's evidence (obstacle_hold.hpp) when they stand as high as an
// obstacle must: two returns 1.5 m up at 10 m (a crown's, seen through a gap; a floating group needs three) and
// a lone return 1.2 m up at 12 m are fragments; two returns 0.2 m up (a clod's top) and a full obstacle are not.
// Without the hold (the published method) no fragment is gathered.
TEST(Pipeline, FragmentsAreTheRaisedGroupsTooFewForTheFilters) {
  constexpr float kFloor = -0.95F;
  Cloud c;
  testing::add_plane(c, 0.F, 0.F, kFloor, 2.F, 30.F, -6.F, 6.F, 0.2F);
  c.push_back(10.F, 3.1F, kFloor + 1.5F);  // the crown's two
  c.push_back(10.F, 3.4F, kFloor + 1.6F);
  c.push_back(12.F, -3.1F, kFloor + 1.2F);  // the lone return
  c.push_back(8.F, -1.1F, kFloor + 0.2F);   // the clod's top
  c.push_back(8.F, -1.4F, kFloor + 0.2F);
  testing::add_block(c, {6.F, 1.F, kFloor + 0.1F}, {4, 4, 12}, 0.1F);  // a 1.2 m post: an obstacle
  const std::vector<LidarPoint> pts = testing::to_lidar(c);

  const FrameResult r = Pipeline(PipelineParams{}).process(pts);
  ASSERT_EQ(r.obstacles.size(), 1U);
  EXPECT_NEAR(r.obstacles[0].distance_m, std::hypot(6.F, 1.F), 0.1F);
  ASSERT_EQ(r.fragments.size(), 2U);
  EXPECT_EQ(r.counts.fragments, 2U);
  std::vector<Fragment> f = r.fragments;
  std::sort(f.begin(), f.end(), [](const Fragment& a, const Fragment& b) { return a.min[0] < b.min[0]; });
  EXPECT_EQ(f[0].points, 2U);
  EXPECT_FLOAT_EQ(f[0].min[1], 3.1F);
  EXPECT_FLOAT_EQ(f[0].max[1], 3.4F);
  EXPECT_FLOAT_EQ(f[0].max[2], kFloor + 1.6F);
  EXPECT_NEAR(f[0].height_above_ground_m, 1.6F, 0.02F);
  EXPECT_NEAR(f[0].distance_m, std::hypot(10.F, 3.1F), 0.01F);
  EXPECT_EQ(f[1].points, 1U);
  EXPECT_FLOAT_EQ(f[1].min[0], 12.F);
  EXPECT_NEAR(f[1].height_above_ground_m, 1.2F, 0.02F);

  PipelineParams off;
  off.hold.enabled = false;
  const FrameResult without = Pipeline(off).process(pts);
  EXPECT_TRUE(without.fragments.empty());
  EXPECT_EQ(without.counts.fragments, 0U);
  ASSERT_EQ(without.obstacles.size(), 1U);
  EXPECT_TRUE(same_bits(without.obstacles[0], r.obstacles[0]));
  EXPECT_TRUE(Pipeline(published_params()).process(pts).fragments.empty());
}

TEST(Pipeline, LargeObjectsAreLarge) {
  sim::Scene scene;
  // An implement 4 m x 2.6 m turned so that its long side faces the sensor: the footprint's rectangle
  // follows that side.
  scene.boxes.push_back(sim::Box{{15.0, 0.0, 0.0}, {4.0, 2.6, 1.4}, 1.3});
  Pipeline pipe(PipelineParams{});
  const FrameResult r = pipe.process(sim::scan(scene, sim::ScanSpec{}));
  ASSERT_EQ(r.obstacles.size(), 1U);
  EXPECT_EQ(r.obstacles[0].size_class, SizeClass::Large);
  EXPECT_NEAR(r.obstacles[0].obb_yaw_rad, 1.3F, 0.1F);
  EXPECT_NEAR(r.obstacles[0].obb_length_m, 4.F, 0.3F);
}

TEST(Pipeline, RefusesAnImpossibleConfiguration) {
  PipelineParams p;
  p.voxel.leaf_m = 0.0;
  EXPECT_THROW(Pipeline{p}, std::invalid_argument);
  p = PipelineParams{};
  p.ground.zones.edges_m = {5.0};
  EXPECT_THROW(Pipeline{p}, std::invalid_argument);
}

}  // namespace
}  // namespace fieldguard::perception
