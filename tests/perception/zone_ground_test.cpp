#include "fieldguard/perception/zone_ground.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "../../benchmarks/synthetic_scene.hpp"
#include "fieldguard/perception/crop.hpp"
#include "fieldguard/perception/pipeline.hpp"
#include "fieldguard/perception/voxel_grid.hpp"
#include "perception/fast_math.hpp"
#include "perception/hypot.hpp"
#include "perception/nth_element.hpp"
#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

constexpr double kPi = std::numbers::pi;

// A scan of the scene after ROI, body and voxel grid, as the ground stage sees it.
Cloud prepared(const sim::Scene& scene, double hz = 10.0) {
  sim::ScanSpec spec;
  spec.rotation_hz = hz;
  spec.max_range_m = 70.0;
  const auto pts = sim::scan(scene, spec);
  const PipelineParams p;
  Cloud cropped, out;
  crop_box(pts, p.roi, p.body, cropped);
  VoxelGrid grid(p.voxel);
  grid.filter(cropped, out);
  return out;
}

TEST(ZoneGround, FindsATiltedPlaneWithinOneDegree) {
  sim::Scene scene;
  scene.terrain.slope_x = std::tan(5.0 * kPi / 180.0);
  scene.terrain.slope_y = std::tan(-3.0 * kPi / 180.0);
  const Cloud c = prepared(scene);
  ZoneGround zones(ZoneParams{});
  GroundLabels labels;
  zones.segment(c, labels);
  const double true_angle_tol = 1.0;
  int fitted = 0;
  for (float x = 3.F; x < 30.F; x += 1.5F) {
    for (float y = -9.F; y <= 9.F; y += 1.5F) {
      // The ground under (x, y) in the sensor frame (sensor 0.95 m above the ground at the origin).
      const auto truth =
          static_cast<float>(scene.terrain.z(static_cast<double>(x), static_cast<double>(y)) - scene.sensor_height_m);
      EXPECT_NEAR(zones.ground_z(x, y), truth, 0.06F) << x << ", " << y;
      if (!zones.fitted_at(x, y)) continue;
      ++fitted;
      const GroundPlane p = zones.plane_at(x, y);
      const double c_ang =
          (scene.terrain.slope_x * static_cast<double>(p.a) + scene.terrain.slope_y * static_cast<double>(p.b) + 1.0) /
          (std::hypot(scene.terrain.slope_x, scene.terrain.slope_y, 1.0) *
           std::hypot(static_cast<double>(p.a), static_cast<double>(p.b), 1.0));
      EXPECT_LT(std::acos(std::min(1.0, c_ang)) * 180.0 / kPi, true_angle_tol) << x << ", " << y;
    }
  }
  EXPECT_GT(fitted, 100);
  std::size_t ground = 0;
  for (const auto g : labels.ground) ground += g;
  EXPECT_EQ(ground, c.size());  // a bare plane is all ground
}

// The tractor rolled 8 degrees and pitched 4: the ground is tilted in the sensor frame, and still ground.
TEST(ZoneGround, HoldsWhenTheVehicleRollsAndPitches) {
  sim::Scene scene;
  scene.roll_deg = 8.0;
  scene.pitch_deg = -4.0;
  scene.terrain.furrow_m = 0.04;
  const Cloud c = prepared(scene);
  ZoneGround zones(ZoneParams{});
  GroundLabels labels;
  zones.segment(c, labels);
  std::size_t ground = 0;
  for (const auto g : labels.ground) ground += g;
  EXPECT_GT(static_cast<double>(ground), 0.995 * static_cast<double>(c.size()));
  Pipeline pipe(PipelineParams{});
  const auto pts = sim::scan(scene, sim::ScanSpec{});
  EXPECT_TRUE(pipe.process(pts).obstacles.empty());
}

