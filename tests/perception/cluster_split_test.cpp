#include "fieldguard/perception/cluster_split.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

using testing::clusters_of;
using testing::Sets;
using testing::sets_of;

// The pipeline's clusterer (anisotropic: 0.4 m horizontally up to 18 m, 0.8 m at 20 m) and the splitter as the
// candidate configuration sets it.
ClusterParams cluster_params() { return ClusterParams{}; }

ClusterSplitParams split_params() {
  ClusterSplitParams p;
  p.min_length_m = 2.0;
  p.min_part_m = 0.5;
  p.gap_ratio = 0.6;
  p.min_part_points = 40;
  p.full_range_m = 10.0;
  return p;
}

// A crown: the points of a 0.15 m lattice inside the ellipsoid centred at `c` with semi-axes `a`. With a centre on
// the lattice and a semi-axis along x a whole number of steps, its tips along x are lattice points.
// `keep`: the share of lattice points kept (at random, from `rng`); `tips_m`: the depth of the tips along x that
// return nothing (far out rays pass through a porous crown's thin ends).
void add_crown(Cloud& cloud, std::array<float, 3> c, std::array<float, 3> a, float keep = 1.F,
               testing::TestRng* rng = nullptr, float tips_m = 0.F) {
  constexpr float kStep = 0.15F;
  const int n[3] = {static_cast<int>(std::floor(a[0] / kStep + 1e-4F)),
                    static_cast<int>(std::floor(a[1] / kStep + 1e-4F)),
                    static_cast<int>(std::floor(a[2] / kStep + 1e-4F))};
  for (int i = -n[0]; i <= n[0]; ++i) {
    for (int j = -n[1]; j <= n[1]; ++j) {
      for (int k = -n[2]; k <= n[2]; ++k) {
        const float dx = kStep * static_cast<float>(i), dy = kStep * static_cast<float>(j),
                    dz = kStep * static_cast<float>(k);
        const float e = dx * dx / (a[0] * a[0]) + dy * dy / (a[1] * a[1]) + dz * dz / (a[2] * a[2]);
        if (e > 1.F + 1e-4F || std::fabs(dx) > a[0] - tips_m + 1e-4F) continue;
        if (rng != nullptr && rng->uniform(0.F, 1.F) >= keep) continue;
        cloud.push_back(c[0] + dx, c[1] + dy, c[2] + dz);
      }
    }
  }
}

Clusters cluster(const Cloud& cloud) {
  EuclideanClusterer clusterer(cluster_params());
  Clusters k;
  clusterer.extract(cloud, k);
  return k;
}

std::vector<std::uint32_t> range(std::uint32_t from, std::uint32_t to) {
  std::vector<std::uint32_t> v;
  for (std::uint32_t i = from; i < to; ++i) v.push_back(i);
  return v;
}

// `c` is two crowns, its points [0, first) and [first, end): the clusterer joins them, the split cuts them apart.
void expect_cut_apart(const Cloud& c, std::uint32_t first) {
  const auto all = static_cast<std::uint32_t>(c.size());
  Clusters k = cluster(c);
  ASSERT_EQ(k.size(), 1U) << "the clusterer must join the two for this test to mean anything";
  EuclideanClusterer clusterer(cluster_params());
  ClusterSplitter s(split_params());
  EXPECT_EQ(s.split(c, clusterer, k), 1U);
  EXPECT_EQ(sets_of(k), (Sets{range(0, first), range(first, all)}));
}

TEST(ClusterSplitter, TwoCrownsTheClustererJoinedAreCutApart) {
  // Two crowns 0.3 m apart in a row along x, 8 m out: their tips (lattice points) are 0.3 m apart, nearer than
  // the clusterer's 0.4 m, so it makes them one.
  Cloud c;
  add_crown(c, {6.F, -3.75F, 0.6F}, {1.05F, 0.9F, 0.9F});
  const auto first = static_cast<std::uint32_t>(c.size());
  add_crown(c, {8.4F, -3.75F, 0.6F}, {1.05F, 0.9F, 0.9F});
  expect_cut_apart(c, first);
}

