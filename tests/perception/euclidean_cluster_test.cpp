#include "fieldguard/perception/euclidean_cluster.hpp"

#include <gtest/gtest.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

using ClusterSets = std::vector<std::vector<std::uint32_t>>;

ClusterSets sets_of(const Clusters& c) {
  ClusterSets s;
  for (std::size_t i = 0; i < c.size(); ++i) s.emplace_back(c[i].begin(), c[i].end());
  return s;
}

// The adaptive radius these tests were written for (1.3 ring gaps, capped at 1.2 m), whatever the defaults are;
// anisotropic: the defaults of config/fieldguard.yaml's first anisotropic setting.
ClusterParams params(ClusterMethod m, ClusterStructure s, double tolerance = 0.6) {
  ClusterParams p;
  p.method = m;
  p.structure = s;
  p.tolerance_m = tolerance;
  if (m == ClusterMethod::Anisotropic) {
    p.beam_factor = 4.0;
    p.max_tolerance_m = 3.0;
    p.horizontal_beam_factor = 1.7;
    p.horizontal_max_tolerance_m = 1.5;
  } else {
    p.beam_factor = 1.3;
    p.max_tolerance_m = 1.2;
  }
  return p;
}

const char* method_name(ClusterMethod m) {
  return m == ClusterMethod::Fixed ? "Fixed" : m == ClusterMethod::Adaptive ? "Adaptive" : "Anisotropic";
}

// Two solid boxes (0.1 m lattice) whose facing sides are `gap` apart, 5 m ahead.
Cloud two_boxes(float gap) {
  Cloud c;
  testing::add_block(c, {5.0F, 0.0F, 0.0F}, {6, 6, 6}, 0.1F);        // x 5.0 .. 5.5
  testing::add_block(c, {5.5F + gap, 0.0F, 0.0F}, {6, 6, 6}, 0.1F);  // from 5.5 + gap
  return c;
}

class EveryClusterer : public ::testing::TestWithParam<std::tuple<ClusterMethod, ClusterStructure>> {};

TEST_P(EveryClusterer, BoxesHalfAMetreApartAreOneClusterAndPointSevenAreTwo) {
  const auto [method, structure] = GetParam();
  EuclideanClusterer clusterer(params(method, structure));
  Clusters out;
  clusterer.extract(two_boxes(0.5F), out);
  EXPECT_EQ(out.size(), 1U);
  clusterer.extract(two_boxes(0.7F), out);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_EQ(out[0].size(), 216U);
  EXPECT_EQ(out[1].size(), 216U);
}

TEST_P(EveryClusterer, EmptyAndSinglePoint) {
  const auto [method, structure] = GetParam();
  EuclideanClusterer clusterer(params(method, structure));
  Clusters out;
  clusterer.extract(Cloud{}, out);
  EXPECT_EQ(out.size(), 0U);
  Cloud one;
  one.push_back(3, 4, 5);
  clusterer.extract(one, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0][0], 0U);
}

// Every point in exactly one cluster; clusters by their lowest index; indices ascending in each.
TEST_P(EveryClusterer, OutputOrder) {
  const auto [method, structure] = GetParam();
  testing::TestRng rng{21};
  Cloud c;
  for (int i = 0; i < 3000; ++i) c.push_back(rng.uniform(0, 40), rng.uniform(-10, 10), rng.uniform(-1, 2));
  EuclideanClusterer clusterer(params(method, structure));
  Clusters out;
  clusterer.extract(c, out);
  std::vector<int> seen(c.size(), 0);
  std::uint32_t last_first = 0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    const auto members = out[k];
    ASSERT_FALSE(members.empty());
    EXPECT_TRUE(std::is_sorted(members.begin(), members.end()));
    if (k > 0) {
      EXPECT_GT(members[0], last_first);
    }
    last_first = members[0];
    for (const auto i : members) ++seen[i];
  }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
}

INSTANTIATE_TEST_SUITE_P(All, EveryClusterer,
                         ::testing::Combine(::testing::Values(ClusterMethod::Fixed, ClusterMethod::Adaptive,
                                                              ClusterMethod::Anisotropic),
                                            ::testing::Values(ClusterStructure::KdTree, ClusterStructure::Grid)),
                         [](const ::testing::TestParamInfo<std::tuple<ClusterMethod, ClusterStructure>>& p) {
                           return std::string(method_name(std::get<0>(p.param))) +
                                  (std::get<1>(p.param) == ClusterStructure::KdTree ? "KdTree" : "Grid");
                         });

// Reference: the clusters of pcl::EuclideanClusterExtraction over pcl::search::KdTree, on a random cloud with
// blobs, sparse noise and near-threshold spacings.
TEST(EuclideanClusterer, FixedRadiusGivesPclsClusters) {
  testing::TestRng rng{77};
  Cloud c;
  pcl::PointCloud<pcl::PointXYZ>::Ptr pc(new pcl::PointCloud<pcl::PointXYZ>);
  for (int i = 0; i < 6000; ++i) {
    float x, y, z;
    if (i % 3 == 0) {  // sparse: chains and singletons around the radius
      x = rng.uniform(0, 45);
      y = rng.uniform(-10, 10);
      z = rng.uniform(-1.5F, 3.F);
    } else {  // blobs
      const auto b = static_cast<float>((i / 7) % 40);
      x = 1.F + b + rng.uniform(0, 0.8F);
      y = -8.F + std::fmod(b * 3.7F, 16.F) + rng.uniform(0, 0.8F);
      z = rng.uniform(-1.F, 1.F);
    }
    c.push_back(x, y, z);
    pc->push_back(pcl::PointXYZ(x, y, z));
  }
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(pc);
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
  ec.setClusterTolerance(0.6);
  ec.setMinClusterSize(1);
  ec.setMaxClusterSize(100000);
  ec.setSearchMethod(tree);
  ec.setInputCloud(pc);
  std::vector<pcl::PointIndices> ref;
  ec.extract(ref);
  ClusterSets expected;
  for (const auto& r : ref) {
    std::vector<std::uint32_t> v(r.indices.begin(), r.indices.end());
    std::sort(v.begin(), v.end());
    expected.push_back(v);
  }
  std::sort(expected.begin(), expected.end());
  ASSERT_GT(expected.size(), 100U);

  for (const auto structure : {ClusterStructure::KdTree, ClusterStructure::Grid}) {
    EuclideanClusterer ours(params(ClusterMethod::Fixed, structure));
    Clusters out;
    ours.extract(c, out);
    auto got = sets_of(out);
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, expected) << (structure == ClusterStructure::KdTree ? "kdtree" : "grid");
  }
}