// A field ridge 35 cm high on a 6-degree slope: the slope is ground, the ridge is not (it stands 35 cm above
// the local ground, so the height filter calls it terrain), and a person behind it is not swallowed.
TEST(ZoneGround, RidgeOnASlopeIsNotGroundAndNotAnObstacle) {
  sim::Scene scene;
  scene.terrain.slope_x = std::tan(6.0 * kPi / 180.0);
  scene.terrain.ridge_x_m = 9.0;
  scene.terrain.ridge_width_m = 1.2;
  scene.terrain.ridge_height_m = 0.35;
  const Cloud c = prepared(scene);
  ZoneGround zones(ZoneParams{});
  GroundLabels labels;
  zones.segment(c, labels);
  int crest = 0, crest_ground = 0, slope = 0, slope_ground = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const double base = scene.terrain.slope_x * static_cast<double>(c.x[i]) - scene.sensor_height_m;
    const double above_base = static_cast<double>(c.z[i]) - base;
    if (std::fabs(c.x[i] - 9.0F) < 0.2F && std::fabs(c.y[i]) < 8.F) {
      ++crest;
      crest_ground += labels.ground[i];
      EXPECT_NEAR(labels.height_m[i], above_base, 0.1) << c.x[i] << ", " << c.y[i];
    } else if (std::fabs(c.x[i] - 9.0F) > 2.0F) {
      ++slope;
      slope_ground += labels.ground[i];
    }
  }
  ASSERT_GT(crest, 10);
  EXPECT_EQ(crest_ground, 0);
  EXPECT_GT(static_cast<double>(slope_ground), 0.995 * slope);

  Pipeline pipe(PipelineParams{});
  const auto pts = sim::scan(scene, sim::ScanSpec{});
  const auto bare = pipe.process(pts);
  EXPECT_TRUE(bare.obstacles.empty()) << bare.obstacles.size() << " obstacles, first at "
                                      << (bare.obstacles.empty() ? 0.F : bare.obstacles[0].distance_m) << " m";

  // People on the slope behind the ridge, near and far: found, standing on the local ground. (Up a 6-degree
  // slope the top rings pass over their heads: the highest return is 1.47 m up the near one, 1.3 m up the far.)
  scene.cylinders.push_back(sim::person(15.0, 2.0));
  scene.cylinders.push_back(sim::person(30.0, -1.0));
  const auto with_people = pipe.process(sim::scan(scene, sim::ScanSpec{}));
  ASSERT_EQ(with_people.obstacles.size(), 2U);
  EXPECT_NEAR(with_people.obstacles[0].distance_m, 14.75F, 0.3F);
  EXPECT_NEAR(with_people.obstacles[1].distance_m, 29.75F, 0.3F);
  EXPECT_NEAR(with_people.obstacles[0].height_above_ground_m, 1.47F, 0.2F);
  EXPECT_NEAR(with_people.obstacles[1].height_above_ground_m, 1.3F, 0.2F);
  for (const float x : {15.F, 30.F}) {
    EXPECT_NEAR(pipe.ground_z(x, 0.F),
                static_cast<float>(scene.terrain.z(static_cast<double>(x), 0.0) - scene.sensor_height_m), 0.15F);
  }
}

// A person standing where no ground is seen (the far zone of a 32-beam sensor: no ring reaches the flat
// ground between 21 and 40 m) takes the ground of the bins around, not a plane through their legs.
TEST(ZoneGround, FarPersonWithNoGroundAroundIsNotGround) {
  sim::Scene scene;
  scene.cylinders.push_back(sim::person(30.0, 0.5));
  const Cloud c = prepared(scene);
  ZoneGround zones(ZoneParams{});
  GroundLabels labels;
  zones.segment(c, labels);
  int person = 0, person_ground = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (std::hypot(c.x[i] - 30.F, c.y[i] - 0.5F) < 0.4F && c.z[i] > -0.7F) {
      ++person;
      person_ground += labels.ground[i];
    }
  }
  EXPECT_GE(person, 3);
  EXPECT_EQ(person_ground, 0);
  EXPECT_NEAR(zones.ground_z(30.F, 0.5F), -0.95F, 0.1F);
}

