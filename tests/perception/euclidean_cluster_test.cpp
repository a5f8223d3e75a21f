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

ClusterParams params(ClusterMethod m, ClusterStructure s, double tolerance = 0.6) {
  ClusterParams p;
  p.method = m;
  p.structure = s;
  p.tolerance_m = tolerance;
  return p;
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
                         ::testing::Combine(::testing::Values(ClusterMethod::Fixed, ClusterMethod::Adaptive),
                                            ::testing::Values(ClusterStructure::KdTree, ClusterStructure::Grid)),
                         [](const ::testing::TestParamInfo<std::tuple<ClusterMethod, ClusterStructure>>& p) {
                           return std::string(std::get<0>(p.param) == ClusterMethod::Fixed ? "Fixed" : "Adaptive") +
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
  for (const auto method : {ClusterMethod::Fixed, ClusterMethod::Adaptive}) {
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
}

}  // namespace
}  // namespace fieldguard::perception