// A standing person at 30 m seen by an HDL-32E: three rings 0.70 m apart (30 m * tan(1.33 deg)), two returns
// each. A 0.6 m radius gives one cluster per ring; the adaptive radius (1.3 * 0.70 m there) gives one.
TEST(EuclideanClusterer, AdaptiveRadiusJoinsAFarPersonsRings) {
  Cloud person;
  for (const double elev : {-1.33, 0.0, 1.33}) {
    const auto z = static_cast<float>(30.0 * std::tan(elev * std::numbers::pi / 180.0));
    person.push_back(30.0F, 0.00F, z);
    person.push_back(30.0F, 0.08F, z);
  }
  for (const auto structure : {ClusterStructure::KdTree, ClusterStructure::Grid}) {
    Clusters out;
    EuclideanClusterer fixed(params(ClusterMethod::Fixed, structure));
    fixed.extract(person, out);
    EXPECT_EQ(out.size(), 3U);
    EuclideanClusterer adaptive(params(ClusterMethod::Adaptive, structure));
    adaptive.extract(person, out);
    EXPECT_EQ(out.size(), 1U);
    EXPECT_NEAR(adaptive.radius_at(30.F), 1.3F * 30.F * std::tan(1.33F * std::numbers::pi_v<float> / 180.F), 1e-4F);
  }
  // Near the sensor the adaptive radius is the fixed one: boxes 0.7 m apart at 5 m stay two.
  EuclideanClusterer adaptive(params(ClusterMethod::Adaptive, ClusterStructure::Grid));
  EXPECT_FLOAT_EQ(adaptive.radius_at(5.F), 0.6F);
  EXPECT_FLOAT_EQ(adaptive.radius_at(500.F), 1.2F);  // capped
}

// Both structures find the same clusters with the adaptive radius too, over ranges where it varies.
TEST(EuclideanClusterer, AdaptiveKdTreeAndGridAgree) {
  testing::TestRng rng{8};
  Cloud c;
  for (int i = 0; i < 5000; ++i) c.push_back(rng.uniform(-10, 50), rng.uniform(-10, 10), rng.uniform(-1.5F, 4.F));
  Clusters a, b;
  EuclideanClusterer kd(params(ClusterMethod::Adaptive, ClusterStructure::KdTree));
  EuclideanClusterer grid(params(ClusterMethod::Adaptive, ClusterStructure::Grid));
  kd.extract(c, a);
  grid.extract(c, b);
  EXPECT_GT(a.size(), 50U);
  EXPECT_EQ(sets_of(a), sets_of(b));
}

// A wide, sparse cloud makes the grid take larger cells (bounded memory); the clusters stay the same.
TEST(EuclideanClusterer, GridWithEnlargedCellsStaysExact) {
  testing::TestRng rng{3};
  Cloud c;
  for (int i = 0; i < 400; ++i) c.push_back(rng.uniform(-400, 400), rng.uniform(-400, 400), rng.uniform(-50, 50));
  for (int i = 0; i < 400; ++i) c.push_back(rng.uniform(0, 3), rng.uniform(0, 3), rng.uniform(0, 1));
  Clusters a, b;
  EuclideanClusterer kd(params(ClusterMethod::Fixed, ClusterStructure::KdTree));
  EuclideanClusterer grid(params(ClusterMethod::Fixed, ClusterStructure::Grid));
  kd.extract(c, a);
  grid.extract(c, b);
  EXPECT_EQ(sets_of(a), sets_of(b));
}

// The grid's cells are a piece of one cluster each, and neighbouring cells join through their nearest pair: a
// lattice just under the radius is one cluster, just over it all singletons (no pair within a cell is ever
// that far apart, so only the cross-cell tests decide), with either structure.
TEST(EuclideanClusterer, LatticeJustUnderAndOverTheRadius) {
  for (const auto structure : {ClusterStructure::KdTree, ClusterStructure::Grid}) {
    EuclideanClusterer clusterer(params(ClusterMethod::Fixed, structure));
    Clusters out;
    for (const float step : {0.59F, 0.61F}) {
      Cloud c;
      testing::add_block(c, {3.0F, -2.0F, -1.0F}, {8, 7, 5}, step);  // 280 points
      clusterer.extract(c, out);
      EXPECT_EQ(out.size(), step < 0.6F ? 1U : 280U) << step << (structure == ClusterStructure::Grid ? " grid" : " kd");
    }
  }
}

// Pairs of points in every direction, 0.59 m apart (one cluster each) and 0.61 m apart (two), spread over many
// cell offsets: two points far enough apart never share a grid cell, and near enough ones in two cells join.
TEST(EuclideanClusterer, PairsJustInsideAndOutsideTheRadius) {
  testing::TestRng rng{5};
  for (const float d : {0.59F, 0.61F}) {
    Cloud c;
    for (int i = 0; i < 300; ++i) {
      float u[3] = {rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)};
      const float len = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      if (len < 0.1F) continue;
      const float x = 2.F + 3.F * static_cast<float>(i % 15) + rng.uniform(0, 1);
      const float y = -9.F + 3.F * static_cast<float>(i / 15) + rng.uniform(0, 1);
      const float z = rng.uniform(-1, 1);
      c.push_back(x, y, z);
      c.push_back(x + d * u[0] / len, y + d * u[1] / len, z + d * u[2] / len);
    }
    for (const auto structure : {ClusterStructure::KdTree, ClusterStructure::Grid}) {
      EuclideanClusterer clusterer(params(ClusterMethod::Fixed, structure));
      Clusters out;
      clusterer.extract(c, out);
      EXPECT_EQ(out.size(), d < 0.6F ? c.size() / 2 : c.size())
          << d << (structure == ClusterStructure::Grid ? " grid" : " kd");
    }
  }
}