// Ground flat to 18 m, then climbing at 8 %: the bin from 10 to 20 m is fitted to the flat part and carries it to
// its outer edge, the bin from 20 to 30 m to the climb. A clod 0.4 m high at 19.8 m stands 0.54 m above the
// inner bin's plane (an obstacle to min_height_m 0.5); blending in the plane of the bin beyond, by distance to
// where each was fitted, brings it back to about its true height. At the inner bin's own fitted points
// nothing changes.
TEST(ZoneGround, BlendsThePlaneBeyondAtABinsOuterEdge) {
  const auto ground = [](float r) { return -0.95F + 0.08F * std::max(0.F, r - 18.F); };
  Cloud c;
  for (float r = 2.5F; r < 10.F; r += 0.25F) {  // the innermost zone all round: the vehicle's own plane
    for (float deg = -180.F; deg < 180.F; deg += 2.F) {
      const float a = deg * static_cast<float>(kPi) / 180.F;
      c.push_back(r * std::cos(a), r * std::sin(a), ground(r));
    }
  }
  for (float r = 10.F; r < 30.F; r += 0.25F) {  // farther out, one sector's worth around 22.5 degrees
    if (r > 18.F && r < 20.5F) continue;        // the rings skip the bend
    for (float deg = 5.F; deg < 40.F; deg += 1.F) {
      const float a = deg * static_cast<float>(kPi) / 180.F;
      c.push_back(r * std::cos(a), r * std::sin(a), ground(r));
    }
  }
  const float a = 22.5F * static_cast<float>(kPi) / 180.F;
  const auto probe = static_cast<std::uint32_t>(c.size());
  c.push_back(19.8F * std::cos(a), 19.8F * std::sin(a), ground(19.8F) + 0.4F);  // the clod's top
  const auto on_fit = static_cast<std::uint32_t>(c.size());
  c.push_back(14.F * std::cos(a), 14.F * std::sin(a), ground(14.F));

  ZoneParams zp;
  zp.edges_m = {2.0, 10.0, 20.0, 30.0};
  zp.rings = {1, 1, 1};
  zp.sectors = {8, 8, 8};
  zp.blend_radial = false;
  GroundLabels plain, blended;
  ZoneGround(zp).segment(c, plain);
  zp.blend_radial = true;
  ZoneGround zones(zp);
  zones.segment(c, blended);
  ASSERT_TRUE(zones.fitted_at(14.F * std::cos(a), 14.F * std::sin(a)));
  ASSERT_TRUE(zones.fitted_at(25.F * std::cos(a), 25.F * std::sin(a)));
  EXPECT_NEAR(plain.height_m[probe], 0.4F + 0.08F * 1.8F, 0.03F);  // above the flat plane carried out
  // The flat plane (fitted about 14 m out) and the climb's (about 25 m out) at 19.8 m, each weighted by the
  // distance to the other's fit: the clod's true 0.4 m, within what the climb's slope prior leaves.
  EXPECT_NEAR(blended.height_m[probe], 0.4F, 0.06F);
  EXPECT_LT(blended.height_m[probe], 0.5F);
  EXPECT_NEAR(blended.height_m[on_fit], plain.height_m[on_fit], 0.01F);
}

// Behind a row of trees (nothing measured between 18 and 26 m in its direction) only the near-horizontal
// lasers reach the next row's crown: its bin at about 29 m holds a flat, wide sheet of returns at the sensor's
// height, 0.95 m above the ground, and one lower laser's return 0.35 m above the ground under them. Today that
// sheet passes every test of a ground plane (continued from 16 m, a step of 0.95 m is allowed) and the crown is
// ground. With max_below_m the return under the sheet shows it is not the lower envelope: the bin keeps the
// ground continued from inside. A bank as high with nothing under it (the other side) stays fitted ground.
TEST(ZoneGround, APlaneWithItsOwnReturnsFarBelowItIsNotGround) {
  const float kGround = -0.95F;
  const float deg = static_cast<float>(kPi) / 180.F;
  Cloud c;
  for (float r = 2.5F; r < 24.F; r += 0.25F) {
    for (float b = -180.F; b < 180.F; b += 1.F) {
      if (r > 18.F && std::fabs(std::fabs(b) - 14.F) < 12.F) continue;  // hidden behind the near row, both sides
      c.push_back(r * std::cos(b * deg), r * std::sin(b * deg), kGround);
    }
  }
  // The crown's returns of the horizontal laser (left), and the bank's top (right): the same sheet, mirrored.
  std::vector<std::uint32_t> crown;
  for (float r = 28.4F; r < 30.F; r += 0.4F) {
    for (float b = 12.F; b < 16.1F; b += 0.5F) {
      crown.push_back(static_cast<std::uint32_t>(c.size()));
      c.push_back(r * std::cos(b * deg), r * std::sin(b * deg), 0.F);
      c.push_back(r * std::cos(-b * deg), r * std::sin(-b * deg), 0.F);
    }
  }
  const auto low = static_cast<std::uint32_t>(c.size());
  c.push_back(28.6F * std::cos(14.F * deg), 28.6F * std::sin(14.F * deg), kGround + 0.35F);
  const float cx = 29.F * std::cos(14.F * deg), cy = 29.F * std::sin(14.F * deg);

  ZoneParams zp;
  zp.max_below_m = 0.0;  // the rule off
  GroundLabels today, fixed;
  ZoneGround plain(zp);
  plain.segment(c, today);
  ASSERT_TRUE(plain.fitted_at(cx, cy));  // the failure this guards against: the sheet taken as ground
  EXPECT_NEAR(plain.ground_z(cx, cy), 0.F, 0.05F);
  EXPECT_EQ(today.ground[crown[0]], 1U);

  zp.max_below_m = 0.3;
  ZoneGround zones(zp);
  zones.segment(c, fixed);
  EXPECT_FALSE(zones.fitted_at(cx, cy));
  EXPECT_NEAR(zones.ground_z(cx, cy), kGround, 0.05F);
  for (const std::uint32_t i : crown) {
    EXPECT_EQ(fixed.ground[i], 0U) << c.x[i] << ", " << c.y[i];
    EXPECT_NEAR(fixed.height_m[i], 0.95F, 0.1F);
    EXPECT_EQ(fixed.ground[i + 1], 1U) << "the bank: " << c.x[i + 1] << ", " << c.y[i + 1];
  }
  EXPECT_EQ(fixed.ground[low], 0U);
  EXPECT_TRUE(zones.fitted_at(cx, -cy));
  EXPECT_NEAR(zones.ground_z(cx, -cy), 0.F, 0.05F);
  // Where nothing lies under a plane the rule changes nothing: every ground point of the near field as before.
  for (std::size_t i = 0; i < crown.front(); ++i) ASSERT_EQ(fixed.ground[i], today.ground[i]) << i;
}

