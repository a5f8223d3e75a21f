#include "fieldguard/perception/canopy.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <vector>

#include "fieldguard/perception/cluster_filter.hpp"
#include "fieldguard/perception/pipeline.hpp"
#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

using testing::lidar_point;
using testing::TestRng;

// A hand-made HDL-32E scan of flat ground 0.95 m below the sensor with axis-aligned boxes on it, solid or
// porous (a ray entering a porous box stops at an exponentially distributed depth inside, or passes on), as
// the simulator models a crop canopy. Range noise 1 cm.
struct Block {
  std::array<float, 3> min, max;
  bool porous = false;
  float mean_free_path_m = 0.4F;
};

constexpr float kGround = -0.95F;

std::optional<std::array<float, 2>> slab(const std::array<float, 3>& d, const Block& b) {
  float t0 = 0.F, t1 = std::numeric_limits<float>::max();
  for (std::size_t a = 0; a < 3; ++a) {
    if (std::fabs(d[a]) < 1e-9F) {
      if (b.min[a] > 0.F || b.max[a] < 0.F) return std::nullopt;
      continue;
    }
    float ta = b.min[a] / d[a], tb = b.max[a] / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 >= t1) return std::nullopt;
  return std::array<float, 2>{t0, t1};
}

std::vector<LidarPoint> scan(const std::vector<Block>& blocks, std::uint64_t seed) {
  TestRng rng(seed);
  std::vector<LidarPoint> out;
  for (int ring = 0; ring < 32; ++ring) {
    const double e = (-30.67 + 1.333 * ring) * std::numbers::pi / 180.0;
    for (int k = 0; k < 2250; ++k) {  // 0.16 degrees: 10 Hz
      const double az = (0.16 * k) * std::numbers::pi / 180.0;
      const std::array<float, 3> d{static_cast<float>(std::cos(e) * std::cos(az)),
                                   static_cast<float>(std::cos(e) * std::sin(az)), static_cast<float>(std::sin(e))};
      float best = d[2] < 0.F ? kGround / d[2] : std::numeric_limits<float>::max();
      for (const Block& b : blocks) {
        const auto t = slab(d, b);
        if (!t || (*t)[0] >= best) continue;
        if (!b.porous) {
          best = (*t)[0];
          continue;
        }
        const float u = rng.uniform(1e-6F, 1.F);
        const float stop = (*t)[0] - b.mean_free_path_m * std::log(u);
        if (stop < std::min((*t)[1], best)) best = stop;
      }
      if (best > 60.F) continue;
      const float r = best + rng.uniform(-0.01F, 0.01F);
      out.push_back(lidar_point(r * d[0], r * d[1], r * d[2], static_cast<std::uint16_t>(ring)));
    }
  }
  return out;
}

Cloud to_cloud(const std::vector<LidarPoint>& pts, const Block& inside) {
  Cloud c;
  for (const LidarPoint& p : pts) {
    if (p.x >= inside.min[0] && p.x <= inside.max[0] && p.y >= inside.min[1] && p.y <= inside.max[1] &&
        p.z > kGround + 0.05F) {
      c.push_back(p.x, p.y, p.z);
    }
  }
  return c;
}

std::vector<std::uint32_t> all(const Cloud& c) {
  std::vector<std::uint32_t> idx(c.size());
  std::iota(idx.begin(), idx.end(), 0U);
  return idx;
}

const Block kCanopy{{5.F, 1.5F, kGround}, {14.F, 8.F, kGround + 0.7F}, true, 0.4F};
const Block kSolid{{6.F, -2.F, kGround}, {7.F, -1.F, kGround + 0.7F}};

TEST(RingJitter, PorousCanopyJittersSolidBoxDoesNot) {
  RingJitterMeter meter(1.333, 0.5);
  const Cloud canopy = to_cloud(scan({kCanopy}, 1), kCanopy);
  ASSERT_GT(canopy.size(), 500U);
  const RingJitter jc = meter.measure(canopy, all(canopy));
  EXPECT_GT(jc.triples, 100U);
  EXPECT_GT(jc.median_m, 0.1F);
  const Cloud box = to_cloud(scan({kSolid}, 1), kSolid);
  ASSERT_GT(box.size(), 100U);
  const RingJitter jb = meter.measure(box, all(box));
  EXPECT_GT(jb.triples, 50U);
  EXPECT_LT(jb.median_m, 0.02F);
}