// A shed's walls after the voxel grid: two dense 0.15 m lattices (4 m long, 3 m high) whose facing sides are
// 0.55 m apart are one cluster, 0.65 m apart two; the grid agrees with the k-d tree point for point.
TEST(EuclideanClusterer, DenseWallsJoinOrStayApart) {
  for (const auto method : {ClusterMethod::Fixed, ClusterMethod::Adaptive, ClusterMethod::Anisotropic}) {
    for (const float gap : {0.55F, 0.65F}) {
      Cloud c;
      testing::add_block(c, {6.0F, -2.0F, -1.0F}, {2, 27, 20}, 0.15F);         // x 6.00 .. 6.15
      testing::add_block(c, {6.15F + gap, -2.0F, -1.0F}, {2, 27, 20}, 0.15F);  // the facing wall
      Clusters a, b;
      EuclideanClusterer kd(params(method, ClusterStructure::KdTree));
      EuclideanClusterer grid(params(method, ClusterStructure::Grid));
      kd.extract(c, a);
      grid.extract(c, b);
      EXPECT_EQ(b.size(), gap < 0.6F ? 1U : 2U) << gap;
      EXPECT_EQ(sets_of(a), sets_of(b)) << gap;
    }
  }
}

// A point that is not finite cannot be put in a cell: the grid then clusters over the k-d tree, where a NaN is
// near nothing (a singleton), and the finite points cluster as ever.
TEST(EuclideanClusterer, GridWithNonFinitePointsMatchesTheKdTree) {
  Cloud c = two_boxes(0.5F);
  c.push_back(std::numeric_limits<float>::quiet_NaN(), 0.F, 0.F);
  c.push_back(5.2F, 0.2F, 0.2F);
  Clusters a, b;
  EuclideanClusterer kd(params(ClusterMethod::Fixed, ClusterStructure::KdTree));
  EuclideanClusterer grid(params(ClusterMethod::Fixed, ClusterStructure::Grid));
  kd.extract(c, a);
  grid.extract(c, b);
  EXPECT_EQ(sets_of(a), sets_of(b));
  ASSERT_EQ(b.size(), 2U);
  EXPECT_EQ(b[1].size(), 1U);  // the NaN
  EXPECT_EQ(b[1][0], 432U);
}

TEST(EuclideanClusterer, RefusesImpossibleRadii) {
  EXPECT_THROW(EuclideanClusterer(params(ClusterMethod::Fixed, ClusterStructure::Grid, 0.0)), std::invalid_argument);
  ClusterParams p = params(ClusterMethod::Adaptive, ClusterStructure::Grid);
  p.beam_factor = 40.0;  // 0.93 m per metre
  EXPECT_THROW(EuclideanClusterer{p}, std::invalid_argument);
  ClusterParams a = params(ClusterMethod::Anisotropic, ClusterStructure::Grid);
  a.horizontal_beam_factor = 40.0;
  EXPECT_THROW(EuclideanClusterer{a}, std::invalid_argument);
  a = params(ClusterMethod::Anisotropic, ClusterStructure::Grid);
  a.beam_factor = 40.0;
  EXPECT_THROW(EuclideanClusterer{a}, std::invalid_argument);
  a = params(ClusterMethod::Anisotropic, ClusterStructure::Grid);
  a.horizontal_max_tolerance_m = std::numeric_limits<double>::infinity();
  EXPECT_THROW(EuclideanClusterer{a}, std::invalid_argument);
}

// --- Anisotropic: a horizontal and a vertical radius.

constexpr float kDeg = std::numbers::pi_v<float> / 180.F;

// One scan ring's returns on a porous crown at `range` (m) of ring elevation `elev_deg`: points every 0.15 m
// (the voxel grid) across `width` m centred on bearing `bearing_deg`, each at a depth inside the crown that
// steps through `depths` (m), as the exponential stopping depth scatters them.
void add_ring_slice(Cloud& c, float range, float bearing_deg, float elev_deg, float width,
                    std::initializer_list<float> depths) {
  const int n = static_cast<int>(width / 0.15F) + 1;
  int k = 0;
  for (int i = 0; i < n; ++i) {
    const float d = range + depths.begin()[static_cast<std::size_t>(k++) % depths.size()];
    const float b = bearing_deg * kDeg + (static_cast<float>(i) * 0.15F - 0.5F * width) / range;
    const float r = d * std::cos(elev_deg * kDeg);
    c.push_back(r * std::cos(b), r * std::sin(b), d * std::sin(elev_deg * kDeg));
  }
}

// The same clusters from both structures, over ranges where both radii vary and hit their caps.
TEST(EuclideanClusterer, AnisotropicKdTreeAndGridAgree) {
  testing::TestRng rng{21};
  Cloud c;
  for (int i = 0; i < 5000; ++i) c.push_back(rng.uniform(-10, 50), rng.uniform(-10, 10), rng.uniform(-1.5F, 4.F));
  for (int i = 0; i < 1500; ++i) c.push_back(rng.uniform(5, 9), rng.uniform(-2, 2), rng.uniform(-1.F, 3.F));
  Clusters a, b;
  EuclideanClusterer kd(params(ClusterMethod::Anisotropic, ClusterStructure::KdTree, 0.4));
  EuclideanClusterer grid(params(ClusterMethod::Anisotropic, ClusterStructure::Grid, 0.4));
  kd.extract(c, a);
  grid.extract(c, b);
  EXPECT_GT(a.size(), 50U);
  EXPECT_EQ(sets_of(a), sets_of(b));
}