// Real ground keeps its labels with the rule on: a ridge on a slope, and the vehicle rolling and pitching over
// furrows (returns of a furrow's bottom lie under a plane, but centimetres, not tenths of a metre).
TEST(ZoneGround, TheLowerEnvelopeRuleLeavesRealGroundAlone) {
  std::vector<sim::Scene> scenes(2);
  scenes[0].terrain.slope_x = std::tan(6.0 * kPi / 180.0);
  scenes[0].terrain.ridge_x_m = 9.0;
  scenes[0].terrain.ridge_width_m = 1.2;
  scenes[0].terrain.ridge_height_m = 0.35;
  scenes[1].roll_deg = 8.0;
  scenes[1].pitch_deg = -4.0;
  scenes[1].terrain.furrow_m = 0.04;
  scenes[1].terrain.undulation_m = 0.3;
  for (const auto& scene : scenes) {
    const Cloud c = prepared(scene);
    ZoneParams zp;
    zp.max_below_m = 0.0;  // the rule off
    GroundLabels off, on;
    ZoneGround(zp).segment(c, off);
    zp.max_below_m = 0.3;
    ZoneGround(zp).segment(c, on);
    ASSERT_EQ(on.ground.size(), off.ground.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < c.size(); ++i) differ += on.ground[i] != off.ground[i] ? 1U : 0U;
    EXPECT_EQ(differ, 0U);
  }
}

TEST(ZoneGround, EmptyInputAndTheSurfaceBeforeAnyFrame) {
  ZoneParams p;
  p.sensor_height_m = 1.2;
  ZoneGround zones(p);
  EXPECT_FLOAT_EQ(zones.ground_z(10.F, 3.F), -1.2F);
  GroundLabels labels;
  zones.segment(Cloud{}, labels);
  EXPECT_TRUE(labels.ground.empty());
  EXPECT_FLOAT_EQ(zones.ground_z(100.F, -70.F), -1.2F);  // beyond the last zone: the last ring's bin
}

TEST(ZoneGround, RefusesALayoutThatIsNone) {
  ZoneParams p;
  p.edges_m = {2.0, 1.0};
  p.rings = {1};
  p.sectors = {8};
  EXPECT_THROW(ZoneGround{p}, std::invalid_argument);
  p.edges_m = {1.0, 2.0, 3.0};
  EXPECT_THROW(ZoneGround{p}, std::invalid_argument);  // two zones, one ring count
  p.rings = {1, 0};
  p.sectors = {8, 8};
  EXPECT_THROW(ZoneGround{p}, std::invalid_argument);
}

// Four zones, edges at 2, 6, 14, 26 and 50 m, rings and sectors growing outwards: the layout the bin tests check
// bins_of against bin_of on.
ZoneParams four_zones() {
  ZoneParams p;
  p.edges_m = {2.0, 6.0, 14.0, 26.0, 50.0};
  p.rings = {2, 4, 4, 4};
  p.sectors = {16, 32, 48, 64};
  return p;
}