TEST(RingJitter, AnObliqueFaceIsSmooth) {
  // A wall seen at 20 degrees: its range changes fast with bearing, but linearly.
  Cloud c;
  const float s = std::sin(0.35F), co = std::cos(0.35F);
  for (int ring = 0; ring < 6; ++ring) {
    for (int k = 0; k < 40; ++k) {
      const float along = 0.1F * static_cast<float>(k);
      c.push_back(10.F + along * co, 2.F + along * s, -0.8F + 0.2F * static_cast<float>(ring));
    }
  }
  RingJitterMeter meter(1.333, 0.5);
  const RingJitter j = meter.measure(c, all(c));
  EXPECT_GT(j.triples, 100U);
  EXPECT_LT(j.median_m, 0.01F);
}

TEST(RingJitter, TooFewPointsGiveNoTriples) {
  Cloud c;
  c.push_back(20.F, 0.F, -0.5F);
  c.push_back(20.F, 0.1F, -0.5F);
  RingJitterMeter meter(1.333, 0.5);
  EXPECT_EQ(meter.measure(c, all(c)).triples, 0U);
  EXPECT_EQ(meter.measure(c, {}).triples, 0U);
  EXPECT_THROW(RingJitterMeter(0.0, 0.5), std::invalid_argument);
  EXPECT_THROW(RingJitterMeter(1.333, 0.0), std::invalid_argument);
}

FilterParams canopy_on() {
  FilterParams f;
  f.canopy_max_height_m = 1.0;
  f.canopy_min_jitter_m = 0.08;
  f.canopy_min_triples = 4;
  f.canopy_max_gap_m = 0.5;
  f.canopy_needle_depth_m = 0.35;
  f.canopy_needle_ratio = 3.0;
  return f;
}

PipelineParams pipeline_canopy_on() {
  PipelineParams p;
  p.filters = canopy_on();
  return p;
}

TEST(CheckCanopy, OnlyLowPorousClustersAndOnlyWhenOn) {
  FilterParams f = canopy_on();
  RingJitterMeter meter(1.333, f.canopy_max_gap_m);
  const Cloud canopy = to_cloud(scan({kCanopy}, 2), kCanopy);
  ClusterSummary s;
  s.height_above_ground_m = 0.7F;
  EXPECT_EQ(check_canopy(f, s, canopy, all(canopy), meter), Rejection::Porous);
  s.height_above_ground_m = 1.75F;  // something stands above it
  EXPECT_EQ(check_canopy(f, s, canopy, all(canopy), meter), Rejection::Kept);
  s.height_above_ground_m = 0.7F;
  f.canopy_min_triples = 100000;  // not enough to judge: kept
  EXPECT_EQ(check_canopy(f, s, canopy, all(canopy), meter), Rejection::Kept);
  f = canopy_on();
  f.canopy_max_height_m = 0.0;  // off
  EXPECT_EQ(check_canopy(f, s, canopy, all(canopy), meter), Rejection::Kept);
  EXPECT_EQ(check_canopy(published_params().filters, s, canopy, all(canopy), meter), Rejection::Kept);
}