// The grid works four at a time in places: the points' cells and radii (the last n % 4 one at a time), empty
// columns, and the runs of cells a cell looks back over (a run's last group reads past its end, masked). Clouds of
// 1 to 13 points, and sparse rows of small clumps (many empty columns, runs of one to three cells), must give the
// k-d tree's clusters, for every radius model.
TEST(EuclideanClusterer, GridTailsAndShortRunsMatchTheKdTree) {
  testing::TestRng rng{33};
  std::vector<Cloud> clouds;
  for (int n = 1; n <= 13; ++n) {
    Cloud c;
    for (int i = 0; i < n; ++i) c.push_back(rng.uniform(3, 6), rng.uniform(-1, 1), rng.uniform(-0.5F, 0.5F));
    clouds.push_back(c);
  }
  for (int k = 0; k < 3; ++k) {
    Cloud c;
    for (int clump = 0; clump < 150; ++clump) {
      const float x = rng.uniform(-8, 45), y = rng.uniform(-8, 8), z = rng.uniform(-1, 3);
      const int m = 1 + clump % (k + 3);
      for (int i = 0; i < m; ++i) {
        c.push_back(x + rng.uniform(-0.3F, 0.3F), y + rng.uniform(-0.3F, 0.3F), z + rng.uniform(-0.6F, 0.6F));
      }
    }
    clouds.push_back(c);
  }
  for (const auto method : {ClusterMethod::Fixed, ClusterMethod::Adaptive, ClusterMethod::Anisotropic}) {
    for (const Cloud& c : clouds) {
      Clusters a, b;
      EuclideanClusterer kd(params(method, ClusterStructure::KdTree, 0.4));
      EuclideanClusterer grid(params(method, ClusterStructure::Grid, 0.4));
      kd.extract(c, a);
      grid.extract(c, b);
      ASSERT_EQ(sets_of(a), sets_of(b)) << method_name(method) << ", " << c.size() << " points";
      ASSERT_EQ(b.indices.size(), c.size());
    }
  }
}

// The grid structure's cell edge for radius `t` over a cloud of this extent (euclidean_cluster.cpp: the radius less
// the rounding allowance, over sqrt 3), as the tests that build cell-edge cases compute it.
float grid_edge(float t, float extent) {
  const float rounding = 8.F * extent * std::numeric_limits<float>::epsilon() + 1e-3F;
  return (t * 0.999F - 2.F * rounding) / std::numbers::sqrt3_v<float>;
}

// A point on the cloud's upper bound whose cell, computed in float, rounds up to one past the grid's last (the
// grid's cell count comes from the same span in double): it must land in the last cell, on x and on z, four at a
// time (the first four points) as one by one. The spans that do this are searched for here with the grid's cell
// edge for a 0.6 m radius (euclidean_cluster.cpp: the radius less the rounding allowance, over sqrt 3); should
// that formula change, the search finds none and the test says so.
TEST(EuclideanClusterer, GridPointOnTheUpperBoundStaysInTheLastCell) {
  // Whether a span's float cell index is the count of cells the double division gives (one past the last).
  const auto past_the_last = [](float span, float edge) {
    const auto cells = static_cast<std::size_t>(static_cast<double>(span) / static_cast<double>(edge)) + 1;
    return static_cast<std::size_t>(static_cast<std::int32_t>(span * (1.F / edge))) >= cells;
  };
  // The floats about k edges long (the edge guessed from an extent near it when the span sets the extent), for k in
  // [k0, k1): the first that is one past the last, or 0.
  const auto find_span = [&](float t, int k0, int k1, bool sets_extent, float extent) {
    for (int k = k0; k < k1; ++k) {
      const float guess = grid_edge(t, sets_extent ? static_cast<float>(k) * t / 1.7F : extent);
      auto span = static_cast<float>(k * static_cast<double>(guess));
      for (int step = 0; step < 32; ++step) span = std::nextafter(span, 1e9F);
      for (int step = 0; step < 64; ++step, span = std::nextafter(span, 0.F)) {
        if (past_the_last(span, grid_edge(t, sets_extent ? span : extent))) return span;
      }
    }
    return 0.F;
  };
  int cases = 0;
  for (int i = 0; i < 60 && cases < 3; ++i) {
    const float t = 0.3F + 0.01F * static_cast<float>(i);
    const float x_span = find_span(t, 40, 120, true, 0.F);  // x sets the extent, so the edge
    if (x_span == 0.F) continue;
    const float z_span = find_span(t, 3, 40, false, x_span);
    if (z_span == 0.F) continue;
    ++cases;
    for (const bool in_first_four : {true, false}) {
      // A row along x from 0 to x_span, 0.2 m apart (one cluster), a column at its far end up to z_span, and
      // an isolated point; the two corner points on the upper bounds among the first four or the last ones.
      Cloud c;
      const auto corners = [&] {
        c.push_back(x_span, 0.F, 0.F);
        c.push_back(x_span, 0.F, z_span);
      };
      if (in_first_four) corners();
      c.push_back(0.F, 0.F, 0.F);
      c.push_back(x_span * 0.5F, 3.F, 0.F);  // alone
      for (float x = 0.2F; x < x_span; x += 0.2F) c.push_back(x, 0.F, 0.F);
      for (float z = 0.2F; z < z_span; z += 0.2F) c.push_back(x_span, 0.F, z);
      if (!in_first_four) {
        // Past the last full four (one by one): points on the row's start until the count is a multiple of four.
        for (float x = 0.05F; c.size() % 4 != 0; x += 0.05F) c.push_back(x, 0.F, 0.F);
        corners();
      }
      Clusters kd_out, grid_out;
      const ClusterParams kd = params(ClusterMethod::Fixed, ClusterStructure::KdTree, static_cast<double>(t));
      const ClusterParams grid = params(ClusterMethod::Fixed, ClusterStructure::Grid, static_cast<double>(t));
      EuclideanClusterer(kd).extract(c, kd_out);
      EuclideanClusterer(grid).extract(c, grid_out);
      EXPECT_EQ(sets_of(grid_out), sets_of(kd_out)) << "radius " << t << ", x span " << x_span << ", z span " << z_span;
      EXPECT_EQ(kd_out.size(), 2U);
    }
  }
  EXPECT_GT(cases, 0) << "no span rounds up to one past the last cell: has the grid's cell edge changed?";
}