// segment() bins four points at a time; the surface it leaves is looked up one point at a time (bin_of). The two
// must agree to the bin everywhere: in each zone, on its edges, beyond the last, at the sensor, and for NaN.
TEST(ZoneGround, BinsFourAtATimeAsOneAtATime) {
  const ZoneParams p = four_zones();
  const ZoneGround zones(p);
  Cloud c;
  testing::TestRng rng(7);  // the same points on every machine
  const auto next = [&rng] { return rng.uniform(0.F, 1.F); };
  for (int i = 0; i < 20000; ++i) {
    const float r = 60.F * next() * next(), a = static_cast<float>(2.0 * kPi) * next();
    c.push_back(r * std::cos(a), r * std::sin(a), 0.F);
  }
  for (const double e : p.edges_m) {  // exactly on each zone edge, all round
    for (int k = 0; k < 64; ++k) {
      const double a = 2.0 * kPi * k / 64.0;
      c.push_back(static_cast<float>(e * std::cos(a)), static_cast<float>(e * std::sin(a)), 0.F);
    }
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  c.push_back(0.F, 0.F, 0.F);
  c.push_back(-0.F, -0.F, 0.F);
  c.push_back(-3.F, 0.F, 0.F);  // bearing pi: the seam
  c.push_back(-3.F, -0.F, 0.F);
  c.push_back(nan, 1.F, 0.F);
  c.push_back(1.F, nan, 0.F);
  c.push_back(1e30F, -1e30F, 0.F);
  c.push_back(5.F, 5.F, 0.F);  // and a tail of fewer than four
  c.push_back(-20.F, 7.F, 0.F);
  Buffer<std::uint32_t> bins;
  zones.bins_of(c, bins);
  ASSERT_EQ(bins.size(), c.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    ASSERT_EQ(bins[i], zones.bin_of(c.x[i], c.y[i])) << "point " << i << " at " << c.x[i] << ", " << c.y[i];
    ASSERT_LT(bins[i], zones.bin_count());
  }
}

// bins_of picks each lane's zone constants by how many zone ends its range has passed: runs of four on each side
// of every zone edge, runs that straddle one, and one point off in a run, must all give bin_of's bins.
TEST(ZoneGround, BinsRunsOfFourInOneZoneAsOneAtATime) {
  const ZoneParams p = four_zones();
  const ZoneGround zones(p);
  Cloud c;
  testing::TestRng rng(5);
  const auto at = [&c](float r, float a) { c.push_back(r * std::cos(a), r * std::sin(a), 0.F); };
  for (const double e : p.edges_m) {
    const auto edge = static_cast<float>(e);
    for (const float off : {-0.3F, -1e-6F, 0.F, 1e-6F, 0.3F}) {
      const float a = rng.uniform(-3.14F, 3.14F);
      for (int k = 0; k < 4; ++k) at(edge + off, a + 0.01F * static_cast<float>(k));  // one run, one side
    }
    at(edge - 0.01F, 1.F);  // a run across the edge: two in, two out
    at(edge - 0.01F, 1.F);
    at(edge + 0.01F, 1.F);
    at(edge + 0.01F, 1.F);
  }
  for (int run = 0; run < 2000; ++run) {  // runs of near points, now and then one far
    const float r = rng.uniform(0.F, 60.F), a = rng.uniform(-3.2F, 3.2F);
    const int odd = run % 7 == 0 ? run % 4 : -1;
    for (int k = 0; k < 4; ++k) at(k == odd ? rng.uniform(0.F, 60.F) : r + 0.05F * static_cast<float>(k), a);
  }
  Buffer<std::uint32_t> bins;
  zones.bins_of(c, bins);
  ASSERT_EQ(bins.size(), c.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    ASSERT_EQ(bins[i], zones.bin_of(c.x[i], c.y[i])) << "point " << i << " at " << c.x[i] << ", " << c.y[i];
  }
}

// bins_of counts passed zone ends over a fixed array of four (unused ends NaN, passed by no range) when there are at
// most five zones, over all the ends otherwise: one zone (no end at all), five (four ends, none NaN) and seven zones
// (the general loop) must each give bin_of's bins, on and beside every edge, for infinite and NaN points too.
TEST(ZoneGround, BinsFourAtATimeAsOneAtATimeForAnyZoneCount) {
  for (const std::size_t zone_count : {std::size_t{1}, std::size_t{5}, std::size_t{7}}) {
    ZoneParams p;
    p.edges_m = {1.0};
    p.rings.clear();
    p.sectors.clear();
    for (std::size_t z = 0; z < zone_count; ++z) {
      p.edges_m.push_back(p.edges_m.back() + 3.0 + static_cast<double>(z));
      p.rings.push_back(1 + static_cast<int>(z % 3));
      p.sectors.push_back(8 + 4 * static_cast<int>(z));
    }
    const ZoneGround zones(p);
    Cloud c;
    testing::TestRng rng(11);
    const auto at = [&c](float r, float a) { c.push_back(r * std::cos(a), r * std::sin(a), 0.F); };
    for (const double e : p.edges_m) {
      for (const float off : {-0.2F, -1e-6F, 0.F, 1e-6F, 0.2F}) {
        for (int k = 0; k < 4; ++k) at(static_cast<float>(e) + off, rng.uniform(-3.2F, 3.2F));
      }
    }
    for (int i = 0; i < 4000; ++i) at(rng.uniform(0.F, 50.F), rng.uniform(-3.2F, 3.2F));
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    c.push_back(inf, 0.F, 0.F);
    c.push_back(-inf, inf, 0.F);
    c.push_back(nan, 2.F, 0.F);
    c.push_back(-0.F, 3.F, 0.F);
    Buffer<std::uint32_t> bins;
    zones.bins_of(c, bins);
    ASSERT_EQ(bins.size(), c.size());
    for (std::size_t i = 0; i < c.size(); ++i) {
      ASSERT_EQ(bins[i], zones.bin_of(c.x[i], c.y[i]))
          << zone_count << " zones, point " << i << " at " << c.x[i] << ", " << c.y[i];
      ASSERT_LT(bins[i], zones.bin_count());
    }
  }
}

// fast_atan2 four at a time takes absolute values by clearing the sign bit and picks the larger and smaller with
// maxps/minps: the scalar's bits, signed zeros, infinities and NaN included.
TEST(ZoneGround, FastAtan2FourAtATimeAsOneAtATime) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> v = {0.F, -0.F, 1.F, -1.F, 3.F, -3.F, 1e-30F, -1e-30F, 1e30F, -1e30F, inf, -inf, nan, -nan};
  testing::TestRng rng(3);
  for (int i = 0; i < 200; ++i) v.push_back(rng.uniform(-60.F, 60.F));
  for (std::size_t i = 0; i < v.size(); ++i) {
    for (std::size_t j = 0; j + 3 < v.size(); j += 4) {
      const simd::f32x4 y = simd::splat(v[i]), x = {v[j], v[j + 1], v[j + 2], v[j + 3]};
      const simd::f32x4 r = fast_atan2(y, x), q = fast_atan2(x, y);
      for (int l = 0; l < 4; ++l) {
        const float want = fast_atan2(v[i], x[l]), want_swapped = fast_atan2(x[l], v[i]);
        if (std::isnan(want)) {
          EXPECT_TRUE(std::isnan(r[l])) << v[i] << ", " << x[l];
        } else {
          EXPECT_EQ(std::bit_cast<std::uint32_t>(r[l]), std::bit_cast<std::uint32_t>(want)) << v[i] << ", " << x[l];
        }
        if (std::isnan(want_swapped)) {
          EXPECT_TRUE(std::isnan(q[l])) << x[l] << ", " << v[i];
        } else {
          EXPECT_EQ(std::bit_cast<std::uint32_t>(q[l]), std::bit_cast<std::uint32_t>(want_swapped))
              << x[l] << ", " << v[i];
        }
      }
    }
  }
}