// A few returns of one ring far out: reaching deep along one bearing is a ray inside a canopy (porous even
// with too few triples to judge the jitter); across the bearing, as a person's slice, it is not; two returns
// are never enough.
TEST(CheckCanopy, ANeedleAlongTheRaysIsPorous) {
  FilterParams f = canopy_on();
  f.canopy_min_triples = 1000;  // only the needle test can decide
  RingJitterMeter meter(1.333, f.canopy_max_gap_m);
  ClusterSummary s;
  s.height_above_ground_m = 0.7F;
  Cloud needle;  // 25 m out, 0.9 m deep, 5 cm wide
  for (const float dr : {0.F, 0.3F, 0.55F, 0.9F}) needle.push_back(25.F + dr, 3.F + 0.01F * dr, -0.25F);
  s.points = static_cast<std::uint32_t>(needle.size());
  EXPECT_EQ(check_canopy(f, s, needle, all(needle), meter), Rejection::Porous);
  const std::vector<std::uint32_t> two{0, 3};
  s.points = 2;
  EXPECT_EQ(check_canopy(f, s, needle, two, meter), Rejection::Kept);
  Cloud slice;  // a person's slice: 0.45 m across the rays, 0.15 m deep
  for (const float dy : {0.F, 0.15F, 0.3F, 0.45F}) slice.push_back(25.F + (dy > 0.2F ? 0.15F : 0.F), 3.F + dy, -0.25F);
  s.points = static_cast<std::uint32_t>(slice.size());
  EXPECT_EQ(check_canopy(f, s, slice, all(slice), meter), Rejection::Kept);
  f.canopy_needle_depth_m = 0.0;  // the needle test off
  s.points = static_cast<std::uint32_t>(needle.size());
  EXPECT_EQ(check_canopy(f, s, needle, all(needle), meter), Rejection::Kept);
}

bool any_obstacle_in(const FrameResult& r, const Block& b) {
  return std::any_of(r.obstacles.begin(), r.obstacles.end(), [&](const Obstacle& o) {
    return o.max[0] >= b.min[0] && o.min[0] <= b.max[0] && o.max[1] >= b.min[1] && o.min[1] <= b.max[1];
  });
}

// Through the whole pipeline (voxel grid, zone ground, clusters): a 0.7 m porous canopy is no obstacle, a
// solid 0.7 m box beside it is, and so is a person (1.75 m) standing in the canopy, and one crouching (1.0 m)
// beside it. Without the canopy rule the canopy is an obstacle (else this test could not fail).
TEST(PipelineCanopy, CanopyIsNoObstacleButWhatStandsInOrBesideItIs) {
  const Block person_in{{9.F, 4.F, kGround}, {9.3F, 4.5F, kGround + 1.75F}};
  const Block crouching{{8.F, -5.F, kGround}, {8.5F, -4.5F, kGround + 1.0F}};
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE(seed);
    Pipeline off([] {
      PipelineParams p = pipeline_canopy_on();
      p.filters.canopy_max_height_m = 0.0;
      return p;
    }());
    EXPECT_TRUE(any_obstacle_in(off.process(scan({kCanopy}, seed)), kCanopy));
    for (const PipelineParams& p : {pipeline_canopy_on(), PipelineParams{}}) {  // and fieldguard.yaml's
      Pipeline on(p);
      EXPECT_FALSE(any_obstacle_in(on.process(scan({kCanopy}, seed)), kCanopy));
      const FrameResult r = on.process(scan({kCanopy, kSolid, person_in, crouching}, seed));
      EXPECT_TRUE(any_obstacle_in(r, kSolid));
      EXPECT_TRUE(any_obstacle_in(r, person_in));
      EXPECT_TRUE(any_obstacle_in(r, crouching));
    }
  }
}

// A slice of a crop canopy's top far out, as the level ring leaves it: two returns 30 m out at h 0.7 m, too few
// for any triple of its own. Around it, two lower rings' returns (heights below the obstacle height): a porous
// canopy (ranges jumping 0.3 m back and forth) or bare ground (ranges smooth).
struct SliceScene {
  Cloud frame;                // every voxel: the field's returns, then the slice's two points
  std::vector<float> height;  // above the ground, one per point of `frame`
  Cloud above;                // the slice alone (the non-ground cloud)
  std::vector<std::uint32_t> in_frame{};
  ClusterSummary s;
};