// Within a column, each cell looks down at the cells below it and stops at the first one under its stencil's lowest
// z cell, `reach` z cells below its own (euclidean_cluster.cpp: reach = (radius + 1 mm) / edge, rounded down, + 1).
// A cell exactly `reach` z cells below may still hold a point within the radius: its top and the looking cell's
// bottom are reach - 1 edges apart, which is mostly under the radius (by less than an edge). So the look must go
// down to that cell too. The case: three points in one column 2 m out (near enough that its z cells are not
// stacked) and 14 m and more high, so that every radius (and the stencil) is the 1.2 m cap. From the bottom: q, p
// and a. a is 1.2 m less 4 mm above q, so the two join;
// q sits near the top of its z cell and a just above the bottom of its own, `reach` z cells apart. p is just under
// a's z cell, at the column's opposite corner: it joins a, not q. a's nearest cell below is p, which is not in q's
// cluster, so a must go on down to q: that look alone makes the three one cluster. A lone point far off is the
// lowest point (so the z cells count from it, and q need not start a cell) and the farthest (so it sets the extent,
// and with it the edge). The radii for which this holds are searched for with the grid's cell edge and stencil
// formula; should those change, the search finds none and the test says so.
TEST(EuclideanClusterer, GridColumnLookReachesTheStencilsLowestCell) {
  const float cap = 1.2F;  // params(): the adaptive radius cap
  const float z0 = 14.F;   // the lone point's height
  const float s = 0.004F;
  int cases = 0;
  for (int i = 0; i <= 30; ++i) {
    const float t = 0.3F + 0.01F * static_cast<float>(i);
    ClusterParams kd = params(ClusterMethod::Adaptive, ClusterStructure::KdTree, static_cast<double>(t));
    kd.beam_factor = 4.0;  // 0.093 m per metre of range: the cap from 13 m on
    ClusterParams grid = kd;
    grid.structure = ClusterStructure::Grid;
    // The grid's cell edge (the extent is 20: the lone point's x) and a cell's stencil depth in z cells at the cap.
    const float edge = grid_edge(t, 20.F);
    const float inv = 1.F / edge;
    const auto reach = static_cast<std::int32_t>((cap + 1e-3F) * inv) + 1;
    const auto cell = [inv](float v, float origin) { return static_cast<std::int32_t>((v - origin) * inv); };
    const float bottom = z0 + 8.F * edge;  // a's z cell's bottom, about
    const float w = 0.9F * edge;           // p's offset from q and a on x and on y
    Cloud c;
    c.push_back(2.F, 0.F, bottom - cap + 2.F * s);  // q
    c.push_back(2.F + w, w, bottom - s);            // p
    c.push_back(2.F, 0.F, bottom + s);              // a
    c.push_back(20.F, 0.F, z0);                     // alone
    // Whether two points join at the cap, as the pair tests compute it.
    const auto joins = [&](std::size_t m, std::size_t n) {
      const float dx = c.x[n] - c.x[m], dy = c.y[n] - c.y[m], dz = c.z[n] - c.z[m];
      return dx * dx + dy * dy + dz * dz < cap * cap;
    };
    const EuclideanClusterer probe(kd);
    const bool all_capped = probe.radius_at(std::sqrt(c.x[0] * c.x[0] + c.z[0] * c.z[0])) == cap;  // q: the nearest
    const bool one_column = cell(c.x[1], 2.F) == 0 && cell(c.y[1], 0.F) == 0;
    const std::int32_t qz = cell(c.z[0], z0), pz = cell(c.z[1], z0), az = cell(c.z[2], z0);
    if (!all_capped || !one_column || az - qz != reach || az - pz != 1 || !joins(0, 2) || !joins(1, 2) || joins(0, 1)) {
      continue;
    }
    ++cases;
    Clusters kd_out, grid_out;
    EuclideanClusterer(kd).extract(c, kd_out);
    EuclideanClusterer(grid).extract(c, grid_out);
    const ClusterSets expected = {{0U, 1U, 2U}, {3U}};
    EXPECT_EQ(sets_of(kd_out), expected) << "radius " << t;
    EXPECT_EQ(sets_of(grid_out), expected) << "radius " << t << ", edge " << edge << ", reach " << reach;
  }
  EXPECT_GT(cases, 0) << "no radius puts q exactly at the bottom of a's stencil: has the grid's cell edge changed?";
}

// Far out the grid stacks z cells into taller ones (the radii are large there): two vertical runs of points
// 30 m out join across a gap just under the vertical radius and stay apart across one just over it, and dense
// far clouds give the k-d tree's clusters, for both growing radii.
TEST(EuclideanClusterer, FarTallCellsStayExact) {
  for (const auto method : {ClusterMethod::Adaptive, ClusterMethod::Anisotropic}) {
    const EuclideanClusterer probe(params(method, ClusterStructure::Grid, 0.4));
    for (const float factor : {0.97F, 1.03F}) {
      Cloud c;
      const float x = 30.F;
      for (int i = 0; i < 8; ++i) c.push_back(x, 0.F, -1.F + 0.15F * static_cast<float>(i));
      const float top = -1.F + 0.15F * 7.F;
      const float gap = factor * probe.radius_at(std::sqrt(x * x + top * top));
      for (int i = 0; i < 8; ++i) c.push_back(x, 0.F, top + gap + 0.15F * static_cast<float>(i));
      for (const auto structure : {ClusterStructure::KdTree, ClusterStructure::Grid}) {
        EuclideanClusterer e(params(method, structure, 0.4));
        Clusters out;
        e.extract(c, out);
        EXPECT_EQ(out.size(), factor < 1.F ? 1U : 2U)
            << factor << (structure == ClusterStructure::Grid ? " grid" : " kd");
      }
    }
    testing::TestRng rng{33};
    Cloud c;
    for (int k = 0; k < 40; ++k) {  // clumps (dense: tall cells of many points) and the odd stray point
      const float cx = rng.uniform(20, 48), cy = rng.uniform(-10, 10), cz = rng.uniform(-1.5F, 5.F);
      for (int i = 0; i < 60; ++i) {
        c.push_back(cx + rng.uniform(-0.4F, 0.4F), cy + rng.uniform(-0.4F, 0.4F), cz + rng.uniform(-0.8F, 0.8F));
      }
      c.push_back(cx + rng.uniform(-3, 3), cy + rng.uniform(-3, 3), cz + rng.uniform(-3, 3));
    }
    Clusters a, b;
    EuclideanClusterer kd(params(method, ClusterStructure::KdTree, 0.4));
    EuclideanClusterer grid(params(method, ClusterStructure::Grid, 0.4));
    kd.extract(c, a);
    grid.extract(c, b);
    EXPECT_GT(a.size(), 5U);
    EXPECT_EQ(sets_of(a), sets_of(b));
  }
}

