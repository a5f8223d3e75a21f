#include "fieldguard/perception/cluster_join.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <vector>

#include "fieldguard/perception/cluster_filter.hpp"
#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

using testing::clusters_of;
using testing::same_bounds;
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

// `gap` for both gap rules (fragments with fragments, and a group to its nearest bigger cluster).
ClusterJoinParams params(double float_h, double gap, bool stacked, double margin = 0.0) {
  ClusterJoinParams p;
  p.float_height_m = float_h;
  p.fragment_gap_m = gap;
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

// Fragments join each other over their own gap, wider than the gap over which a group joins a bigger cluster.
TEST(ClusterJoiner, FragmentsJoinOverTheirOwnGapAndAttachOverTheOther) {
  // A crown of 27 points (x 10..11), then three floating single returns, 0.8 m apart from each other, the first
  // 0.75 m beyond the crown's box: with a fragment gap of 1.0 m the three are one group; with a gap of 0.6 m for
  // the group to a bigger cluster it stays off the crown (and joins it at 0.8 m).
  Cloud c;
  testing::add_block(c, {10.F, 0.F, 1.F}, {3, 3, 3}, 0.5F);  // 0..26
  c.push_back(11.75F, 0.2F, 1.5F);                           // 27
  c.push_back(12.55F, 0.0F, 2.0F);                           // 28
  c.push_back(13.35F, 0.1F, 1.8F);                           // 29
  const auto h = heights_of(c);
  ClusterJoinParams p = params(0.8, 0.6, false);
  p.fragment_gap_m = 1.0;
  Clusters k = clusters_of({range(0, 27), {27}, {28}, {29}});
  EXPECT_EQ(ClusterJoiner(p).join(c, h, filters(), k), 2U);
  EXPECT_EQ(sets_of(k), (Sets{range(0, 27), {27, 28, 29}}));
  p.gap_m = 0.8;
  k = clusters_of({range(0, 27), {27}, {28}, {29}});
  EXPECT_EQ(ClusterJoiner(p).join(c, h, filters(), k), 3U);
  EXPECT_EQ(sets_of(k), (Sets{range(0, 30)}));
  // Either gap rule alone: the fragment gap 0 leaves the three apart, and none is within 0.6 m of the crown.
  p = params(0.8, 0.6, false);
  p.fragment_gap_m = 0.0;
  const Sets before{range(0, 27), {27}, {28}, {29}};
  k = clusters_of(before);
  EXPECT_EQ(ClusterJoiner(p).join(c, h, filters(), k), 0U);
  EXPECT_EQ(sets_of(k), before);
  p.fragment_gap_m = 1.0;
  p.gap_m = 0.0;
  k = clusters_of(before);
  EXPECT_EQ(ClusterJoiner(p).join(c, h, filters(), k), 2U);
  EXPECT_EQ(sets_of(k), (Sets{range(0, 27), {27, 28, 29}}));
}

// A crown seen through gaps as two small obstacles (each passing the filters alone): its foliage and its trunk's
// returns. With a fragment factor above 1 they are fragments, and join; with 1 they stay two.
TEST(ClusterJoiner, TheFragmentFactorMakesSmallObstaclesFragments) {
  // At 10 m the filters want 6 points: 8 foliage returns 1.5-2.2 m up and 7 trunk returns 0.1-0.7 m up, their x-y
  // boxes 0.9 m apart.
  Cloud c;
  for (int i = 0; i < 8; ++i)
    c.push_back(10.F + 0.05F * static_cast<float>(i), 0.F, 1.5F + 0.1F * static_cast<float>(i));
  for (int i = 0; i < 7; ++i)
    c.push_back(11.F + 0.05F * static_cast<float>(i), 0.6F, 0.1F + 0.1F * static_cast<float>(i));
  const auto h = heights_of(c);
  const Sets before{range(0, 8), range(8, 15)};
  ClusterJoinParams p = params(0.8, 0.6, false);
  p.fragment_gap_m = 1.0;
  Clusters k = clusters_of(before);
  EXPECT_EQ(ClusterJoiner(p).join(c, h, filters(), k), 0U);  // factor 1: two obstacles
  EXPECT_EQ(sets_of(k), before);
  p.fragment_factor = 1.5;  // fewer than 9 points: both are fragments
  k = clusters_of(before);
  EXPECT_EQ(ClusterJoiner(p).join(c, h, filters(), k), 1U);
  EXPECT_EQ(sets_of(k), (Sets{range(0, 15)}));
  p.fragment_factor = 1.2;  // fewer than 7.2: only the trunk, which does not float, and is 0.9 m off the foliage
  k = clusters_of(before);
  EXPECT_EQ(ClusterJoiner(p).join(c, h, filters(), k), 0U);
  EXPECT_EQ(sets_of(k), before);
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

// The three rules read straight from cluster_join.hpp, every pair of clusters compared: the reference the stage's
// sweep along x must agree with.
Sets reference_join(const Cloud& c, const std::vector<float>& h, const FilterParams& f, const ClusterJoinParams& p,
                    const Sets& in) {
  const std::size_t nc = in.size();
  struct Box {
    float lo[2], hi[2];
    bool floats, small, empty;
  };
  std::vector<Box> box(nc);
  for (std::size_t k = 0; k < nc; ++k) {
    Box b{{1e30F, 1e30F}, {-1e30F, -1e30F}, false, false, in[k].empty()};
    float low = 1e30F, r2 = 1e30F;
    for (const std::uint32_t i : in[k]) {
      b.lo[0] = std::min(b.lo[0], c.x[i]);
      b.hi[0] = std::max(b.hi[0], c.x[i]);
      b.lo[1] = std::min(b.lo[1], c.y[i]);
      b.hi[1] = std::max(b.hi[1], c.y[i]);
      low = std::min(low, h[i]);
      r2 = std::min(r2, c.x[i] * c.x[i] + c.y[i] * c.y[i]);
    }
    b.floats = !b.empty && low >= static_cast<float>(p.float_height_m);
    b.small = !b.empty && static_cast<double>(in[k].size()) <
                              p.fragment_factor * static_cast<double>(min_points_at(f, std::sqrt(r2)));
    box[k] = b;
  }
  std::vector<std::size_t> up(nc);
  for (std::size_t k = 0; k < nc; ++k) up[k] = k;
  const auto root = [&](std::size_t k) {
    while (up[k] != k) k = up[k];
    return k;
  };
  const auto unite = [&](std::size_t a, std::size_t b) {
    a = root(a);
    b = root(b);
    up[std::max(a, b)] = std::min(a, b);
  };
  const auto axis_gap = [&](std::size_t a, std::size_t b, int k) {
    return std::max(box[a].lo[k], box[b].lo[k]) - std::min(box[a].hi[k], box[b].hi[k]);
  };
  const auto gap = [&](std::size_t a, std::size_t b) {
    return std::hypot(std::max(axis_gap(a, b, 0), 0.F), std::max(axis_gap(a, b, 1), 0.F));
  };
  const auto fg = static_cast<float>(p.fragment_gap_m);
  if (p.fragment_gap_m > 0.0) {
    for (std::size_t a = 0; a < nc; ++a) {
      for (std::size_t b = a + 1; b < nc; ++b) {
        if (box[a].small && box[b].small && (box[a].floats || box[b].floats) && gap(a, b) <= fg) unite(a, b);
      }
    }
  }
  const auto g = static_cast<float>(p.gap_m);
  if (p.gap_m > 0.0) {
    std::map<std::size_t, std::pair<float, std::size_t>> nearest;  // group root: (gap, big cluster)
    std::map<std::size_t, bool> floats;
    for (std::size_t a = 0; a < nc; ++a) {
      if (!box[a].small) continue;
      const std::size_t r = root(a);
      floats[r] = floats[r] || box[a].floats;
      for (std::size_t b = 0; b < nc; ++b) {
        if (box[b].empty || box[b].small || gap(a, b) > g) continue;
        const auto it = nearest.find(r);
        if (it == nearest.end() || gap(a, b) < it->second.first ||
            (gap(a, b) == it->second.first && b < it->second.second)) {
          nearest[r] = {gap(a, b), b};
        }
      }
    }
    for (const auto& [r, choice] : nearest) {
      if (floats[r]) unite(r, choice.second);
    }
  }
  if (p.stacked) {
    const auto m = static_cast<float>(p.stack_margin_m);
    for (std::size_t a = 0; a < nc; ++a) {
      for (std::size_t b = a + 1; b < nc; ++b) {
        if (box[a].empty || box[b].empty || !(box[a].floats || box[b].floats)) continue;
        if (axis_gap(a, b, 0) <= m && axis_gap(a, b, 1) <= m) unite(a, b);
      }
    }
  }
  std::map<std::size_t, std::vector<std::uint32_t>> groups;
  for (std::size_t k = 0; k < nc; ++k) {
    auto& members = groups[root(k)];
    members.insert(members.end(), in[k].begin(), in[k].end());
  }
  Sets out;
  for (auto& [r, members] : groups) {
    if (members.empty()) continue;
    std::sort(members.begin(), members.end());
    out.push_back(members);
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.front() < b.front(); });
  return out;
}

// Scattered clusters of 1-12 returns over 40 x 20 m, a third of them floating, with the stage against the reference:
// the sweep along x must find every pair the rules name, whatever the clusters' order.
TEST(ClusterJoiner, SweepAgreesWithEveryPairCompared) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> ux(5.F, 45.F), uy(-10.F, 10.F), spread(0.F, 0.8F), unit(0.F, 1.F);
  std::size_t joins = 0;
  for (int run = 0; run < 12; ++run) {
    Cloud c;
    std::vector<float> h;
    Sets in;
    const int count = 50 + 40 * run;
    for (int k = 0; k < count; ++k) {
      const float x = ux(rng), y = uy(rng), base = unit(rng) < 0.33F ? 0.8F + 2.F * unit(rng) : 0.5F * unit(rng);
      const auto points = static_cast<int>(1 + 11 * unit(rng) * unit(rng));
      std::vector<std::uint32_t> members;
      for (int i = 0; i < points; ++i) {
        members.push_back(static_cast<std::uint32_t>(c.size()));
        c.push_back(x + spread(rng), y + spread(rng), base + spread(rng));
        h.push_back(c.z[c.size() - 1]);
      }
      in.push_back(members);
    }
    std::shuffle(in.begin(), in.end(), rng);  // clusters in no particular order
    ClusterJoinParams p = params(0.8, run % 3 == 0 ? 0.0 : 0.6, run % 2 == 0, 0.4);
    if (run % 4 == 1) p.fragment_gap_m = 1.0;  // the two gap rules apart, as fieldguard.yaml has them
    if (run % 4 == 2) p.fragment_gap_m = 0.0;
    if (run % 3 == 1) p.fragment_factor = 1.5;
    const Sets want = reference_join(c, h, filters(), p, in);
    Clusters k = clusters_of(in);
    ClusterJoiner j(p);
    const std::uint32_t n = j.join(c, h, filters(), k);
    joins += n;
    if (n == 0) {
      EXPECT_EQ(sets_of(k), in) << "run " << run;
    } else {
      EXPECT_EQ(sets_of(k), want) << "run " << run;
    }
    EXPECT_EQ(n, in.size() - want.size()) << "run " << run;
    // With bounds given (the pipeline's way): the same joins, and the bounds of the joined clusters.
    Clusters kb = clusters_of(in);
    Buffer<ClusterBounds> bounds, fresh;
    bound_clusters(c, h, {}, kb, bounds);
    ClusterJoiner jb(p);
    EXPECT_EQ(jb.join(c, h, filters(), kb, &bounds), n) << "run " << run;
    EXPECT_EQ(sets_of(kb), sets_of(k)) << "run " << run;
    bound_clusters(c, h, {}, kb, fresh);
    ASSERT_EQ(bounds.size(), fresh.size()) << "run " << run;
    for (std::size_t q = 0; q < fresh.size(); ++q) {
      EXPECT_TRUE(same_bounds(bounds[q], fresh[q])) << "run " << run << " cluster " << q;
    }
  }
  EXPECT_GT(joins, 100U);  // the scenes must exercise the rules
}