TEST(ClusterSplitter, TwoFarCrownsWithFewReturnsAreCutApart) {
  // 30 m out the horizontal radius is 1.2 m: two sparse crowns (a fifth of the lattice, and nothing from the last
  // 0.3 m of their tips) 0.45 m apart, their returns 1.05 m apart, are one cluster; the slot is 0.87 times the radius
  // and each has far more than the 40 * (10 / 30)^2 = 5 points a part needs there.
  Cloud c;
  testing::TestRng rng(7);
  add_crown(c, {28.F, -3.75F, 0.6F}, {1.05F, 0.9F, 0.9F}, 0.2F, &rng, 0.3F);
  const auto first = static_cast<std::uint32_t>(c.size());
  add_crown(c, {30.55F, -3.75F, 0.6F}, {1.05F, 0.9F, 0.9F}, 0.2F, &rng, 0.3F);
  expect_cut_apart(c, first);
}

TEST(ClusterSplitter, APorousCrownStaysWhole) {
  // One crown 3.3 m long, 8 m out, half its lattice points missing at random: returns all along it.
  Cloud c;
  testing::TestRng rng(3);
  add_crown(c, {7.F, -3.75F, 0.6F}, {1.65F, 1.2F, 1.05F}, 0.5F, &rng);
  // ... and a few stray returns in the air beyond its thin end, 0.5 m out: a gap, but no second crown.
  const auto body = static_cast<std::uint32_t>(c.size());
  for (int i = 0; i < 6; ++i) c.push_back(7.F + 1.65F + 0.5F + 0.1F * static_cast<float>(i), -3.75F, 0.6F);
  Clusters k = clusters_of({range(0, static_cast<std::uint32_t>(c.size()))});
  const Sets before = sets_of(k);
  EuclideanClusterer clusterer(cluster_params());
  ClusterSplitter s(split_params());
  EXPECT_EQ(s.split(c, clusterer, k), 0U);
  EXPECT_EQ(sets_of(k), before);
  // The strays become a part once they are a tenth of the points and 0.5 m long: then the gap cuts (the rule
  // does look at that gap).
  const auto strays = static_cast<std::uint32_t>(body / 9);
  for (std::uint32_t i = 0; i < strays; ++i) {
    c.push_back(7.F + 1.65F + 0.5F + 0.6F * static_cast<float>(i) / static_cast<float>(strays), -3.75F,
                0.6F + 0.01F * static_cast<float>(i % 7));
  }
  Clusters k2 = clusters_of({range(0, static_cast<std::uint32_t>(c.size()))});
  EXPECT_EQ(s.split(c, clusterer, k2), 1U);
}

// Two groups of 20 returns, x0 .. x0 + 0.6 and x0 + 0.6 + slot .. x0 + 1.2 + slot, 0.3 m high, 0.15 m deep.
Cloud two_groups(float x0, float y, float slot) {
  Cloud c;
  testing::add_block(c, {x0, y, 0.F}, {5, 2, 2}, 0.15F);
  testing::add_block(c, {x0 + 0.6F + slot, y, 0.F}, {5, 2, 2}, 0.15F);
  return c;
}

