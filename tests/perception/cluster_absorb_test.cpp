#include "fieldguard/perception/cluster_absorb.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

using testing::clusters_of;
using testing::same_bounds;
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
  Buffer<ClusterBounds> one_more(k.size() + 1);
  EXPECT_THROW(a.absorb(c, k, &one_more), std::invalid_argument);
  EXPECT_THROW(ClusterAbsorber(-1, 0.3), std::invalid_argument);
  EXPECT_THROW(ClusterAbsorber(10, -0.1), std::invalid_argument);
  EXPECT_THROW(ClusterAbsorber(10, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

// The rule written plainly: each small cluster to the first big one (most points, then lowest index) whose box,
// grown by the margin, holds its box. The absorber tests four big boxes at a time; its choice must be this one,
// with more big clusters than one group of four, boxes inside boxes and boxes sharing an edge.
TEST(ClusterAbsorber, TakesTheFirstHoldingBoxAsOneAtATime) {
  testing::TestRng rng(3);
  const auto next = [&rng] { return rng.uniform(0.F, 1.F); };
  for (int trial = 0; trial < 40; ++trial) {
    Cloud c;
    Sets sets;
    const auto add_cluster = [&](std::size_t points, float x, float y, float size) {
      std::vector<std::uint32_t> members;
      for (std::size_t k = 0; k < points; ++k) {
        members.push_back(static_cast<std::uint32_t>(c.size()));
        // On a 0.1 m lattice: boxes often share an edge exactly.
        c.push_back(x + std::round(size * next() * 10.F) / 10.F, y + std::round(size * next() * 10.F) / 10.F,
                    std::round(2.F * next() * 10.F) / 10.F);
      }
      sets.push_back(members);
    };
    const int big = 1 + trial % 11;
    for (int b = 0; b < big; ++b)
      add_cluster(11 + static_cast<std::size_t>(next() * 5.F), 4.F * next(), 4.F * next(), 3.F);
    for (int f = 0; f < 60; ++f)
      add_cluster(1 + static_cast<std::size_t>(next() * 10.F), 6.F * next(), 6.F * next(), 0.5F);
    const float margin = 0.1F * static_cast<float>(trial % 4);
    // The expected result, one big box at a time.
    struct Box {
      float lo[3], hi[3];
    };
    std::vector<Box> boxes;
    for (const auto& m : sets) {
      Box b{{c.x[m[0]], c.y[m[0]], c.z[m[0]]}, {c.x[m[0]], c.y[m[0]], c.z[m[0]]}};
      for (const std::uint32_t i : m) {
        const float p[3] = {c.x[i], c.y[i], c.z[i]};
        for (int k = 0; k < 3; ++k) {
          b.lo[k] = std::min(b.lo[k], p[k]);
          b.hi[k] = std::max(b.hi[k], p[k]);
        }
      }
      boxes.push_back(b);
    }
    std::vector<std::size_t> order;
    for (std::size_t k = 0; k < sets.size(); ++k) {
      if (sets[k].size() > 10) order.push_back(k);
    }
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return sets[a].size() > sets[b].size(); });
    Sets expected = sets;
    std::uint32_t moved = 0;
    for (std::size_t k = 0; k < sets.size(); ++k) {
      if (sets[k].size() > 10) continue;
      for (const std::size_t b : order) {
        bool inside = true;
        for (int a = 0; a < 3; ++a) {
          inside = inside && boxes[k].lo[a] >= boxes[b].lo[a] - margin && boxes[k].hi[a] <= boxes[b].hi[a] + margin;
        }
        if (inside) {
          expected[b].insert(expected[b].end(), sets[k].begin(), sets[k].end());
          expected[k].clear();
          ++moved;
          break;
        }
      }
    }
    expected.erase(std::remove_if(expected.begin(), expected.end(), [](const auto& m) { return m.empty(); }),
                   expected.end());
    Clusters k = clusters_of(sets);
    ClusterAbsorber absorber(10, static_cast<double>(margin));
    ASSERT_EQ(absorber.absorb(c, k), moved) << "trial " << trial;
    ASSERT_GT(moved, 0U);
    // As the absorber gives them: members ascending, clusters by their lowest point.
    for (auto& m : expected) std::sort(m.begin(), m.end());
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(sets_of(k), expected) << "trial " << trial;
    // With bounds given (the pipeline's way): the same result, and the bounds of the merged clusters.
    Clusters kb = clusters_of(sets);
    const std::vector<float> h(c.z.begin(), c.z.end());
    Buffer<ClusterBounds> bounds, fresh;
    bound_clusters(c, h, {}, kb, bounds);
    ClusterAbsorber with_bounds(10, static_cast<double>(margin));
    ASSERT_EQ(with_bounds.absorb(c, kb, &bounds), moved) << "trial " << trial;
    EXPECT_EQ(sets_of(kb), expected) << "trial " << trial;
    bound_clusters(c, h, {}, kb, fresh);
    ASSERT_EQ(bounds.size(), fresh.size()) << "trial " << trial;
    for (std::size_t q = 0; q < fresh.size(); ++q) {
      EXPECT_TRUE(same_bounds(bounds[q], fresh[q])) << "trial " << trial << " cluster " << q;
    }
  }
}