SliceScene slice_scene(bool porous_field, float slice_height = 0.7F) {
  SliceScene sc;
  constexpr float kRange = 30.F;
  constexpr float kStep = 0.16F * std::numbers::pi_v<float> / 180.F;  // 10 Hz azimuth step
  for (const float elevation_deg : {-1.333F, -2.667F}) {
    const float t = std::tan(elevation_deg * std::numbers::pi_v<float> / 180.F);
    for (int k = -30; k <= 30; ++k) {
      const float b = 0.09F + kStep * static_cast<float>(k);
      const float r = kRange + (porous_field ? ((k % 2 == 0) ? 0.15F : -0.15F) : 0.F);
      sc.frame.push_back(r * std::cos(b), r * std::sin(b), r * t);
      sc.height.push_back(0.1F);
    }
  }
  for (const float db : {0.F, kStep}) {
    const float b = 0.09F + db;
    sc.in_frame.push_back(static_cast<std::uint32_t>(sc.frame.size()));
    sc.frame.push_back(kRange * std::cos(b), kRange * std::sin(b), 0.F);
    sc.height.push_back(0.3F);  // low enough to count as surroundings: only the marks keep it out
    sc.above.push_back(kRange * std::cos(b), kRange * std::sin(b), 0.F);
  }
  sc.s.points = 2;
  sc.s.min = {sc.above.x[1], sc.above.y[0], 0.F};
  sc.s.max = {sc.above.x[0], sc.above.y[1], 0.F};
  sc.s.distance_m = kRange;
  sc.s.height_above_ground_m = slice_height;
  return sc;
}

FilterParams surroundings_on() {
  FilterParams f;  // fieldguard.yaml's canopy thresholds
  f.canopy_surroundings_m = 2.0;
  return f;
}

TEST(LowSurroundings, GathersTheClusterThenTheLowPointsAroundItsBox) {
  SliceScene sc = slice_scene(true);
  sc.height[0] = 0.6F;                    // not low: left out
  sc.frame.push_back(40.F, 2.8F, -0.9F);  // far beyond the radius: left out
  sc.height.push_back(0.F);
  std::vector<std::uint8_t> skip(sc.frame.size(), 0U);
  for (const std::uint32_t i : sc.in_frame) skip[i] = 1U;
  LowSurroundings around;
  around.min = {sc.s.min[0], sc.s.min[1]};
  around.max = {sc.s.max[0], sc.s.max[1]};
  around.radius_m = 2.F;
  around.max_height_m = 0.5F;
  Cloud out;
  const std::vector<std::uint32_t> members{0, 1};
  gather_low_surroundings(sc.above, members, sc.frame, sc.height, skip, around, out);
  // The 2 slice points first, then the 122 field returns but the one too high (all lie within 2 m: the rings
  // span 61 steps of 0.084 m = 5 m across, so not all: count those inside).
  std::size_t inside = 0;
  for (std::size_t i = 1; i < 122; ++i) {
    const float x = sc.frame.x[i], y = sc.frame.y[i];
    inside +=
        (x >= around.min[0] - 2.F && x <= around.max[0] + 2.F && y >= around.min[1] - 2.F && y <= around.max[1] + 2.F)
            ? 1U
            : 0U;
  }
  ASSERT_GT(inside, 40U);
  ASSERT_LT(inside, 121U);
  ASSERT_EQ(out.size(), 2U + inside);
  EXPECT_EQ(out.x[0], sc.above.x[0]);
  EXPECT_EQ(out.y[1], sc.above.y[1]);
  // Without the marks the slice's own points come in twice.
  gather_low_surroundings(sc.above, members, sc.frame, sc.height, {}, around, out);
  EXPECT_EQ(out.size(), 4U + inside);
  const std::vector<float> short_heights(3, 0.F);
  EXPECT_THROW(gather_low_surroundings(sc.above, members, sc.frame, short_heights, {}, around, out),
               std::invalid_argument);
  const std::vector<std::uint8_t> short_skip(3, 0U);
  EXPECT_THROW(gather_low_surroundings(sc.above, members, sc.frame, sc.height, short_skip, around, out),
               std::invalid_argument);
}