TEST(ClusterSplitter, AShadowedSlotInASparseNearCrownIsNoCut) {
  // A crown of the next row seen through the gaps of the row in front, 8 m out: two groups of 20 returns with a
  // 0.5 m slot between them (a nearer crown's shadow; 1.25 times the radius). Within 10 m a crown in full gives
  // hundreds of returns, a part needs 40: no cut.
  EuclideanClusterer clusterer(cluster_params());
  ClusterSplitParams p = split_params();
  p.min_length_m = 1.5;
  ClusterSplitter s(p);
  const Cloud near = two_groups(7.F, -8.F, 0.5F);
  Clusters k = clusters_of({range(0, static_cast<std::uint32_t>(near.size()))});
  EXPECT_EQ(s.split(near, clusterer, k), 0U);
  // The same returns 30 m out with a slot 0.8 times the radius there (1.2 m) are two crowns: 40 * (10 / 30)^2 = 4.4
  // points make a part there.
  const Cloud far = two_groups(29.F, -3.7F, 0.96F);
  Clusters kf = clusters_of({range(0, static_cast<std::uint32_t>(far.size()))});
  EXPECT_EQ(s.split(far, clusterer, kf), 1U);
  EXPECT_EQ(sets_of(kf), (Sets{range(0, 20), range(20, 40)}));
  // ... but not with a slot of 0.5 times the radius: the clusterer's reach is what a gap is measured against.
  const Cloud narrow = two_groups(29.F, -3.7F, 0.6F);
  Clusters kn = clusters_of({range(0, static_cast<std::uint32_t>(narrow.size()))});
  EXPECT_EQ(s.split(narrow, clusterer, kn), 0U);
}

TEST(ClusterSplitter, APersonAWallAndABaleStackStayWhole) {
  EuclideanClusterer clusterer(cluster_params());
  ClusterSplitter s(split_params());
  // A person, 10 m out: 0.5 x 0.3 x 1.75 m, with a 0.3 m gap between the legs: shorter than min_length_m.
  Cloud person;
  testing::add_block(person, {10.F, 0.F, -0.95F}, {2, 1, 6}, 0.15F);    // left leg
  testing::add_block(person, {10.F, 0.45F, -0.95F}, {2, 1, 6}, 0.15F);  // right leg, 0.3 m slot
  testing::add_block(person, {10.F, 0.F, -0.05F}, {2, 4, 6}, 0.15F);    // torso and head
  Clusters kp = clusters_of({range(0, static_cast<std::uint32_t>(person.size()))});
  EXPECT_EQ(s.split(person, clusterer, kp), 0U);
  // A house wall 8 m long, 20 m out: returns all along it.
  Cloud wall;
  testing::add_block(wall, {20.F, -4.F, -0.9F}, {1, 54, 20}, 0.15F);
  Clusters kw = clusters_of({range(0, static_cast<std::uint32_t>(wall.size()))});
  EXPECT_EQ(s.split(wall, clusterer, kw), 0U);
  // A stack of round bales side by side, touching: no slot between them.
  Cloud bales;
  for (int b = 0; b < 3; ++b) add_crown(bales, {15.F, -1.5F + 1.5F * static_cast<float>(b), 0.F}, {0.6F, 0.75F, 0.75F});
  Clusters kb = cluster(bales);
  ASSERT_EQ(kb.size(), 1U);
  EXPECT_EQ(s.split(bales, clusterer, kb), 0U);
}

TEST(ClusterSplitter, OffDoesNothingAndOtherClustersKeepTheirOrder) {
  Cloud c;
  c.push_back(1.F, 1.F, 0.F);  // 0: a cluster of its own, before the crowns in point order
  add_crown(c, {6.F, -3.75F, 0.6F}, {1.05F, 0.9F, 0.9F});
  const auto first = static_cast<std::uint32_t>(c.size());
  add_crown(c, {8.4F, -3.75F, 0.6F}, {1.05F, 0.9F, 0.9F});
  const auto all = static_cast<std::uint32_t>(c.size());
  c.push_back(1.F, 2.F, 0.F);  // last: another
  const Sets before{{0U}, range(1, all), {all}};
  EuclideanClusterer clusterer(cluster_params());
  ClusterSplitParams off = split_params();
  off.min_length_m = 0.0;
  ClusterSplitter none(off);
  Clusters k = clusters_of(before);
  EXPECT_EQ(none.split(c, clusterer, k), 0U);
  EXPECT_EQ(sets_of(k), before);
  ClusterSplitter s(split_params());
  EXPECT_EQ(s.split(c, clusterer, k), 1U);
  EXPECT_EQ(sets_of(k), (Sets{{0U}, range(1, first), range(first, all), {all}}));
}