// segment() labels bin by bin, four points at a time (bins of every size, so every tail), blending with the
// neighbour outside or inside per point; the labels must be label_one_at_a_time's to the bit, with and without
// blend_radial, and also with points that are not finite (a step with a NaN distance falls back to the
// one-at-a-time arithmetic; such points leave the planes NaN, but the two must still agree).
TEST(ZoneGround, LabelsFourAtATimeAsOneAtATime) {
  sim::Scene scene;
  scene.terrain.undulation_m = 0.4;
  scene.terrain.ridge_x_m = 21.0;
  scene.terrain.ridge_width_m = 5.0;
  scene.terrain.ridge_height_m = 1.0;
  scene.cylinders.push_back(sim::Cylinder{12.0, 1.5, 0.3, 1.8, 0.0});
  Cloud c = prepared(scene, 5.0);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  Cloud odd = c;  // and points no crop lets through: not finite
  odd.push_back(nan, 3.F, -0.9F);
  odd.push_back(20.F, inf, -0.9F);
  odd.push_back(inf, -inf, 0.F);
  odd.push_back(8.F, 1.F, nan);
  const auto same = [](float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0 || (a != a && b != b); };
  for (const Cloud* cloud : {&c, &odd}) {
    for (const bool blend : {true, false}) {
      ZoneParams zp;
      zp.blend_radial = blend;
      zp.max_below_m = 0.3;
      ZoneGround zones(zp);
      GroundLabels four, one;
      zones.segment(*cloud, four);
      zones.label_one_at_a_time(*cloud, one);
      ASSERT_EQ(four.height_m.size(), cloud->size());
      std::size_t blended = 0;
      for (std::size_t i = 0; i < cloud->size(); ++i) {
        ASSERT_TRUE(same(four.height_m[i], one.height_m[i]))
            << "point " << i << ": " << four.height_m[i] << " vs " << one.height_m[i];
        ASSERT_EQ(four.ground[i], one.ground[i]) << i;
        ASSERT_EQ(four.guessed[i], one.guessed[i]) << i;
        const float own = cloud->z[i] - zones.ground_z(cloud->x[i], cloud->y[i]);
        blended += same(own, four.height_m[i]) ? 0U : 1U;
      }
      if (cloud == &odd) continue;  // a NaN point in the innermost ring leaves every plane NaN: nothing to count
      if (blend) {
        EXPECT_GT(blended, cloud->size() / 4);  // the blend path was taken
      } else {
        EXPECT_EQ(blended, 0U);
      }
    }
  }
}

