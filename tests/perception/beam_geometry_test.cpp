// The sensor's ring geometry and the rules that take it: the spacing at an elevation, the clustering radii per
// point on uneven rings (both structures still finding the same clusters), the canopy's ring grouping, and the
// pipeline taking the sensor's rings only when the configuration leaves the spacing to it.
#include "fieldguard/perception/beam_geometry.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "fieldguard/perception/canopy.hpp"
#include "fieldguard/perception/euclidean_cluster.hpp"
#include "fieldguard/perception/pipeline.hpp"
#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

constexpr double kRad = std::numbers::pi / 180.0;

// protocols.md §1.5 and §1.10; §2.4's example RS-32 table (the simulator's unit).
const std::vector<double> kHdl32e = {-30.67, -9.33, -29.33, -8.00, -28.00, -6.67, -26.67, -5.33,
                                     -25.33, -4.00, -24.00, -2.67, -22.67, -1.33, -21.33, 0.00,
                                     -20.00, 1.33,  -18.67, 2.67,  -17.33, 4.00,  -16.00, 5.33,
                                     -14.67, 6.67,  -13.33, 8.00,  -12.00, 9.33,  -10.67, 10.67};
const std::vector<double> kVlp16 = {-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15};
const std::vector<double> kRs32 = {-10.26, 0.30,  -6.41, -0.02, 2.28,  -0.33,  3.30,  -0.67,  4.61,  1.68,  7.02,
                                   1.30,   10.30, 1.00,  15.02, 0.70,  -25.00, -2.28, -14.64, -2.67, -7.91, -3.02,
                                   -5.41,  -3.30, -3.65, -1.02, -4.05, -1.33,  -4.39, -1.63,  -4.65, -1.98};

TEST(BeamGeometry, EvenRingsHaveOneSpacingTheirMedianGap) {
  const BeamGeometry hdl(kHdl32e);  // gaps of 1.33 and 1.34 degrees
  EXPECT_TRUE(hdl.is_uniform());
  EXPECT_NEAR(hdl.spacing_deg(-20.0), 1.33, 1e-9);
  EXPECT_NEAR(hdl.spacing_deg(40.0), 1.33, 1e-9);
  EXPECT_NEAR(BeamGeometry{}.spacing_deg(0.0), 1.33, 1e-12);  // the default: the HDL-32E's
  const BeamGeometry vlp(kVlp16);
  EXPECT_TRUE(vlp.is_uniform());
  EXPECT_DOUBLE_EQ(vlp.spacing_deg(3.0), 2.0);
  EXPECT_EQ(vlp.describe(), "16 rings from -15.00 to 15.00 deg, 2.00 deg apart");
  EXPECT_EQ(BeamGeometry::uniform(1.5).describe(), "1.50 deg apart everywhere");
}

TEST(BeamGeometry, UnevenRingsTakeTheLargerGapBesideTheNearestRing) {
  const BeamGeometry rs(kRs32);
  EXPECT_FALSE(rs.is_uniform());
  EXPECT_EQ(rs.rings(), 32U);
  EXPECT_NEAR(rs.min_spacing_deg(), 0.26, 1e-9);   // -4.65 .. -4.39
  EXPECT_NEAR(rs.max_spacing_deg(), 10.36, 1e-9);  // -25.00 .. -14.64
  EXPECT_NEAR(rs.spacing_deg(-0.02), 0.32, 1e-9);  // gaps 0.31 below, 0.32 above
  EXPECT_NEAR(rs.spacing_deg(0.1), 0.32, 1e-9);    // nearest ring -0.02
  EXPECT_NEAR(rs.spacing_deg(0.2), 0.40, 1e-9);    // nearest ring 0.30: 0.32 below, 0.40 above
  EXPECT_NEAR(rs.spacing_deg(-24.0), 10.36, 1e-9);
  EXPECT_NEAR(rs.spacing_deg(-40.0), 10.36, 1e-9);  // beyond the lowest ring: its gap
  EXPECT_NEAR(rs.spacing_deg(20.0), 4.72, 1e-9);    // beyond the highest: 10.30 .. 15.02
  EXPECT_EQ(rs.describe(), "32 rings from -25.00 to 15.02 deg, 0.26 to 10.36 deg apart");
  // The hot loops' table agrees with the exact spacing away from the bins' edges.
  for (const double e : {-20.0, -12.0, -6.0, -3.25, -1.6, 0.35, 3.2, 8.5, 12.0}) {  // away from midpoints
    const auto s = static_cast<float>(std::sin(e * kRad));
    EXPECT_NEAR(rs.tan_spacing(s), std::tan(rs.spacing_deg(e) * kRad), 1e-6) << e;
    EXPECT_NEAR(rs.spacing_rad(s), rs.spacing_deg(e) * kRad, 1e-6) << e;
  }
}