TEST(ClusterSplitter, BadParametersAndIndicesThrow) {
  ClusterSplitParams p = split_params();
  p.min_length_m = -1.0;
  EXPECT_THROW(ClusterSplitter{p}, std::invalid_argument);
  p = split_params();
  p.gap_ratio = std::nan("");
  EXPECT_THROW(ClusterSplitter{p}, std::invalid_argument);
  p.gap_ratio = 0.0;  // would count every gap between two returns
  EXPECT_THROW(ClusterSplitter{p}, std::invalid_argument);
  p = split_params();
  p.min_part_points = -1;
  EXPECT_THROW(ClusterSplitter{p}, std::invalid_argument);
  p = split_params();
  p.full_range_m = 0.0;
  EXPECT_THROW(ClusterSplitter{p}, std::invalid_argument);
  Cloud c;
  c.push_back(1.F, 1.F, 1.F);
  Clusters k = clusters_of({{0U, 5U}});
  EuclideanClusterer clusterer(cluster_params());
  ClusterSplitter s(split_params());
  EXPECT_THROW(s.split(c, clusterer, k), std::out_of_range);
  // The indices are checked eight at a time: one past the end anywhere among them, however large, throws.
  for (int i = 1; i < 20; ++i) c.push_back(static_cast<float>(i), 1.F, 1.F);
  for (const std::size_t at : {std::size_t{0}, std::size_t{5}, std::size_t{11}, std::size_t{17}}) {
    for (const std::uint32_t bad : {20U, 0x7FFFFFFFU, 0x80000000U, 0xFFFFFFFFU}) {
      std::vector<std::uint32_t> members = range(0, 18);
      members[at] = bad;
      Clusters past = clusters_of({range(18, 20), members});
      EXPECT_THROW(s.split(c, clusterer, past), std::out_of_range) << at << " " << bad;
    }
  }
  Clusters fine = clusters_of({range(0, 20)});
  EXPECT_EQ(s.split(c, clusterer, fine), 0U);  // valid: no throw (and 20 returns are too few for two parts)
}

// Two crowns the clusterer joined, with a point that is not finite among them: no axis to cut along, so the
// cluster stays whole.
TEST(ClusterSplitter, APointNotFiniteOrFarOutLeavesTheClusterWhole) {
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    Cloud c;
    add_crown(c, {6.F, -3.75F, 0.6F}, {1.05F, 0.9F, 0.9F});
    add_crown(c, {8.4F, -3.75F, 0.6F}, {1.05F, 0.9F, 0.9F});
    const auto all = static_cast<std::uint32_t>(c.size());
    c.push_back(7.F, bad, 0.6F);
    EuclideanClusterer clusterer(cluster_params());
    ClusterSplitter s(split_params());
    Clusters k = clusters_of({range(0, all + 1)});
    EXPECT_EQ(s.split(c, clusterer, k), 0U);
    EXPECT_EQ(sets_of(k), (Sets{range(0, all + 1)}));
    Clusters whole = clusters_of({range(0, all)});  // without it, cut as ever
    EXPECT_EQ(s.split(c, clusterer, whole), 1U);
  }
  // Finite, but spread over most of the float range: the projections overflow, the cluster stays whole.
  Cloud wide;
  for (const float x : {-3e38F, 3e38F, 0.F, 0.F, 1.F, 2.F}) wide.push_back(x, x == 0.F ? 3e38F : 1.F, 0.F);
  wide.y[3] = -3e38F;
  EuclideanClusterer clusterer(cluster_params());
  ClusterSplitter s(split_params());
  Clusters k = clusters_of({range(0, 6)});
  EXPECT_EQ(s.split(wide, clusterer, k), 0U);
  EXPECT_EQ(sets_of(k), (Sets{range(0, 6)}));
}

}  // namespace
}  // namespace fieldguard::perception