// Values for which libstdc++'s nth_element(v, v + nth, v + n) runs out of partitions and heap-selects: McIlroy's
// adversary ("A killer adversary for quicksort"), mirrored. Every value starts as "gas" (below everything solid);
// when two gas values meet, one of them freezes to the next solid value, each one lower than the last, so the
// pivots come out near the top and each partition cuts off a few elements at the top only.
std::vector<float> nth_element_killer(std::uint32_t n, std::uint32_t nth) {
  std::vector<std::uint32_t> val(n, 0), ids(n);
  for (std::uint32_t i = 0; i < n; ++i) ids[i] = i;
  std::uint32_t solid = 2 * n, candidate = 0;
  std::nth_element(ids.begin(), ids.begin() + nth, ids.end(), [&](std::uint32_t x, std::uint32_t y) {
    if (val[x] == 0 && val[y] == 0) val[x == candidate ? x : y] = solid--;
    if (val[x] == 0) {
      candidate = x;
    } else if (val[y] == 0) {
      candidate = y;
    }
    return val[x] < val[y];
  });
  std::vector<float> v(n);  // the same order, in metres about the ground
  for (std::uint32_t i = 0; i < n; ++i) v[i] = -1.F + 0.0005F * static_cast<float>(val[i]);
  return v;
}

// The seeds' height is the sum of a bin's lowest residuals in the order std::nth_element leaves them:
// nth_element_branchfree must leave every element where libstdc++ does, or the sum and the planes change. Arrays of
// every size up to 300, with ties, NaN, signed zeros and infinities, sorted and not, every nth.
TEST(ZoneGround, NthElementBranchFreeMovesElementsAsTheLibrary) {
  testing::TestRng rng(5);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const auto same = [](const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
  };
  std::vector<std::uint32_t> scratch;
  std::size_t gave_up = 0;
  for (int run = 0; run < 60000; ++run) {
    const auto n = static_cast<std::uint32_t>(run % 3 == 0 ? rng.next() % 301 : rng.next() % 24);
    std::vector<float> v(n);
    const int kind = run % 5;
    for (float& x : v) {
      const auto u = static_cast<std::uint32_t>(rng.next() >> 32U);
      switch (kind) {
        case 0: x = rng.uniform(-2.F, 2.F); break;
        case 1: x = static_cast<float>(u % 4U); break;  // many ties
        case 2: x = u % 40U == 0 ? nan : static_cast<float>(u % 8U) - 3.F; break;
        case 3: {
          const float odd[] = {0.F, -0.F, inf, -inf, 1.F, -1.F, 1e6F};
          x = odd[u % 7U];
          break;
        }
        default: x = rng.uniform(-1.F, 1.F); break;
      }
    }
    if (kind == 4 && run % 2 == 0) std::sort(v.begin(), v.end());
    if (kind == 4 && run % 2 == 1) std::sort(v.rbegin(), v.rend());
    const std::uint32_t nth = n == 0 ? 0 : static_cast<std::uint32_t>(rng.next() % n);
    std::vector<float> ours = v, lib = v;
    scratch.assign(2 * std::size_t{n} + 2, 0);
    const bool done = nth_element_branchfree(ours.data(), n, nth, scratch.data());
    std::nth_element(lib.begin(), lib.begin() + nth, lib.end());
    if (!done) {
      ++gave_up;
      continue;
    }
    ASSERT_TRUE(same(ours, lib)) << "run " << run << ", n " << n << ", nth " << nth;
  }
  EXPECT_LT(gave_up, 10U);
  // Where libstdc++ heap-selects, this one says so instead of answering.
  for (const std::uint32_t n : {32U, 64U, 256U}) {
    std::vector<float> v = nth_element_killer(n, 9);
    scratch.assign(2 * std::size_t{n} + 2, 0);
    EXPECT_FALSE(nth_element_branchfree(v.data(), n, 9, scratch.data())) << n;
  }
}