TEST(ClusterJoiner, BadInputThrows) {
  EXPECT_THROW(ClusterJoiner(params(-0.1, 0.6, false)), std::invalid_argument);
  EXPECT_THROW(ClusterJoiner(params(0.8, -1.0, false)), std::invalid_argument);
  ClusterJoinParams bad_fragment_gap = params(0.8, 0.6, false);
  bad_fragment_gap.fragment_gap_m = -0.5;
  EXPECT_THROW(ClusterJoiner{bad_fragment_gap}, std::invalid_argument);
  bad_fragment_gap.fragment_gap_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(ClusterJoiner{bad_fragment_gap}, std::invalid_argument);
  ClusterJoinParams bad_factor = params(0.8, 0.6, false);
  bad_factor.fragment_factor = 0.9;  // a cluster the filters drop would be no fragment
  EXPECT_THROW(ClusterJoiner{bad_factor}, std::invalid_argument);
  bad_factor.fragment_factor = std::numeric_limits<double>::infinity();
  EXPECT_THROW(ClusterJoiner{bad_factor}, std::invalid_argument);
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
  Buffer<ClusterBounds> one(1);
  EXPECT_THROW(j.join(c, h, filters(), ok, &one), std::invalid_argument);
}

}  // namespace
}  // namespace fieldguard::perception
