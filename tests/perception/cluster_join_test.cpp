#include "fieldguard/perception/cluster_join.hpp"

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

std::vector<std::uint32_t> range(std::uint32_t from, std::uint32_t to) {
  std::vector<std::uint32_t> r;
  for (std::uint32_t i = from; i < to; ++i) r.push_back(i);
  return r;
}

// Ground is z = 0 in these clouds: a point's height above ground is its z.
std::vector<float> heights_of(const Cloud& c) { return {c.z.begin(), c.z.end()}; }

// The filters of config/fieldguard.yaml: at 10 m a cluster needs 6 points.
FilterParams filters() { return FilterParams{}; }

ClusterJoinParams params(double float_h, double gap, bool stacked, double margin = 0.0) {
  ClusterJoinParams p;
  p.float_height_m = float_h;
  p.gap_m = gap;
  p.stacked = stacked;
  p.stack_margin_m = margin;
  return p;
}

// A crown seen through gaps at 10 m: four single returns 1.6-2.4 m up, 0.5 m apart along x, and one 1.5 m beyond
// the last (another crown's).
Cloud crown_fragments() {
  Cloud c;
  c.push_back(10.0F, 0.0F, 1.6F);  // 0
  c.push_back(10.5F, 0.1F, 2.4F);  // 1
  c.push_back(11.0F, 0.0F, 2.0F);  // 2
  c.push_back(11.5F, 0.2F, 1.8F);  // 3
  c.push_back(13.0F, 0.0F, 2.0F);  // 4: 1.5 m on
  return c;
}

TEST(ClusterJoiner, FloatingFragmentsWithinTheGapJoin) {
  const Cloud c = crown_fragments();
  const auto h = heights_of(c);
  Clusters k = clusters_of({{0}, {1}, {2}, {3}, {4}});
  ClusterJoiner j(params(0.8, 0.6, false));
  EXPECT_EQ(j.join(c, h, filters(), k), 3U);
  EXPECT_EQ(sets_of(k), (Sets{{0, 1, 2, 3}, {4}}));
}

TEST(ClusterJoiner, FragmentsThatDoNotFloatStayApart) {
  // The same fragments 0.3 m above the ground (crop, a clod's slices): none floats at 0.8 m.
  Cloud c = crown_fragments();
  for (float& z : c.z) z = 0.3F;
  const auto h = heights_of(c);
  const Sets before{{0}, {1}, {2}, {3}, {4}};
  Clusters k = clusters_of(before);
  ClusterJoiner j(params(0.8, 0.6, true, 0.4));
  EXPECT_EQ(j.join(c, h, filters(), k), 0U);
  EXPECT_EQ(sets_of(k), before);
}

TEST(ClusterJoiner, OneFloatingFragmentIsEnoughForAPair) {
  // A trunk return 0.4 m up under a crown fragment 2 m up: the pair joins (the crown floats).
  Cloud c;
  c.push_back(10.0F, 0.0F, 0.4F);
  c.push_back(10.3F, 0.0F, 2.0F);
  const auto h = heights_of(c);
  Clusters k = clusters_of({{0}, {1}});
  ClusterJoiner j(params(0.8, 0.6, false));
  EXPECT_EQ(j.join(c, h, filters(), k), 1U);
  EXPECT_EQ(sets_of(k), (Sets{{0, 1}}));
}

TEST(ClusterJoiner, AFragmentJoinsOnlyTheNearerOfTwoCrowns) {
  // Two crowns of 27 points each (x 10..11 and 12..13), a floating fragment between them 0.4 m from the first
  // and 0.6 m from the second: it joins the first only; the two crowns stay two.
  Cloud c;
  testing::add_block(c, {10.F, 0.F, 1.F}, {3, 3, 3}, 0.5F);  // 0..26
  testing::add_block(c, {12.F, 0.F, 1.F}, {3, 3, 3}, 0.5F);  // 27..53
  c.push_back(11.4F, 0.5F, 1.5F);                            // 54
  const auto h = heights_of(c);
  Clusters k = clusters_of({range(0, 27), range(27, 54), {54}});
  ClusterJoiner j(params(0.8, 0.7, false));
  EXPECT_EQ(j.join(c, h, filters(), k), 1U);
  auto first = range(0, 27);
  first.push_back(54);
  EXPECT_EQ(sets_of(k), (Sets{first, range(27, 54)}));
}

TEST(ClusterJoiner, BigClustersDoNotJoinByTheGapRule) {
  // Two crowns 0.4 m apart, each with enough points: the fragment rules leave them.
  Cloud c;
  testing::add_block(c, {10.F, 0.F, 1.F}, {3, 3, 3}, 0.5F);
  testing::add_block(c, {11.4F, 0.F, 1.F}, {3, 3, 3}, 0.5F);
  const auto h = heights_of(c);
  const Sets before{range(0, 27), range(27, 54)};
  Clusters k = clusters_of(before);
  ClusterJoiner j(params(0.8, 0.6, false));
  EXPECT_EQ(j.join(c, h, filters(), k), 0U);
  EXPECT_EQ(sets_of(k), before);
}