// merge_clusters (the absorber's and the joiner's regrouping) against sets merged by hand: clusters in the
// clusterer's order (merged cluster by cluster) and out of it (regrouped point by point), one big cluster taking
// a few small ones (merged by bisection) or several of any size (merged in one sweep), empty clusters among them.
TEST(MergeClusters, AsTheMergedSetsInTheOrderOfTheirLowestPoint) {
  std::uint32_t state = 12345U;
  const auto next = [&state](std::uint32_t below) {
    state = state * 1664525U + 1013904223U;
    return (state >> 8) % below;
  };
  Buffer<std::uint32_t> of_point, id, scratch;
  for (int trial = 0; trial < 400; ++trial) {
    const std::uint32_t n = 1 + next(600);
    const std::uint32_t labels = 1 + next(40);
    // Label 0 takes most points in half the trials: a big cluster and small ones.
    const bool skewed = trial % 2 == 0;
    Sets sets(labels);
    for (std::uint32_t i = 0; i < n; ++i) {
      if (trial % 5 == 0 && next(10) == 0) continue;  // in no cluster
      const std::uint32_t l = skewed && next(100) < 95 ? 0 : next(labels);
      sets[l].push_back(i);
    }
    const bool in_order = trial % 3 != 0;
    if (in_order) {
      std::stable_sort(sets.begin(), sets.end(),
                       [](const auto& a, const auto& b) { return !a.empty() && (b.empty() || a.front() < b.front()); });
    } else {
      for (std::size_t k = sets.size(); k > 1; --k) std::swap(sets[k - 1], sets[next(static_cast<std::uint32_t>(k))]);
      for (auto& m : sets) {
        if (next(2) == 0) std::reverse(m.begin(), m.end());
      }
    }
    // Each cluster goes to a root: itself, or one of the few clusters that are their own roots.
    const std::size_t nc = sets.size();
    std::vector<std::uint32_t> target(nc);
    for (std::size_t c = 0; c < nc; ++c) {
      const std::uint32_t root = next(std::min<std::uint32_t>(4, static_cast<std::uint32_t>(nc)));
      target[c] = next(3) == 0 ? static_cast<std::uint32_t>(c) : root;
    }
    for (std::size_t c = 0; c < nc; ++c) target[target[c]] = target[c];
    Sets expected(nc);
    for (std::size_t c = 0; c < nc; ++c) {
      expected[target[c]].insert(expected[target[c]].end(), sets[c].begin(), sets[c].end());
    }
    expected.erase(std::remove_if(expected.begin(), expected.end(), [](const auto& m) { return m.empty(); }),
                   expected.end());
    for (auto& m : expected) std::sort(m.begin(), m.end());
    std::sort(expected.begin(), expected.end());
    Clusters k = clusters_of(sets);
    merge_clusters(target, n, k, of_point, id, scratch);
    ASSERT_EQ(sets_of(k), expected) << "trial " << trial;
    ASSERT_EQ(k.offsets.size(), expected.size() + 1) << "trial " << trial;
  }
}

}  // namespace
}  // namespace fieldguard::perception