// A bin whose residuals make libstdc++ heap-select (the branch-free selection gives up): the zone ground selects its
// seeds with std::nth_element on the residuals again, and the bin gets its plane like any other.
TEST(ZoneGround, ABinTheSelectionGivesUpOnStillGetsItsPlane) {
  // 64 points in one bin of the first zone's outer ring (4 to 6 m, the sector from 0 to 22.5 degrees), heights in
  // the killer's order; nothing nearer, so the bin's prior is level (slope 0): its residuals are its heights.
  const std::vector<float> z = nth_element_killer(64, 9);
  Cloud c;
  for (std::uint32_t i = 0; i < 64; ++i) {
    const float r = 4.2F + 0.2F * static_cast<float>(i % 8U), a = 0.04F + 0.04F * static_cast<float>(i / 8U);
    c.push_back(r * std::cos(a), r * std::sin(a), z[i]);
  }
  std::vector<float> residuals = z;
  std::vector<std::uint32_t> scratch(2 * 64 + 2);
  ASSERT_FALSE(nth_element_branchfree(residuals.data(), 64, 9, scratch.data()));  // the case under test

  ZoneGround zones(ZoneParams{});
  GroundLabels labels, one;
  zones.segment(c, labels);
  for (std::size_t i = 0; i < c.size(); ++i) ASSERT_EQ(zones.bin_of(c.x[i], c.y[i]), zones.bin_of(c.x[0], c.y[0]));
  EXPECT_TRUE(zones.fitted_at(5.F, 0.2F));
  EXPECT_NEAR(zones.ground_z(5.F, 0.2F), -0.96F, 0.03F);
  zones.label_one_at_a_time(c, one);
  for (std::size_t i = 0; i < c.size(); ++i) {
    EXPECT_EQ(labels.ground[i], 1U) << i;
    EXPECT_EQ(std::memcmp(&labels.height_m[i], &one.height_m[i], sizeof(float)), 0) << i;
  }
}

// The ground's distances go through hypot_f: it must give std::hypot's bits, or heights (and obstacles) change.
TEST(ZoneGround, HypotGivesTheLibrarysBits) {
  testing::TestRng rng(11);
  const auto bits = [&rng] { return static_cast<std::uint32_t>(rng.next() >> 32U); };
  const auto from_bits = [](std::uint32_t u) {
    float f = 0.F;
    std::memcpy(&f, &u, sizeof f);
    return f;
  };
  const auto same = [](float a, float b) {
    return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b));
  };
  for (int i = 0; i < 2000000; ++i) {
    const float x = from_bits(bits()), y = from_bits(bits());  // every exponent, NaN and infinity among them
    ASSERT_TRUE(same(hypot_f(x, y), std::hypot(x, y))) << x << ", " << y;
  }
  for (int i = 0; i < 2000000; ++i) {  // and the ground's own scale: metres, near one another
    const float x = from_bits(0x3C000000U + bits() % 0x05000000U), y = from_bits(0x3C000000U + bits() % 0x05000000U);
    ASSERT_TRUE(same(hypot_f(x, -y), std::hypot(x, -y))) << x << ", " << y;
  }
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(hypot_f(inf, nan), inf);
  EXPECT_EQ(hypot_f(nan, -inf), inf);
  EXPECT_TRUE(std::isnan(hypot_f(nan, 1.F)));
  EXPECT_EQ(hypot_f(3e38F, 3e38F), inf);
  EXPECT_EQ(hypot_f(0.F, -0.F), 0.F);
}

}  // namespace
}  // namespace fieldguard::perception