// The grid joins column by column, and passes over a pair of columns each wholly in one cluster, the same one. A
// column whose cells are in two clusters (two clumps 4 m apart one above the other) joins both through a vertical
// chain of points in the column beside it, before it in cell order or after it; without the chain they stay
// apart. And random towers of such clumps, some of them chained: the k-d tree's clusters.
TEST(EuclideanClusterer, GridColumnsSplitInHeightJoinThroughTheirNeighbours) {
  const auto clumps = [](Cloud& c, float x) {
    for (int i = 0; i < 3; ++i) c.push_back(x, 0.05F, 0.1F * static_cast<float>(i));
    for (int i = 0; i < 3; ++i) c.push_back(x, 0.05F, 4.F + 0.1F * static_cast<float>(i));
  };
  const auto chain = [](Cloud& c, float x) {
    for (int i = 0; i <= 28; ++i) c.push_back(x, 0.05F, 0.15F * static_cast<float>(i));
  };
  for (const auto method : {ClusterMethod::Fixed, ClusterMethod::Adaptive, ClusterMethod::Anisotropic}) {
    for (const float chain_dx : {-0.25F, 0.25F, 0.F}) {  // 0: no chain
      Cloud c;
      clumps(c, 10.F);
      if (chain_dx != 0.F) chain(c, 10.F + chain_dx);
      for (const auto structure : {ClusterStructure::KdTree, ClusterStructure::Grid}) {
        EuclideanClusterer e(params(method, structure, 0.4));
        Clusters out;
        e.extract(c, out);
        EXPECT_EQ(out.size(), chain_dx != 0.F ? 1U : 2U)
            << method_name(method) << " chain " << chain_dx << (structure == ClusterStructure::Grid ? " grid" : " kd");
      }
    }
    testing::TestRng rng{59};
    Cloud c;
    for (int t = 0; t < 300; ++t) {
      const float x = rng.uniform(4, 30), y = rng.uniform(-6, 6);
      const int levels = 1 + t % 4;
      for (int l = 0; l < levels; ++l) {
        const float z = rng.uniform(-1.5F, 6.F);
        for (int i = 0; i < 4; ++i) {
          c.push_back(x + rng.uniform(-0.1F, 0.1F), y + rng.uniform(-0.1F, 0.1F), z + 0.1F * static_cast<float>(i));
        }
      }
      if (t % 3 == 0) {
        const float cx = x + rng.uniform(-0.5F, 0.5F), cy = y + rng.uniform(-0.5F, 0.5F);
        for (int i = 0; i < 40; ++i) c.push_back(cx, cy, -1.5F + 0.2F * static_cast<float>(i));
      }
    }
    // Lone columns of a few points each (a column's cells below a cell may be in several clusters, which the
    // cell may join at once: its nearest one below must not end the look).
    for (int t = 0; t < 400; ++t) {
      const float x = 4.F + 3.F * static_cast<float>(t % 10), y = -30.F + 3.F * static_cast<float>(t / 10);
      for (int i = 0; i < 6; ++i) {
        c.push_back(x + rng.uniform(0.F, 0.2F), y + rng.uniform(0.F, 0.2F), rng.uniform(0.F, 2.5F));
      }
    }
    Clusters a, b;
    EuclideanClusterer kd(params(method, ClusterStructure::KdTree, 0.4));
    EuclideanClusterer grid(params(method, ClusterStructure::Grid, 0.4));
    kd.extract(c, a);
    grid.extract(c, b);
    EXPECT_GT(a.size(), 50U) << method_name(method);
    EXPECT_EQ(sets_of(a), sets_of(b)) << method_name(method);
  }
}

// The grid passes over a column with no cell below the looking cell in the radii order. That column's lowest cell
// may be mid-column (its point nearest the sensor), not its first: a point in the next column beside a column
// 20 m out, nearer than the column's bottom point and farther than its middle one, joins the middle one; bottom
// and top, 3 m away, stay apart.
TEST(EuclideanClusterer, GridLooksIntoAColumnThroughItsNearestCell) {
  for (const auto method : {ClusterMethod::Fixed, ClusterMethod::Adaptive, ClusterMethod::Anisotropic}) {
    Cloud c;
    c.push_back(20.F, 0.F, -3.F);
    c.push_back(20.F, 0.F, 0.F);
    c.push_back(20.F, 0.F, 3.F);
    c.push_back(20.F, 0.25F, 0.1F);  // y: the next column (cells of 0.4 / sqrt(3) m)
    for (const auto structure : {ClusterStructure::KdTree, ClusterStructure::Grid}) {
      EuclideanClusterer e(params(method, structure, 0.4));
      Clusters out;
      e.extract(c, out);
      EXPECT_EQ(sets_of(out), (ClusterSets{{0}, {1, 3}, {2}}))
          << method_name(method) << (structure == ClusterStructure::Grid ? " grid" : " kd");
    }
  }
}