TEST(CheckCanopySurroundings, ASliceInAPorousFieldIsPorousOnBareGroundItIsNot) {
  const FilterParams f = surroundings_on();
  RingJitterMeter meter(1.333, f.canopy_max_gap_m);
  Cloud scratch;
  for (const bool porous : {true, false}) {
    SliceScene sc = slice_scene(porous);
    std::vector<std::uint8_t> marks(sc.frame.size(), 0U);
    const FrameSurroundings frame{sc.frame, sc.height, sc.in_frame, marks};
    const std::vector<std::uint32_t> members{0, 1};
    // Alone, the slice says nothing.
    EXPECT_EQ(check_canopy(f, sc.s, sc.above, members, meter), Rejection::Kept);
    EXPECT_EQ(check_canopy(f, sc.s, sc.above, members, meter, &frame, &scratch),
              porous ? Rejection::Porous : Rejection::Kept);
    EXPECT_TRUE(std::all_of(marks.begin(), marks.end(), [](std::uint8_t v) { return v == 0U; }));
  }
}

// What the rule must not drop: anything standing higher than a canopy (a person in the crop), a cluster with
// enough triples of its own (check_canopy has told), and everything while the key is 0.
TEST(CheckCanopySurroundings, TallClustersOwnEvidenceAndOffAreKept) {
  RingJitterMeter meter(1.333, 0.5);
  Cloud scratch;
  const std::vector<std::uint32_t> members{0, 1};
  {
    SliceScene sc = slice_scene(true, 1.2F);
    std::vector<std::uint8_t> marks(sc.frame.size(), 0U);
    const FrameSurroundings frame{sc.frame, sc.height, sc.in_frame, marks};
    EXPECT_EQ(check_canopy(surroundings_on(), sc.s, sc.above, members, meter, &frame, &scratch), Rejection::Kept);
  }
  SliceScene sc = slice_scene(true);
  std::vector<std::uint8_t> marks(sc.frame.size(), 0U);
  const FrameSurroundings frame{sc.frame, sc.height, sc.in_frame, marks};
  FilterParams f = surroundings_on();
  f.canopy_min_triples = 1;  // the slice's own triples (none) ... still too few: decided by the surroundings
  EXPECT_EQ(check_canopy(f, sc.s, sc.above, members, meter, &frame, &scratch), Rejection::Porous);
  f = surroundings_on();
  f.canopy_surroundings_m = 0.0;
  EXPECT_EQ(check_canopy(f, sc.s, sc.above, members, meter, &frame, &scratch), Rejection::Kept);
  f = surroundings_on();
  f.canopy_max_height_m = 0.0;
  EXPECT_EQ(check_canopy(f, sc.s, sc.above, members, meter, &frame, &scratch), Rejection::Kept);
  // A smooth solid slice of its own with plenty of triples (a box's face) standing in the porous field.
  SliceScene box = slice_scene(true);
  box.above.clear();
  box.in_frame.clear();
  std::vector<std::uint32_t> face;
  for (int k = 0; k < 30; ++k) {
    const float b = 0.09F + 0.0028F * static_cast<float>(k);
    box.in_frame.push_back(static_cast<std::uint32_t>(box.frame.size()));
    box.frame.push_back(29.F * std::cos(b), 29.F * std::sin(b), 0.F);
    box.height.push_back(0.7F);
    face.push_back(static_cast<std::uint32_t>(box.above.size()));
    box.above.push_back(29.F * std::cos(b), 29.F * std::sin(b), 0.F);
  }
  std::vector<std::uint8_t> box_marks(box.frame.size(), 0U);
  const FrameSurroundings box_frame{box.frame, box.height, box.in_frame, box_marks};
  EXPECT_EQ(check_canopy(surroundings_on(), box.s, box.above, face, meter, &box_frame, &scratch), Rejection::Kept);
  std::vector<std::uint8_t> wrong(3, 0U);
  const FrameSurroundings bad{sc.frame, sc.height, sc.in_frame, wrong};
  EXPECT_THROW((void)check_canopy(surroundings_on(), sc.s, sc.above, members, meter, &bad, &scratch),
               std::invalid_argument);
}

}  // namespace
}  // namespace fieldguard::perception