TEST(ClusterJoiner, StackedClustersJoinWhenOneFloats) {
  // A crown (x-y 10..11 x 0..1, 1.5-2.5 m up) over its trunk (x-y 10.4..10.6 x 0.4..0.6, 0-1 m up), both with
  // enough points; and a second crown 0.5 m beyond the first.
  Cloud c;
  testing::add_block(c, {10.F, 0.F, 1.5F}, {3, 3, 3}, 0.5F);   // 0..26
  testing::add_block(c, {10.4F, 0.4F, 0.F}, {2, 2, 3}, 0.2F);  // 27..38: x 10.4..10.6, z 0..0.4
  for (std::uint32_t i = 27; i < 39; ++i) c.z[i] *= 2.5F;      // z 0..1
  testing::add_block(c, {11.5F, 0.F, 1.5F}, {3, 3, 3}, 0.5F);  // 39..65: 0.5 m beyond the first crown
  const auto h = heights_of(c);
  {
    Clusters k = clusters_of({range(0, 27), range(27, 39), range(39, 66)});
    ClusterJoiner j(params(0.8, 0.0, true, 0.0));
    EXPECT_EQ(j.join(c, h, filters(), k), 1U);
    EXPECT_EQ(sets_of(k), (Sets{range(0, 39), range(39, 66)}));
  }
  {
    // A margin wider than the gap between the crowns joins them too.
    Clusters k = clusters_of({range(0, 27), range(27, 39), range(39, 66)});
    ClusterJoiner j(params(0.8, 0.0, true, 0.6));
    EXPECT_EQ(j.join(c, h, filters(), k), 2U);
    EXPECT_EQ(sets_of(k), (Sets{range(0, 66)}));
  }
  {
    // Nothing floats at 2 m: nothing stacks.
    Clusters k = clusters_of({range(0, 27), range(27, 39), range(39, 66)});
    ClusterJoiner j(params(2.0, 0.0, true, 0.6));
    EXPECT_EQ(j.join(c, h, filters(), k), 0U);
    EXPECT_EQ(k.size(), 3U);
  }
}

TEST(ClusterJoiner, OffLeavesTheClusters) {
  const Cloud c = crown_fragments();
  const auto h = heights_of(c);
  const Sets before{{0}, {1}, {2}, {3}, {4}};
  for (const ClusterJoinParams& p : {params(0.0, 0.6, true, 0.4), params(0.8, 0.0, false)}) {
    Clusters k = clusters_of(before);
    ClusterJoiner j(p);
    EXPECT_EQ(j.join(c, h, filters(), k), 0U);
    EXPECT_EQ(sets_of(k), before);
  }
  // join_float_height_m 0 switches the stage off whatever the other keys say (published.yaml).
  ClusterParams off;
  off.join_float_height_m = 0.0;
  Clusters k = clusters_of(before);
  ClusterJoiner j(ClusterJoinParams::from(off));
  EXPECT_EQ(j.join(c, h, filters(), k), 0U);
  EXPECT_EQ(sets_of(k), before);
}

TEST(ClusterJoiner, OutputIsInTheOrderOfEachClustersLowestPoint) {
  // Cluster {4} comes first in the input; the joined {0..3} holds the lowest index and comes first.
  const Cloud c = crown_fragments();
  const auto h = heights_of(c);
  Clusters k = clusters_of({{4}, {1, 3}, {2}, {0}});
  ClusterJoiner j(params(0.8, 0.6, false));
  EXPECT_EQ(j.join(c, h, filters(), k), 2U);
  EXPECT_EQ(sets_of(k), (Sets{{0, 1, 2, 3}, {4}}));
}

TEST(ClusterJoiner, EmptyClustersTakePartInNoRule) {
  const Cloud c = crown_fragments();
  const auto h = heights_of(c);
  Clusters k = clusters_of({{0}, {}, {1}});
  ClusterJoiner j(params(0.8, 0.6, true));
  EXPECT_EQ(j.join(c, h, filters(), k), 1U);
  EXPECT_EQ(sets_of(k), (Sets{{0, 1}}));
}

TEST(ClusterJoiner, BadInputThrows) {
  EXPECT_THROW(ClusterJoiner(params(-0.1, 0.6, false)), std::invalid_argument);
  EXPECT_THROW(ClusterJoiner(params(0.8, -1.0, false)), std::invalid_argument);
  EXPECT_THROW(ClusterJoiner(params(0.8, 0.6, true, -0.1)), std::invalid_argument);
  EXPECT_THROW(ClusterJoiner(params(std::numeric_limits<double>::quiet_NaN(), 0.6, false)), std::invalid_argument);
  EXPECT_THROW(ClusterJoiner(params(0.8, std::numeric_limits<double>::infinity(), false)), std::invalid_argument);
  const Cloud c = crown_fragments();
  const auto h = heights_of(c);
  ClusterJoiner j(params(0.8, 0.6, false));
  Clusters past = clusters_of({{0}, {5}});
  EXPECT_THROW(j.join(c, h, filters(), past), std::out_of_range);
  Clusters ok = clusters_of({{0}, {1}});
  const std::vector<float> short_h(2, 1.F);
  EXPECT_THROW(j.join(c, short_h, filters(), ok), std::out_of_range);
}

}  // namespace
}  // namespace fieldguard::perception
