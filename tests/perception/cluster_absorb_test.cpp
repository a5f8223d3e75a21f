#include "fieldguard/perception/cluster_absorb.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>
#include <vector>

#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

using testing::clusters_of;
using testing::Sets;
using testing::sets_of;

// A crown's body: a 4 x 4 x 4 lattice of 0.5 m (x 10..11.5 m, 64 points), and three stray returns behind it.
Cloud crown_with_fragments() {
  Cloud c;
  testing::add_block(c, {10.F, 0.F, 0.F}, {4, 4, 4}, 0.5F);  // 0..63: x 10..11.5, y 0..1.5, z 0..1.5
  c.push_back(11.7F, 0.5F, 1.0F);                            // 64: a deep return 0.2 m behind the body
  c.push_back(11.75F, 0.6F, 1.0F);                           // 65
  c.push_back(12.2F, 0.5F, 1.0F);                            // 66: 0.7 m behind: beyond the margin
  return c;
}

TEST(ClusterAbsorber, AFragmentInsideTheGrownBoxJoins) {
  const Cloud c = crown_with_fragments();
  std::vector<std::uint32_t> body(64);
  for (std::uint32_t i = 0; i < 64; ++i) body[i] = i;
  Clusters k = clusters_of({body, {64, 65}, {66}});
  ClusterAbsorber a(10, 0.3);
  EXPECT_EQ(a.absorb(c, k), 1U);
  ASSERT_EQ(k.size(), 2U);
  std::vector<std::uint32_t> joined = body;
  joined.push_back(64);
  joined.push_back(65);
  EXPECT_EQ(sets_of(k), (Sets{joined, {66}}));
}

TEST(ClusterAbsorber, OffOrNothingToDoLeavesTheClusters) {
  const Cloud c = crown_with_fragments();
  std::vector<std::uint32_t> body(64);
  for (std::uint32_t i = 0; i < 64; ++i) body[i] = i;
  const Sets before{body, {64, 65}, {66}};
  Clusters k = clusters_of(before);
  ClusterAbsorber off(0, 0.3);
  EXPECT_EQ(off.absorb(c, k), 0U);
  EXPECT_EQ(sets_of(k), before);
  // No cluster is bigger than the limit: none can take another in.
  ClusterAbsorber all_small(100, 0.3);
  EXPECT_EQ(all_small.absorb(c, k), 0U);
  EXPECT_EQ(sets_of(k), before);
  // Margin 0: the fragment 0.2 m behind stays out.
  ClusterAbsorber tight(10, 0.0);
  EXPECT_EQ(tight.absorb(c, k), 0U);
  EXPECT_EQ(sets_of(k), before);
}

// Two small clusters, each inside the other's box: neither is big, so neither moves (no chains, no order).
TEST(ClusterAbsorber, SmallClustersDoNotAbsorbEachOther) {
  Cloud c;
  c.push_back(5.F, 0.F, 0.F);
  c.push_back(5.1F, 0.F, 0.F);
  c.push_back(5.05F, 0.F, 0.F);
  Clusters k = clusters_of({{0, 1}, {2}});
  ClusterAbsorber a(2, 0.3);
  EXPECT_EQ(a.absorb(c, k), 0U);
  EXPECT_EQ(k.size(), 2U);
}

// A fragment inside two overlapping boxes goes to the cluster with more points, and the output keeps the
// clusterer's order: by lowest point index, members ascending.
TEST(ClusterAbsorber, GoesToTheBiggerClusterAndKeepsTheOrder) {
  Cloud c;
  testing::add_block(c, {0.F, 0.F, 0.F}, {3, 3, 2}, 0.5F);   // 0..17: x 0..1, y 0..1, z 0..0.5
  testing::add_block(c, {0.8F, 0.F, 0.F}, {4, 3, 2}, 0.5F);  // 18..41: x 0.8..2.3
  c.push_back(0.9F, 0.5F, 0.25F);                            // 42: inside both boxes
  std::vector<std::uint32_t> a(18), b(24);
  for (std::uint32_t i = 0; i < 18; ++i) a[i] = i;
  for (std::uint32_t i = 0; i < 24; ++i) b[i] = 18 + i;
  Clusters k = clusters_of({{42}, b, a});  // any input order
  ClusterAbsorber absorber(10, 0.1);
  EXPECT_EQ(absorber.absorb(c, k), 1U);
  std::vector<std::uint32_t> b_and_fragment = b;
  b_and_fragment.push_back(42);
  EXPECT_EQ(sets_of(k), (Sets{a, b_and_fragment}));
}

// Points in no cluster stay in none; an index past the cloud throws; an empty cluster is dropped.
TEST(ClusterAbsorber, PartialClusteringAndBadInput) {
  const Cloud c = crown_with_fragments();
  std::vector<std::uint32_t> body(64);
  for (std::uint32_t i = 0; i < 64; ++i) body[i] = i;
  Clusters k = clusters_of({body, {}, {65}});  // 64 and 66 in none
  ClusterAbsorber a(10, 0.3);
  EXPECT_EQ(a.absorb(c, k), 1U);
  std::vector<std::uint32_t> joined = body;
  joined.push_back(65);
  EXPECT_EQ(sets_of(k), (Sets{joined}));
  Clusters bad = clusters_of({body, {67}});
  EXPECT_THROW(a.absorb(c, bad), std::out_of_range);
  EXPECT_THROW(ClusterAbsorber(-1, 0.3), std::invalid_argument);
  EXPECT_THROW(ClusterAbsorber(10, -0.1), std::invalid_argument);
  EXPECT_THROW(ClusterAbsorber(10, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

}  // namespace
}  // namespace fieldguard::perception