// The grid skips a cell pair whose point boxes are farther apart than the looking cell's radii. Pairs of small
// clumps whose nearest points lie just inside or just outside the joining distance, in every direction (the
// vertical and horizontal radii differ), 5-45 m out: the k-d tree's clusters, with both outcomes common.
TEST(EuclideanClusterer, GridCellBoxesKeepPairsNearTheRadius) {
  for (const auto method : {ClusterMethod::Fixed, ClusterMethod::Adaptive, ClusterMethod::Anisotropic}) {
    const EuclideanClusterer probe(params(method, ClusterStructure::Grid, 0.4));
    testing::TestRng rng{47};
    Cloud c;
    constexpr int kPairs = 150;  // 4 m apart side by side, 9 m on top of each other: each pair alone
    for (int k = 0; k < kPairs; ++k) {
      const float px = 5.F + 4.F * static_cast<float>(k % 10), py = -8.F + 4.F * static_cast<float>(k / 10 % 5);
      const float pz = rng.uniform(-1.5F, 0.F) + 9.F * static_cast<float>(k / 50);
      const float range = std::sqrt(px * px + py * py + pz * pz);
      const float h = probe.horizontal_radius_at(range), v = probe.radius_at(range);
      const float az = rng.uniform(0.F, 2.F * std::numbers::pi_v<float>), el = rng.uniform(-1.5F, 1.5F);
      const float f = rng.uniform(0.97F, 1.03F);
      const float dx = f * h * std::cos(el) * std::cos(az), dy = f * h * std::cos(el) * std::sin(az);
      const float dz = f * v * std::sin(el);
      c.push_back(px, py, pz);
      c.push_back(px + dx, py + dy, pz + dz);
      // each end a clump: its other points on the far side from the other end
      for (int i = 0; i < 3; ++i) {
        const float s = rng.uniform(0.02F, 0.08F);
        c.push_back(px - s * dx, py - s * dy, pz - s * dz);
        c.push_back(px + (1.F + s) * dx, py + (1.F + s) * dy, pz + (1.F + s) * dz);
      }
    }
    Clusters a, b;
    EuclideanClusterer kd(params(method, ClusterStructure::KdTree, 0.4));
    EuclideanClusterer grid(params(method, ClusterStructure::Grid, 0.4));
    kd.extract(c, a);
    grid.extract(c, b);
    EXPECT_GT(a.size(), static_cast<std::size_t>(kPairs) * 6 / 5) << method_name(method);
    EXPECT_LT(a.size(), static_cast<std::size_t>(kPairs) * 9 / 5) << method_name(method);
    EXPECT_EQ(sets_of(a), sets_of(b)) << method_name(method);
  }
}

TEST(EuclideanClusterer, AnisotropicRadii) {
  const EuclideanClusterer e(params(ClusterMethod::Anisotropic, ClusterStructure::Grid, 0.4));
  const float gap = std::tan(1.33F * kDeg);
  EXPECT_FLOAT_EQ(e.radius_at(2.F), 0.4F);  // both floored at tolerance_m near the sensor
  EXPECT_FLOAT_EQ(e.horizontal_radius_at(2.F), 0.4F);
  EXPECT_NEAR(e.radius_at(20.F), 4.F * 20.F * gap, 1e-4F);
  EXPECT_NEAR(e.horizontal_radius_at(20.F), 1.7F * 20.F * gap, 1e-4F);
  EXPECT_FLOAT_EQ(e.radius_at(500.F), 3.F);  // capped
  EXPECT_FLOAT_EQ(e.horizontal_radius_at(500.F), 1.5F);
  const EuclideanClusterer f(params(ClusterMethod::Adaptive, ClusterStructure::Grid));
  EXPECT_FLOAT_EQ(f.horizontal_radius_at(30.F), f.radius_at(30.F));  // one radius when not anisotropic
}

// Two crowns side by side at 8 m whose nearest returns are 0.45 m apart, each four rings of porous returns: the
// adaptive radius (0.6 m there) joins them, the anisotropic one (0.4 m horizontally) keeps them two, each one
// cluster. (Nearer than 0.4 m they would join: the horizontal radius is the floor of what stays apart.)
TEST(EuclideanClusterer, AnisotropicKeepsCrownsSideBySideTwo) {
  Cloud c;
  for (const float elev : {-2.67F, -1.33F, 0.F, 1.33F}) {
    // Tangential offsets at 8 m: the first slice's returns from -0.8 to 0.7 m, the second's from 1.15 m.
    add_ring_slice(c, 8.F, 0.F, elev, 1.6F, {0.F, 0.1F, 0.05F});
    add_ring_slice(c, 8.F, (0.7F + 0.45F + 0.8F) / 8.F / kDeg, elev, 1.6F, {0.F, 0.1F, 0.05F});
  }
  const std::size_t half = c.size() / 2;
  for (const auto structure : {ClusterStructure::KdTree, ClusterStructure::Grid}) {
    Clusters out;
    EuclideanClusterer adaptive(params(ClusterMethod::Adaptive, structure));
    adaptive.extract(c, out);
    EXPECT_EQ(out.size(), 1U);
    EuclideanClusterer aniso(params(ClusterMethod::Anisotropic, structure, 0.4));
    aniso.extract(c, out);
    ASSERT_EQ(out.size(), 2U);
    EXPECT_EQ(out[0].size(), half);
    EXPECT_EQ(out[1].size(), half);
  }
}

// A porous crown at 25 m: three rings 0.58 m apart (25 m * tan(1.33 deg)) whose returns stopped at depths that
// differ by 0.6 m and more from ring to ring. The adaptive radius (0.76 m there) leaves three ring slices; the
// anisotropic one (2.3 m vertically, 1.0 m horizontally) one crown.
TEST(EuclideanClusterer, AnisotropicJoinsAPorousCrownsRingSlices) {
  Cloud c;
  add_ring_slice(c, 25.F, 10.F, -1.33F, 2.F, {0.F, 0.05F});
  add_ring_slice(c, 25.F, 10.F, 0.F, 2.F, {0.65F, 0.7F});
  add_ring_slice(c, 25.F, 10.F, 1.33F, 2.F, {1.3F, 1.35F});
  for (const auto structure : {ClusterStructure::KdTree, ClusterStructure::Grid}) {
    Clusters out;
    EuclideanClusterer adaptive(params(ClusterMethod::Adaptive, structure));
    adaptive.extract(c, out);
    EXPECT_EQ(out.size(), 3U);
    EuclideanClusterer aniso(params(ClusterMethod::Anisotropic, structure, 0.4));
    aniso.extract(c, out);
    EXPECT_EQ(out.size(), 1U);
  }
}

