#include "fieldguard/perception/near_field.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

#include "../../benchmarks/synthetic_scene.hpp"
#include "fieldguard/perception/pipeline.hpp"

namespace fieldguard::perception {
namespace {

// A 2D LiDAR on the bumper: 1081 steps of 0.25 degrees, step 540 straight ahead, the scan plane level or
// dipping forward (the nose pitched down), over flat ground. Boxes are axis-aligned, standing on the ground.
struct AaBox {
  double x0, x1, y0, y1;
  float height;
};
struct Scan2d {
  float ground_z = -0.95F;  // the 3D LiDAR 0.95 m up: ground at -0.95 in its frame
  float origin_x = 0.3F;    // on the bumper, just ahead of the 3D LiDAR
  float height_m = 0.3F;    // above the ground
  float dip_deg = 0.F;      // scan plane's pitch, + nose down
  float noise_m = 0.F;      // +- along the ray, deterministic
  float slope_x = 0.F;      // rise of the ground per metre forward (boxes still stand at ground_z)
  float max_range_m = 30.F;
  std::vector<AaBox> boxes;

  [[nodiscard]] std::vector<LidarPoint> scan() const {
    std::vector<LidarPoint> out;
    const double oz = static_cast<double>(ground_z + height_m);
    const double dip = static_cast<double>(dip_deg) * std::numbers::pi / 180.0;
    for (int step = 0; step <= 1080; ++step) {
      const double a = static_cast<double>(step - 540) * 0.25 * std::numbers::pi / 180.0;
      const double dx = std::cos(a) * std::cos(dip), dy = std::sin(a), dz = -std::cos(a) * std::sin(dip);
      double best = static_cast<double>(max_range_m);
      // Ground z = ground_z + slope_x x, met where oz + t dz = ground_z + slope_x (origin_x + t dx).
      const double sx = static_cast<double>(slope_x);
      const double closing = dz - sx * dx;
      if (closing < 0.0) {
        best = std::min(best, (static_cast<double>(ground_z) + sx * static_cast<double>(origin_x) - oz) / closing);
      }
      for (const AaBox& b : boxes) {
        // Slabs: the ray's entry into the box.
        double t0 = 0.0, t1 = best;
        const double o[3] = {static_cast<double>(origin_x), 0.0, oz};
        const double d[3] = {dx, dy, dz};
        const double lo[3] = {b.x0, b.y0, static_cast<double>(ground_z)};
        const double hi[3] = {b.x1, b.y1, static_cast<double>(ground_z + b.height)};
        bool hit = true;
        for (int k = 0; k < 3 && hit; ++k) {
          if (std::fabs(d[k]) < 1e-12) {
            hit = o[k] >= lo[k] && o[k] <= hi[k];
            continue;
          }
          double ta = (lo[k] - o[k]) / d[k], tb = (hi[k] - o[k]) / d[k];
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(t0, ta);
          t1 = std::min(t1, tb);
          hit = t0 <= t1;
        }
        if (hit) best = std::min(best, t0);
      }
      if (best >= static_cast<double>(max_range_m)) continue;  // no echo
      const double t = best + static_cast<double>(noise_m) * std::sin(static_cast<double>(step) * 12.9898);
      LidarPoint p;
      p.x = static_cast<float>(static_cast<double>(origin_x) + t * dx);
      p.y = static_cast<float>(t * dy);
      p.z = static_cast<float>(oz + t * dz);
      p.range_m = static_cast<float>(t);
      p.ring = static_cast<std::uint16_t>(step);
      p.source = static_cast<std::uint8_t>(PointSource::Lidar2d);
      out.push_back(p);
    }
    return out;
  }
};

std::vector<LidarPoint> merged(std::vector<LidarPoint> a, const std::vector<LidarPoint>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// The 3D LiDAR's view of a flat field (and whatever stands in it), sensor `height` up.
std::vector<LidarPoint> scan3d(double height, const std::vector<sim::Box>& boxes = {}) {
  sim::Scene s;
  s.sensor_height_m = height;
  s.boxes = boxes;
  return sim::scan(s, sim::ScanSpec{});
}

PipelineParams params_for(double sensor_height) {
  PipelineParams p;
  p.ground.zones.sensor_height_m = sensor_height;
  p.roi.min[2] = -(sensor_height + 1.0);  // the default ROI is for a LiDAR 0.95 m up
  return p;
}

bool same_bits(const Obstacle& a, const Obstacle& b) {
  return a.min == b.min && a.max == b.max && a.obb_center == b.obb_center && a.obb_length_m == b.obb_length_m &&
         a.obb_width_m == b.obb_width_m && a.obb_yaw_rad == b.obb_yaw_rad && a.points == b.points &&
         a.distance_m == b.distance_m && a.bearing_deg == b.bearing_deg &&
         a.height_above_ground_m == b.height_above_ground_m && a.size_class == b.size_class && a.sources == b.sources;
}

NearField::GroundFn flat(float z) {
  return [z](float /*x*/, float /*y*/) { return z; };
}

// A line of 2D points across y at x, z, one step apart (0.25 deg at 5 m: 2.2 cm).
std::vector<LidarPoint> line(float x, float y0, float y1, float z, std::uint16_t first_step) {
  std::vector<LidarPoint> out;
  std::uint16_t step = first_step;
  for (float y = y0; y <= y1; y += 0.022F) {
    LidarPoint p;
    p.x = x;
    p.y = y;
    p.z = z;
    p.ring = step++;
    p.source = static_cast<std::uint8_t>(PointSource::Lidar2d);
    out.push_back(p);
  }
  return out;
}

// The brief's case: a 0.4 m box 1 m ahead of the bumper, under the lowest beam of a 3D LiDAR 1.8 m up.
TEST(NearField, LowBoxInTheBlindZoneFromTheScanAlone) {
  const double h = 1.8;
  const std::vector<LidarPoint> pts3d = scan3d(h, {sim::Box{{1.7, 0.0, 0.0}, {0.6, 0.6, 0.4}, 0.0}});
  Scan2d s;
  s.ground_z = -1.8F;
  s.noise_m = 0.01F;
  s.boxes.push_back({1.4, 2.0, -0.3, 0.3, 0.4F});

  Pipeline pipe(params_for(h));
  const FrameResult alone = pipe.process(pts3d);
  EXPECT_TRUE(alone.obstacles.empty()) << "the 3D LiDAR should not see it: the test would prove nothing";

  const std::vector<LidarPoint> scan = s.scan();
  const FrameResult r = pipe.process(merged(pts3d, scan));
  ASSERT_EQ(r.obstacles.size(), 1U);
  const Obstacle& o = r.obstacles[0];
  EXPECT_EQ(o.sources, kSeenBy2d);
  EXPECT_NEAR(o.min[0], 1.4F, 0.03F);  // the face the scan sees
  EXPECT_NEAR(o.min[1], -0.3F, 0.03F);
  EXPECT_NEAR(o.max[1], 0.3F, 0.03F);
  EXPECT_NEAR(o.min[2], -1.8F, 0.05F);                // down to the ground ...
  EXPECT_NEAR(o.max[2], -1.5F, 0.02F);                // ... up to the scan line
  EXPECT_NEAR(o.height_above_ground_m, 0.3F, 0.05F);  // a lower bound: the scan's height
  EXPECT_NEAR(o.distance_m, 1.4F, 0.03F);
  EXPECT_NEAR(o.bearing_deg, 0.F, 1.F);
  EXPECT_NEAR(o.obb_length_m, 0.6F, 0.05F);
  EXPECT_EQ(o.size_class, SizeClass::Small);
  EXPECT_GE(o.points, 20U);
  // Counts: the 3D path's are the 3D frame's, the scan's apart.
  EXPECT_EQ(r.counts.input, alone.counts.input);
  EXPECT_EQ(r.counts.after_roi, alone.counts.after_roi);
  EXPECT_EQ(r.counts.after_voxel, alone.counts.after_voxel);
  EXPECT_EQ(r.counts.obstacles, 0U);
  EXPECT_EQ(r.counts.near_input, scan.size());
  EXPECT_EQ(r.counts.near_obstacles, 1U);
  EXPECT_EQ(r.counts.near_merged, 0U);
  EXPECT_EQ(r.counts.near_in_zone, r.counts.near_input);  // the box is the scan's only echo

  // Switched off (the published method), the same frame has nothing.
  PipelineParams off = params_for(h);
  off.near_field.enabled = false;
  Pipeline pipe_off(off);
  const FrameResult r_off = pipe_off.process(merged(pts3d, scan));
  EXPECT_TRUE(r_off.obstacles.empty());
  EXPECT_EQ(r_off.counts.near_input, scan.size());
  EXPECT_EQ(r_off.counts.near_obstacles, 0U);
}

// The nose pitched down 5 degrees: the scan plane meets the ground 3.4 m ahead, a long line of ground hits.
TEST(NearField, GroundHitsAreNotObstacles) {
  const std::vector<LidarPoint> pts3d = scan3d(0.95);
  Scan2d s;
  s.dip_deg = 5.F;
  s.noise_m = 0.03F;  // the UTM-30LX-EW's accuracy
  const std::vector<LidarPoint> scan = s.scan();
  Pipeline pipe(params_for(0.95));
  const FrameResult r = pipe.process(merged(pts3d, scan));
  EXPECT_TRUE(r.obstacles.empty());
  EXPECT_GT(r.counts.near_in_zone, 200U) << "the ground line must be in the zone for the test to mean anything";
  EXPECT_EQ(r.counts.near_obstacles, 0U);

  // The same line with the ground 0.2 m lower than the 3D LiDAR says would be an obstacle: the test depends on
  // the ground lookup.
  NearField nf(NearFieldParams{});
  std::vector<Obstacle> out;
  nf.detect(scan, flat(-1.15F), out);
  EXPECT_FALSE(out.empty());
}

// The field rising ahead (3 deg) with the tractor still level: the level scan meets the ground 6 m ahead. The
// 3D ground of the same frame says so; the level ground under the tractor would make it a 0.3 m wall.
TEST(NearField, GroundHitsOnRisingGroundAreNotObstacles) {
  sim::Scene scene;
  scene.terrain.slope_x = 0.05;
  const std::vector<LidarPoint> pts3d = sim::scan(scene, sim::ScanSpec{});
  Scan2d s;
  s.slope_x = 0.05F;
  s.noise_m = 0.02F;
  const std::vector<LidarPoint> scan = s.scan();
  Pipeline pipe(params_for(0.95));
  const FrameResult r = pipe.process(merged(pts3d, scan));
  EXPECT_TRUE(r.obstacles.empty());
  EXPECT_GT(r.counts.near_in_zone, 100U);
  std::vector<Obstacle> out;
  NearField(NearFieldParams{}).detect(scan, flat(-0.95F), out);
  EXPECT_FALSE(out.empty());
}

// A 5 cm clod where the dipping scan plane meets the ground (there it cuts the clod 4.6 cm up): ground.
TEST(NearField, ClodIsNotAnObstacle) {
  const std::vector<LidarPoint> pts3d = scan3d(0.95);
  Scan2d s;
  s.dip_deg = 5.F;
  s.boxes.push_back({3.2, 3.5, -0.2, 0.2, 0.05F});
  const std::vector<LidarPoint> scan = s.scan();
  Pipeline pipe(params_for(0.95));
  const FrameResult r = pipe.process(merged(pts3d, scan));
  EXPECT_TRUE(r.obstacles.empty());
  // The clod's face is in the scan: a 2 cm threshold makes it an obstacle.
  NearFieldParams low;
  low.min_height_m = 0.02;
  std::vector<Obstacle> out;
  NearField(low).detect(
      scan, [&pipe](float x, float y) { return pipe.ground_z(x, y); }, out);
  EXPECT_TRUE(std::any_of(out.begin(), out.end(), [](const Obstacle& o) {
    return std::fabs(o.min[0] - 3.2F) < 0.05F && o.min[1] > -0.25F && o.max[1] < 0.25F;
  }));
}

TEST(NearField, GapsSplitSegments) {
  // Two runs 0.5 m apart along the line, steps consecutive.
  std::vector<LidarPoint> pts = line(5.F, -1.F, -0.3F, -0.6F, 400);
  std::vector<LidarPoint> b = line(5.F, 0.2F, 0.9F, -0.6F, static_cast<std::uint16_t>(400 + pts.size()));
  pts.insert(pts.end(), b.begin(), b.end());
  NearFieldParams p;
  {
    NearField nf(p);
    std::vector<Obstacle> out;
    EXPECT_EQ(nf.detect(pts, flat(-0.95F), out).obstacles, 2U);
    ASSERT_EQ(out.size(), 2U);
    EXPECT_NEAR(out[0].max[1], -0.3F, 0.03F);
    EXPECT_NEAR(out[1].min[1], 0.2F, 0.03F);
  }
  p.max_gap_m = 0.6;
  {
    NearField nf(p);
    std::vector<Obstacle> out;
    nf.detect(pts, flat(-0.95F), out);
    EXPECT_EQ(out.size(), 1U);
  }
  // Steps that go backwards (a second scan in the frame) split even where the points touch.
  std::vector<LidarPoint> twice = line(5.F, -1.F, -0.32F, -0.6F, 400);
  const std::vector<LidarPoint> second = line(5.F, -0.3F, 0.4F, -0.6F, 400);  // 2 cm on, steps from 400 again
  ASSERT_LT(std::fabs(twice.back().y - second.front().y), 0.05F);
  twice.insert(twice.end(), second.begin(), second.end());
  NearField nf(NearFieldParams{});
  std::vector<Obstacle> out;
  nf.detect(twice, flat(-0.95F), out);
  EXPECT_EQ(out.size(), 2U);
}

TEST(NearField, MinPoints) {
  const std::vector<LidarPoint> pts = line(5.F, 0.F, 0.1F, -0.6F, 500);  // a post: 5 points
  ASSERT_EQ(pts.size(), 5U);
  NearFieldParams p;
  p.min_points = 5;
  std::vector<Obstacle> out;
  NearField(p).detect(pts, flat(-0.95F), out);
  EXPECT_EQ(out.size(), 1U);
  p.min_points = 6;
  out.clear();
  NearField(p).detect(pts, flat(-0.95F), out);
  EXPECT_TRUE(out.empty());
  // Points lower than min_height_m do not count: the same post with its two lowest points on the ground.
  std::vector<LidarPoint> low = pts;
  low[0].z = -0.85F;  // 0.1 m up, 0.25 m from its neighbour: joined, were it not ground
  low[4].z = -0.85F;
  p.min_points = 4;
  out.clear();
  NearField(p).detect(low, flat(-0.95F), out);
  EXPECT_TRUE(out.empty());
  p.min_points = 3;
  out.clear();
  NearField(p).detect(low, flat(-0.95F), out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].points, 3U);
}

// A crate 3 m ahead that the 3D LiDAR (0.95 m up) sees as a cluster and the scan cuts: one obstacle.
TEST(NearField, MergesWithTheOverlapping3dObstacle) {
  const std::vector<LidarPoint> pts3d = scan3d(0.95, {sim::Box{{3.3, 0.0, 0.0}, {0.6, 0.8, 1.2}, 0.0}});
  Scan2d s;
  s.noise_m = 0.01F;
  s.boxes.push_back({3.0, 3.6, -0.4, 0.4, 1.2F});
  const std::vector<LidarPoint> scan = s.scan();

  Pipeline pipe(params_for(0.95));
  const FrameResult alone = pipe.process(pts3d);
  ASSERT_EQ(alone.obstacles.size(), 1U) << "the 3D path must see it for the test to mean anything";
  const FrameResult r = pipe.process(merged(pts3d, scan));
  ASSERT_EQ(r.obstacles.size(), 1U);
  const Obstacle& o = r.obstacles[0];
  EXPECT_EQ(o.sources, kSeenBy3d | kSeenBy2d);
  EXPECT_EQ(r.counts.near_obstacles, 1U);
  EXPECT_EQ(r.counts.near_merged, 1U);
  EXPECT_EQ(r.counts.obstacles, 1U);
  // The scan's points added; the box the union of both.
  std::vector<Obstacle> near;
  NearField nf(NearFieldParams{});
  nf.detect(
      scan, [&pipe](float x, float y) { return pipe.ground_z(x, y); }, near);
  ASSERT_EQ(near.size(), 1U);
  EXPECT_EQ(o.points, alone.obstacles[0].points + near[0].points);
  for (std::size_t a = 0; a < 3; ++a) {
    EXPECT_EQ(o.min[a], std::min(alone.obstacles[0].min[a], near[0].min[a]));
    EXPECT_EQ(o.max[a], std::max(alone.obstacles[0].max[a], near[0].max[a]));
  }
  EXPECT_EQ(o.distance_m, std::min(alone.obstacles[0].distance_m, near[0].distance_m));
  // The oriented box holds both.
  EXPECT_GE(o.obb_length_m + 1e-4F, std::max(alone.obstacles[0].obb_length_m, near[0].obb_length_m));
}

// Apart by more than the clustering tolerance, both stay, each its own, sorted nearest first (the scan also
// cuts the crate: that segment is merged into it).
TEST(NearField, DistinctObstaclesStaySeparateAndSorted) {
  const std::vector<LidarPoint> pts3d = scan3d(0.95, {sim::Box{{6.0, 0.0, 0.0}, {0.6, 0.8, 1.2}, 0.0}});
  Scan2d s;
  s.boxes.push_back({2.0, 2.3, 1.0, 1.4, 0.4F});   // left of the crate's line of sight, low
  s.boxes.push_back({5.7, 6.3, -0.4, 0.4, 1.2F});  // the crate
  const std::vector<LidarPoint> scan = s.scan();
  Pipeline pipe(params_for(0.95));
  const FrameResult r = pipe.process(merged(pts3d, scan));
  ASSERT_EQ(r.obstacles.size(), 2U);
  EXPECT_EQ(r.obstacles[0].sources, kSeenBy2d);
  EXPECT_EQ(r.obstacles[1].sources, kSeenBy3d | kSeenBy2d);
  EXPECT_LT(r.obstacles[0].distance_m, r.obstacles[1].distance_m);
  EXPECT_EQ(r.counts.near_obstacles, 2U);
  EXPECT_EQ(r.counts.near_merged, 1U);
}

TEST(NearField, FuseMergesOnlyWithinTheTolerance) {
  std::vector<Obstacle> v(2);
  v[0].min = {5.F, -0.5F, -1.F};
  v[0].max = {6.F, 0.5F, 0.8F};
  v[1].min = {4.6F, 0.9F, -0.95F};  // 0.4 m to the left of the first
  v[1].max = {5.2F, 1.5F, -0.6F};
  v[1].sources = kSeenBy2d;
  NearField nf(NearFieldParams{});
  std::vector<Obstacle> a = v;
  EXPECT_EQ(nf.fuse(a, 1, 0.3F), 0U);
  EXPECT_EQ(a.size(), 2U);
  std::vector<Obstacle> b = v;
  EXPECT_EQ(nf.fuse(b, 1, 0.6F), 1U);
  ASSERT_EQ(b.size(), 1U);
  EXPECT_EQ(b[0].sources, kSeenBy3d | kSeenBy2d);
  EXPECT_EQ(b[0].min, (std::array<float, 3>{4.6F, -0.5F, -1.F}));
  EXPECT_EQ(b[0].max, (std::array<float, 3>{6.F, 1.5F, 0.8F}));
}

// Without a 2D point the pipeline's output is what it was: the split leaves such a frame alone. And a frame
// whose 2D points all lie outside the zone gives the 3D frame's obstacles bit for bit.
TEST(NearField, No2dPointsChangesNothing) {
  const std::vector<LidarPoint> field = sim::scan(sim::benchmark_scene(), sim::ScanSpec{});
  Pipeline pipe(PipelineParams{});
  const FrameResult plain = pipe.process(field);
  ASSERT_FALSE(plain.obstacles.empty());
  for (const Obstacle& o : plain.obstacles) EXPECT_EQ(o.sources, kSeenBy3d);
  EXPECT_EQ(plain.counts.near_input, 0U);
  EXPECT_EQ(plain.counts.near_obstacles, 0U);

  // A wall beyond 12 m and one behind the bumper: in the scan, outside the zone.
  Scan2d s;
  s.boxes.push_back({14., 15., -3., 3., 1.F});
  std::vector<LidarPoint> scan = s.scan();
  const std::vector<LidarPoint> behind = line(0.2F, 1.6F, 3.F, -0.6F, 1000);
  scan.insert(scan.end(), behind.begin(), behind.end());
  const FrameResult r = pipe.process(merged(field, scan));
  EXPECT_EQ(r.counts.near_input, scan.size());
  EXPECT_EQ(r.counts.near_in_zone, 0U);
  EXPECT_EQ(r.counts.input, plain.counts.input);
  EXPECT_EQ(r.counts.after_roi, plain.counts.after_roi);
  EXPECT_EQ(r.counts.after_voxel, plain.counts.after_voxel);
  EXPECT_EQ(r.counts.ground, plain.counts.ground);
  EXPECT_EQ(r.counts.clusters, plain.counts.clusters);
  ASSERT_EQ(r.obstacles.size(), plain.obstacles.size());
  for (std::size_t i = 0; i < r.obstacles.size(); ++i) EXPECT_TRUE(same_bits(r.obstacles[i], plain.obstacles[i])) << i;
  // Inside the zone the same wall is an obstacle (so the zone, not something else, left it out).
  NearFieldParams wide;
  wide.zone.max[0] = 20.0;
  std::vector<Obstacle> out;
  NearField(wide).detect(scan, flat(-0.95F), out);
  EXPECT_FALSE(out.empty());
  // The 2D points never reach the 3D path, wherever they are: interleaved, the 3D counts stay.
  std::vector<LidarPoint> inter;
  for (std::size_t i = 0; i < field.size(); ++i) {
    inter.push_back(field[i]);
    if (i < scan.size()) inter.push_back(scan[i]);
  }
  const FrameResult ri = pipe.process(inter);
  EXPECT_EQ(ri.counts.input, plain.counts.input);
  EXPECT_EQ(ri.counts.after_voxel, plain.counts.after_voxel);
  ASSERT_EQ(ri.obstacles.size(), plain.obstacles.size());
  for (std::size_t i = 0; i < ri.obstacles.size(); ++i) EXPECT_TRUE(same_bits(ri.obstacles[i], plain.obstacles[i]));
}

TEST(NearField, NonFinitePointsAreDroppedAndCutSegments) {
  std::vector<LidarPoint> pts = line(5.F, -0.5F, 0.5F, -0.6F, 500);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  pts[10].x = nan;
  pts[20].z = std::numeric_limits<float>::infinity();
  NearField nf(NearFieldParams{});
  std::vector<Obstacle> out;
  const NearField::Counts c = nf.detect(pts, flat(-0.95F), out);
  EXPECT_EQ(c.in_zone, pts.size() - 2);
  ASSERT_EQ(out.size(), 1U);  // the neighbours of a dropped point are still nearer than the gap
  EXPECT_EQ(out[0].points, pts.size() - 2);
  for (const float v : out[0].min) EXPECT_TRUE(std::isfinite(v));
  // A ground lookup that answers NaN (no ground) drops the points rather than keeping or crashing.
  out.clear();
  nf.detect(pts, flat(nan), out);
  EXPECT_TRUE(out.empty());
}

TEST(NearField, RejectsParametersNoStageCanRunWith) {
  NearFieldParams p;
  p.zone.min[2] = p.zone.max[2];
  EXPECT_THROW(NearField{p}, std::invalid_argument);
  p = NearFieldParams{};
  p.max_gap_m = 0.0;
  EXPECT_THROW(NearField{p}, std::invalid_argument);
  p = NearFieldParams{};
  p.min_points = 0;
  EXPECT_THROW(NearField{p}, std::invalid_argument);
  p = NearFieldParams{};
  p.min_height_m = -0.1;
  EXPECT_THROW(NearField{p}, std::invalid_argument);
  PipelineParams pp;
  pp.near_field.zone.max[0] = -1.0;
  EXPECT_THROW(Pipeline{pp}, std::invalid_argument);
  EXPECT_FALSE(published_params().near_field.enabled);
}

}  // namespace
}  // namespace fieldguard::perception