TEST(BeamGeometry, RefusesTooFewOrImpossibleRings) {
  EXPECT_THROW(BeamGeometry(std::vector<double>{1.0}), std::invalid_argument);
  EXPECT_THROW(BeamGeometry(std::vector<double>{1.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(BeamGeometry(std::vector<double>{1.0, 95.0}), std::invalid_argument);
  EXPECT_THROW(BeamGeometry(std::vector<double>{1.0, std::nan("")}), std::invalid_argument);
  EXPECT_THROW((void)BeamGeometry::uniform(0.0), std::invalid_argument);
  EXPECT_THROW((void)BeamGeometry::uniform(50.0), std::invalid_argument);
}

ClusterParams anisotropic(ClusterStructure s) {
  ClusterParams p;
  p.method = ClusterMethod::Anisotropic;
  p.structure = s;
  p.tolerance_m = 0.4;
  return p;
}

std::vector<std::vector<std::uint32_t>> sets_of(const Clusters& c) {
  std::vector<std::vector<std::uint32_t>> s;
  for (std::size_t i = 0; i < c.size(); ++i) s.emplace_back(c[i].begin(), c[i].end());
  return s;
}

// On uneven rings each point has its own radii: the grid (whose bounds take the largest growth and whose stacked
// cells the smallest) still finds the k-d tree's clusters, over the elevations where the RS-32's gaps change most.
TEST(BeamGeometry, UnevenRingsKdTreeAndGridAgree) {
  testing::TestRng rng{31};
  Cloud c;
  for (int i = 0; i < 6000; ++i) c.push_back(rng.uniform(-10, 50), rng.uniform(-10, 10), rng.uniform(-1.5F, 4.F));
  for (int i = 0; i < 1500; ++i) c.push_back(rng.uniform(1, 4), rng.uniform(-2, 2), rng.uniform(-1.F, 2.F));
  for (const ClusterMethod m : {ClusterMethod::Adaptive, ClusterMethod::Anisotropic}) {
    ClusterParams pk = anisotropic(ClusterStructure::KdTree);
    ClusterParams pg = anisotropic(ClusterStructure::Grid);
    pk.method = pg.method = m;
    EuclideanClusterer kd(pk);
    EuclideanClusterer grid(pg);
    kd.set_beams(BeamGeometry(kRs32));
    grid.set_beams(BeamGeometry(kRs32));
    Clusters a, b;
    kd.extract(c, a);
    grid.extract(c, b);
    EXPECT_GT(a.size(), 50U);
    EXPECT_EQ(sets_of(a), sets_of(b)) << (m == ClusterMethod::Adaptive ? "adaptive" : "anisotropic");
  }
}

// Two points 1 m apart vertically at 20 m: joined where the rings are 4.7 degrees apart (a radius of 4 x 20 x
// tan 4.72 = 6.6 m, capped at 3), not where they are 0.32 apart (1.8 x 0.4 = 0.45 m: under 1 m). With the
// HDL-32E's 1.33 everywhere (1.86 m) both pairs join.
TEST(BeamGeometry, TheRadiusFollowsTheRingsAtThePointsElevation) {
  ClusterParams p = anisotropic(ClusterStructure::Grid);
  p.method = ClusterMethod::Adaptive;
  const auto pair_at = [](double elevation_deg) {
    Cloud c;
    const auto x = static_cast<float>(20.0 * std::cos(elevation_deg * kRad));
    const auto z = static_cast<float>(20.0 * std::sin(elevation_deg * kRad));
    c.push_back(x, 0.F, z - 0.5F);
    c.push_back(x, 0.F, z + 0.5F);
    return c;
  };
  EuclideanClusterer even(p);
  EuclideanClusterer rs(p);
  rs.set_beams(BeamGeometry(kRs32));
  Clusters out;
  for (const double e : {0.0, 12.0}) {
    even.extract(pair_at(e), out);
    EXPECT_EQ(out.size(), 1U) << e;
  }
  rs.extract(pair_at(0.0), out);
  EXPECT_EQ(out.size(), 2U);
  rs.extract(pair_at(12.0), out);
  EXPECT_EQ(out.size(), 1U);
  EXPECT_NEAR(rs.horizontal_radius_at(20.F, static_cast<float>(std::sin(12.0 * kRad))), 3.0F, 1e-5F);
}

// The canopy meter groups samples into rings by half the spacing at their elevation: two RS-32 rings 0.32 degrees
// apart near the horizon are two rings (half the HDL-32E's spacing, 0.67, would make them one).
TEST(BeamGeometry, CanopyRingsAreTheSensorsRings) {
  Cloud c;
  for (const double e : {-0.02, 0.30}) {
    for (int k = 0; k < 12; ++k) {
      const double b = (k - 6) * 0.2 * kRad;
      const double r = 10.0 + ((k % 2 == 0) ? 0.0 : 0.3);  // a jagged ring: every other return 0.3 m deeper
      c.push_back(static_cast<float>(r * std::cos(e * kRad) * std::cos(b)),
                  static_cast<float>(r * std::cos(e * kRad) * std::sin(b)), static_cast<float>(r * std::sin(e * kRad)));
    }
  }
  RingJitterMeter hdl(1.33, 0.5);
  RingJitterMeter rs(1.33, 0.5);
  rs.set_beams(BeamGeometry(kRs32));
  // One ring of 24 samples alternating between the rings' interleaved bearings, or two rings of 12: 2 x 10 triples.
  EXPECT_EQ(rs.measure_all(c).triples, 20U);
  EXPECT_EQ(hdl.measure_all(c).triples, 22U);
}

TEST(BeamGeometry, PipelineTakesTheSensorsRingsOnlyWhenLeftToIt) {
  PipelineParams auto_spacing;
  Pipeline a(auto_spacing);
  EXPECT_NEAR(a.beams().spacing_deg(0.0), 1.33, 1e-12);
  EXPECT_TRUE(a.set_beams(BeamGeometry(kRs32)));
  EXPECT_EQ(a.beams(), BeamGeometry(kRs32));
  PipelineParams fixed;
  fixed.cluster.beam_spacing_deg = 2.0;
  Pipeline f(fixed);
  EXPECT_FALSE(f.set_beams(BeamGeometry(kRs32)));
  EXPECT_DOUBLE_EQ(f.beams().spacing_deg(0.0), 2.0);
}

}  // namespace
}  // namespace fieldguard::perception