// A person side-on at 30 m: three rings 0.70 m apart, two or three returns each, the legs' ring 0.25 m off the
// torso's horizontally (a stride). One cluster; and a second person 1.5 m beside them stays apart (the
// horizontal radius there is 1.19 m).
TEST(EuclideanClusterer, AnisotropicKeepsAFarPersonOneCluster) {
  Cloud c;
  const float ring = 30.F * std::tan(1.33F * kDeg);
  for (const float y0 : {0.F, 0.16F + 1.5F}) {
    c.push_back(30.25F, y0 + 0.00F, -ring);  // legs
    c.push_back(30.25F, y0 + 0.08F, -ring);
    c.push_back(30.00F, y0 + 0.00F, 0.F);  // torso
    c.push_back(30.00F, y0 + 0.08F, 0.F);
    c.push_back(30.00F, y0 + 0.16F, 0.F);
    c.push_back(30.05F, y0 + 0.04F, ring);  // head and shoulders
    c.push_back(30.05F, y0 + 0.12F, ring);
  }
  for (const auto structure : {ClusterStructure::KdTree, ClusterStructure::Grid}) {
    Clusters out;
    EuclideanClusterer aniso(params(ClusterMethod::Anisotropic, structure, 0.4));
    aniso.extract(c, out);
    ASSERT_EQ(out.size(), 2U);
    EXPECT_EQ(out[0].size(), 7U);
    EXPECT_EQ(out[1].size(), 7U);
  }
}

// The grid's bounds pass tells non-finite coordinates by x - x (0 only for a finite x): an infinity on any axis,
// alone or beside finite points, also sends the cloud to the k-d tree, with the same clusters.
TEST(EuclideanClusterer, GridWithInfinitePointsMatchesTheKdTree) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    for (const float bad : {kInf, -kInf}) {
      Cloud c = two_boxes(0.5F);
      float p[3] = {5.2F, 0.2F, 0.2F};
      p[axis] = bad;
      c.push_back(p[0], p[1], p[2]);
      c.push_back(5.2F, 0.3F, 0.2F);
      Clusters a, b;
      EuclideanClusterer kd(params(ClusterMethod::Fixed, ClusterStructure::KdTree));
      EuclideanClusterer grid(params(ClusterMethod::Fixed, ClusterStructure::Grid));
      kd.extract(c, a);
      grid.extract(c, b);
      EXPECT_EQ(sets_of(a), sets_of(b)) << axis << " " << bad;
      EXPECT_EQ(b.size(), 2U) << axis << " " << bad;  // the boxes with the last point, and the infinite one
    }
  }
}

// Each grid cell looks back (in cell order) at the cells before it, so a pair may be found only from the side
// with the smaller radii: its stencil must reach as far as the other side's larger radius. With a 0.1 m
// tolerance (cells of about 0.057 m) and points straight below or above the sensor (range = |z|), a pair 30 m
// down joins at 0.98 of the lower point's vertical radius, 2.7 m, which is beyond the upper point's own radius
// (2.54 m at 27.3 m) by more than three cells; at 1.02 it stays apart. Above the sensor the farther point is the
// later cell. Also sideways (x negative: the farther point comes first in cell order) and for both growing radii.
TEST(EuclideanClusterer, GridReachesTheLargerRadiusOfAnEarlierCell) {
  for (const auto method : {ClusterMethod::Adaptive, ClusterMethod::Anisotropic}) {
    const EuclideanClusterer probe(params(method, ClusterStructure::Grid, 0.1));
    for (const float far : {12.F, 20.F, 30.F}) {
      for (const float factor : {0.98F, 1.02F}) {
        for (const int dir : {0, 1, 2}) {  // down, up, along -x
          Cloud c;
          const float v = probe.radius_at(far), h = probe.horizontal_radius_at(far);
          if (dir == 0) {
            c.push_back(0.F, 0.F, -far);
            c.push_back(0.F, 0.F, -far + factor * v);
          } else if (dir == 1) {
            c.push_back(0.F, 0.F, far);
            c.push_back(0.F, 0.F, far - factor * v);
          } else {
            c.push_back(-far, 0.F, 0.F);
            c.push_back(-far + factor * h, 0.F, 0.F);
          }
          c.push_back(-far, 40.F, 0.F);  // far aside: a singleton that widens the grid
          for (const auto structure : {ClusterStructure::KdTree, ClusterStructure::Grid}) {
            EuclideanClusterer e(params(method, structure, 0.1));
            Clusters out;
            e.extract(c, out);
            EXPECT_EQ(out.size(), factor < 1.F ? 2U : 3U)
                << method_name(method) << " " << far << " " << factor << " dir " << dir
                << (structure == ClusterStructure::Grid ? " grid" : " kd");
          }
        }
      }
    }
  }
}

// Just inside and just outside the ellipse at 5 m: the vertical radius is 4 * 5 * tan(1.33 deg) = 0.465 m, the
// horizontal one 0.4 m (its floor). (0.30, 0.27) is 0.404 m away: outside a 0.4 m sphere, inside the ellipse.
TEST(EuclideanClusterer, AnisotropicEllipseBoundary) {
  const EuclideanClusterer probe(params(ClusterMethod::Anisotropic, ClusterStructure::Grid, 0.4));
  for (const auto structure : {ClusterStructure::KdTree, ClusterStructure::Grid}) {
    EuclideanClusterer e(params(ClusterMethod::Anisotropic, structure, 0.4));
    // (dz, dy): straight up, straight aside, and diagonally; margins of a few percent around the boundary.
    for (const auto& [dz, dy, joined] :
         {std::tuple{0.44F, 0.F, true}, std::tuple{0.52F, 0.F, false}, std::tuple{0.F, 0.38F, true},
          std::tuple{0.F, 0.42F, false}, std::tuple{0.3F, 0.27F, true}, std::tuple{0.36F, 0.32F, false}}) {
      Cloud c;
      c.push_back(5.F, 0.F, 0.F);
      c.push_back(5.F, dy, dz);
      Clusters out;
      e.extract(c, out);
      EXPECT_EQ(out.size(), joined ? 1U : 2U) << dz << " " << dy << " V " << probe.radius_at(5.F);
    }
  }
}

}  // namespace
}  // namespace fieldguard::perception
