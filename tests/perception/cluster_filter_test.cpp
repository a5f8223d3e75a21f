#include "fieldguard/perception/cluster_filter.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

#include "fieldguard/perception/euclidean_cluster.hpp"
#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

ClusterSummary summary(std::uint32_t points, float distance, std::array<float, 3> size, float height) {
  ClusterSummary s;
  s.points = points;
  s.distance_m = distance;
  s.min = {distance, 0.F, -0.9F};
  s.max = {distance + size[0], size[1], -0.9F + size[2]};
  s.height_above_ground_m = height;
  return s;
}

TEST(ClusterFilter, PublishedCountAndVolumeBoundsAreInclusive) {
  const FilterParams f = published_params().filters;
  EXPECT_EQ(check_cluster(f, summary(10, 5.F, {0.5F, 0.5F, 0.5F}, 0.F)), Rejection::Kept);
  EXPECT_EQ(check_cluster(f, summary(9, 5.F, {0.5F, 0.5F, 0.5F}, 0.F)), Rejection::TooFewPoints);
  EXPECT_EQ(check_cluster(f, summary(240, 5.F, {0.5F, 0.5F, 0.5F}, 0.F)), Rejection::Kept);
  EXPECT_EQ(check_cluster(f, summary(241, 5.F, {0.5F, 0.5F, 0.5F}, 0.F)), Rejection::TooManyPoints);
  EXPECT_EQ(check_cluster(f, summary(50, 5.F, {0.5F, 0.25F, 0.5F}, 0.F)), Rejection::Kept);     // 0.0625 m^3
  EXPECT_EQ(check_cluster(f, summary(50, 5.F, {0.2F, 0.2F, 1.0F}, 0.F)), Rejection::TooSmall);  // 0.04 m^3
  EXPECT_EQ(check_cluster(f, summary(50, 5.F, {1.F, 1.F, 1.25F}, 0.F)), Rejection::TooLarge);
  // Far and low: the published filters know neither.
  EXPECT_EQ(check_cluster(f, summary(10, 40.F, {0.5F, 0.5F, 0.5F}, 0.1F)), Rejection::Kept);
}

TEST(ClusterFilter, ZeroMaximaAreNoLimits) {
  FilterParams f;
  f.max_points = 0;
  f.max_volume_m3 = 0.0;
  f.min_height_m = 0.0;
  EXPECT_EQ(check_cluster(f, summary(100000, 5.F, {20.F, 10.F, 6.F}, 6.F)), Rejection::Kept);
}

// Height above the local ground: a 0.6 m object stays, a 0.3 m clod is terrain.
TEST(ClusterFilter, HeightAboveGroundKeepsAnObjectAndDropsAClod) {
  FilterParams f;
  f.min_height_m = 0.5;
  EXPECT_EQ(check_cluster(f, summary(30, 8.F, {0.4F, 0.4F, 0.6F}, 0.6F)), Rejection::Kept);
  EXPECT_EQ(check_cluster(f, summary(30, 8.F, {0.4F, 0.4F, 0.3F}, 0.3F)), Rejection::TooLow);
  f.min_height_m = 0.0;  // off
  EXPECT_EQ(check_cluster(f, summary(30, 8.F, {0.4F, 0.4F, 0.3F}, 0.3F)), Rejection::Kept);
}

TEST(ClusterFilter, MinimumPointsFallsWithDistance) {
  FilterParams f;
  f.min_points = 10;
  f.min_points_full_range_m = 12.0;
  f.min_points_floor = 3;
  EXPECT_EQ(min_points_at(f, 5.F), 10U);
  EXPECT_EQ(min_points_at(f, 12.F), 10U);
  EXPECT_EQ(min_points_at(f, 15.F), 7U);  // 10 * (12/15)^2 = 6.4 -> 7
  EXPECT_EQ(min_points_at(f, 20.F), 4U);  // 3.6 -> 4
  EXPECT_EQ(min_points_at(f, 30.F), 3U);  // 1.6 -> the floor
  // A side-on pedestrian at 30 m leaves a handful of voxels: enough far away, not enough near.
  EXPECT_EQ(check_cluster(f, summary(4, 30.F, {0.2F, 0.5F, 1.4F}, 1.6F)), Rejection::Kept);
  EXPECT_EQ(check_cluster(f, summary(4, 8.F, {0.2F, 0.5F, 1.4F}, 1.6F)), Rejection::TooFewPoints);
  f.min_points_full_range_m = 0.0;  // off: min_points everywhere
  EXPECT_EQ(min_points_at(f, 30.F), 10U);
  f.min_points_full_range_m = 12.0;
  f.min_points_floor = 50;  // a floor above min_points does not raise it
  EXPECT_EQ(min_points_at(f, 30.F), 10U);
}

// A crown seen through gaps floats: its lowest return stands well above the ground; crop, clods and people do not.
TEST(ClusterFilter, AFloatingClusterNeedsFewerPoints) {
  FilterParams f;  // 6 points up to 12 m
  f.float_min_height_m = 1.0;
  f.float_min_points = 3;
  ClusterSummary s = summary(3, 10.F, {0.5F, 0.5F, 0.5F}, 2.5F);
  s.lowest_above_ground_m = 1.2F;
  EXPECT_EQ(min_points_of(f, s), 3U);
  EXPECT_EQ(check_cluster(f, s), Rejection::Kept);
  s.points = 2;
  EXPECT_EQ(check_cluster(f, s), Rejection::TooFewPoints);
  // Standing on the ground (or 0.99 m up): the distance rule.
  s.points = 3;
  s.lowest_above_ground_m = 0.99F;
  EXPECT_EQ(min_points_of(f, s), 6U);
  EXPECT_EQ(check_cluster(f, s), Rejection::TooFewPoints);
  // Never more than the distance rule asks: far out 2 points do.
  s.lowest_above_ground_m = 1.5F;
  s.distance_m = 30.F;
  EXPECT_EQ(min_points_of(f, s), 2U);
  // Off (the default).
  f.float_min_height_m = 0.0;
  s.distance_m = 10.F;
  EXPECT_EQ(min_points_of(f, s), 6U);
}

// Far out a ring's slice of a clod stands 0.5-0.65 m above ground measured by one or two rings; a person 1.4 m.
TEST(ClusterFilter, LeastHeightGrowsWithDistance) {
  FilterParams f;                    // min_height_m 0.5
  f.min_height_growth_from_m = 0.0;  // growth off
  const ClusterSummary clod = summary(4, 40.F, {0.3F, 0.4F, 0.1F}, 0.6F);
  const ClusterSummary person = summary(4, 40.F, {0.2F, 0.5F, 1.4F}, 1.4F);
  EXPECT_EQ(check_cluster(f, clod), Rejection::Kept);  // off: the plain threshold
  EXPECT_DOUBLE_EQ(min_height_at(f, 40.F), 0.5);
  f.min_height_growth_from_m = 25.0;
  f.min_height_growth_per_m = 0.03;
  f.min_height_growth_max_m = 0.0;  // no cap
  EXPECT_DOUBLE_EQ(min_height_at(f, 20.F), 0.5);
  EXPECT_DOUBLE_EQ(min_height_at(f, 25.F), 0.5);
  EXPECT_NEAR(min_height_at(f, 35.F), 0.8, 1e-6);
  EXPECT_NEAR(min_height_at(f, 45.F), 1.1, 1e-6);  // no cap
  EXPECT_EQ(check_cluster(f, clod), Rejection::TooLow);
  EXPECT_EQ(check_cluster(f, person), Rejection::Kept);
  // The same clod near: the plain threshold.
  EXPECT_EQ(check_cluster(f, summary(30, 20.F, {0.3F, 0.4F, 0.1F}, 0.6F)), Rejection::Kept);
  f.min_height_growth_max_m = 0.8;
  EXPECT_NEAR(min_height_at(f, 45.F), 0.8, 1e-6);
  // The defaults (config/fieldguard.yaml): 0.5 m up to 25 m, 0.03 m per metre beyond, capped at 0.75 m.
  EXPECT_NEAR(min_height_at(FilterParams{}, 30.F), 0.65, 1e-6);
  EXPECT_NEAR(min_height_at(FilterParams{}, 45.F), 0.75, 1e-6);
  EXPECT_EQ(check_cluster(f, summary(4, 45.F, {0.3F, 0.4F, 0.1F}, 0.85F)), Rejection::Kept);
  EXPECT_EQ(check_cluster(f, summary(4, 45.F, {0.3F, 0.4F, 0.1F}, 0.75F)), Rejection::TooLow);
  // min_height_m 0 switches the height rule off altogether, growth included.
  f.min_height_m = 0.0;
  EXPECT_EQ(check_cluster(f, clod), Rejection::Kept);
}

TEST(ClusterFilter, Summary) {
  Cloud c;
  c.push_back(3.F, 4.F, -0.5F);
  c.push_back(6.F, 8.F, 0.5F);
  c.push_back(9.F, 9.F, 9.F);  // not in the cluster
  const std::vector<float> heights{0.4F, 1.4F, 3.F};
  const std::vector<std::uint32_t> members{0, 1};
  const ClusterSummary s = summarize(c, heights, {}, members);
  EXPECT_EQ(s.points, 2U);
  EXPECT_FLOAT_EQ(s.distance_m, 5.F);  // horizontal, to the nearest point
  EXPECT_FLOAT_EQ(s.height_above_ground_m, 1.4F);
  EXPECT_FLOAT_EQ(s.lowest_above_ground_m, 0.4F);
  EXPECT_EQ(s.min, (std::array<float, 3>{3.F, 4.F, -0.5F}));
  EXPECT_EQ(s.max, (std::array<float, 3>{6.F, 8.F, 0.5F}));
  EXPECT_FLOAT_EQ(s.volume_m3(), 12.F);
}

// Bit for bit (a signed zero or a NaN would tell summary_of from summarize where == could not).
void expect_same_summary(const ClusterSummary& a, const ClusterSummary& b, int trial) {
  const auto bits = [](float v) { return std::bit_cast<std::uint32_t>(v); };
  EXPECT_EQ(a.points, b.points) << "trial " << trial;
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(bits(a.min[k]), bits(b.min[k])) << "trial " << trial;
    EXPECT_EQ(bits(a.max[k]), bits(b.max[k])) << "trial " << trial;
  }
  EXPECT_EQ(bits(a.distance_m), bits(b.distance_m)) << "trial " << trial;
  EXPECT_EQ(bits(a.height_above_ground_m), bits(b.height_above_ground_m)) << "trial " << trial;
  EXPECT_EQ(bits(a.lowest_above_ground_m), bits(b.lowest_above_ground_m)) << "trial " << trial;
  EXPECT_EQ(a.ground_guessed, b.ground_guessed) << "trial " << trial;
}

// The pipeline summarizes from bounds found once for all clusters and merged along (bound_clusters,
// merge_bounds): each cluster's must be summarize's, before and after a merge, with and without guesses.
TEST(ClusterFilter, BoundsGiveTheSummaryBeforeAndAfterAMerge) {
  testing::TestRng rng(7);
  Buffer<std::uint32_t> of_point, id, scratch;
  Buffer<ClusterBounds> bounds, bounds_scratch;
  for (int trial = 0; trial < 60; ++trial) {
    Cloud c;
    std::vector<float> h;
    std::vector<std::uint8_t> guessed;
    const auto n = static_cast<std::uint32_t>(1 + rng.uniform(0.F, 300.F));
    for (std::uint32_t i = 0; i < n; ++i) {
      c.push_back(rng.uniform(-30.F, 30.F), rng.uniform(-30.F, 30.F), rng.uniform(-2.F, 4.F));
      h.push_back(rng.uniform(-0.5F, 3.F));
      guessed.push_back(rng.uniform(0.F, 1.F) < (trial % 3 == 0 ? 0.97F : 0.5F) ? 1U : 0U);
    }
    // Points dealt to clusters in order (so in the clusterer's order), an empty cluster now and then.
    const auto nc = static_cast<std::uint32_t>(1 + rng.uniform(0.F, 20.F));
    testing::Sets sets(nc);
    for (std::uint32_t i = 0; i < n; ++i) {
      sets[std::min(nc - 1, static_cast<std::uint32_t>(rng.uniform(0.F, static_cast<float>(nc))))].push_back(i);
    }
    std::stable_sort(sets.begin(), sets.end(),
                     [](const auto& a, const auto& b) { return !a.empty() && (b.empty() || a.front() < b.front()); });
    Clusters k = testing::clusters_of(sets);
    const std::span<const std::uint8_t> g =
        trial % 2 == 0 ? std::span<const std::uint8_t>{guessed} : std::span<const std::uint8_t>{};
    bound_clusters(c, h, g, k, bounds);
    ASSERT_EQ(bounds.size(), k.size());
    for (std::size_t j = 0; j < k.size(); ++j) {
      if (k[j].empty()) continue;
      expect_same_summary(summary_of(bounds[j], static_cast<std::uint32_t>(k[j].size())), summarize(c, h, g, k[j]),
                          trial);
    }
    // Every cluster to one of the first three, or kept.
    std::vector<std::uint32_t> target(k.size());
    for (std::size_t j = 0; j < k.size(); ++j) {
      target[j] = rng.uniform(0.F, 1.F) < 0.5F
                      ? static_cast<std::uint32_t>(j)
                      : std::min<std::uint32_t>(static_cast<std::uint32_t>(j),
                                                static_cast<std::uint32_t>(rng.uniform(0.F, 3.F)));
    }
    for (std::size_t j = 0; j < k.size(); ++j) target[j] = target[target[j]];
    merge_clusters(target, n, k, of_point, id, scratch);
    merge_bounds(target, id, k.size(), bounds, bounds_scratch);
    ASSERT_EQ(bounds.size(), k.size());
    for (std::size_t j = 0; j < k.size(); ++j) {
      expect_same_summary(summary_of(bounds[j], static_cast<std::uint32_t>(k[j].size())), summarize(c, h, g, k[j]),
                          trial);
    }
  }
  Cloud c;
  c.push_back(1.F, 1.F, 1.F);
  const std::vector<float> h{0.5F};
  Clusters past = testing::clusters_of({{0, 1}});
  EXPECT_THROW(bound_clusters(c, h, {}, past, bounds), std::out_of_range);
  Clusters ok = testing::clusters_of({{0}});
  EXPECT_THROW(bound_clusters(c, {}, {}, ok, bounds), std::out_of_range);
  bound_clusters(c, h, {}, ok, bounds);
  const std::vector<std::uint32_t> two_targets{0, 0};
  EXPECT_THROW(merge_bounds(two_targets, id, 1, bounds, bounds_scratch), std::invalid_argument);
}

// bound_clusters folds a cluster of 8 points or more four at a time (a run of four indices loaded straight, others
// gathered), then the lanes: it must still give summarize's bits where the order of the points tells, between -0
// and +0 (ties everywhere here), pass over NaN as summarize does, and take every member whatever the order of
// the indices (runs, shuffled, descending, with gaps).
TEST(ClusterFilter, BoundsFoldedFourAtATimeAreSummarizesBitForBit) {
  testing::TestRng rng(11);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Buffer<ClusterBounds> bounds;
  for (int trial = 0; trial < 400; ++trial) {
    // Half the trials from values with both zeros (the lanes' order would show), half without a zero (the
    // four-lane result itself is what comes out).
    const bool zeros = trial % 8 < 4;
    const auto pick = [&] {
      const float r = rng.uniform(0.F, 1.F);
      if (r < 0.1F) return nan;
      if (zeros) return r < 0.4F ? 0.F : r < 0.7F ? -0.F : r < 0.85F ? 1.F : -1.F;
      return r < 0.4F ? 0.5F : r < 0.7F ? -2.F : r < 0.85F ? 3.F : -0.25F;
    };
    Cloud c;
    std::vector<float> h;
    std::vector<std::uint8_t> guessed;
    const auto n = static_cast<std::uint32_t>(8 + rng.uniform(0.F, 60.F));
    for (std::uint32_t i = 0; i < n; ++i) {
      c.push_back(pick(), pick(), pick());
      h.push_back(pick());
      // Any nonzero byte is a guess; now and then one that is not, inside a run of four.
      const bool guess = rng.uniform(0.F, 1.F) < (trial % 3 == 0 ? 0.99F : 0.9F);
      guessed.push_back(guess ? static_cast<std::uint8_t>(1 + i % 3) : 0U);
    }
    std::vector<std::uint32_t> members;
    for (std::uint32_t i = 0; i < n; ++i) {
      if (trial % 4 != 3 || i % 5 != 2) members.push_back(i);  // trial % 4 == 3: gaps
    }
    if (trial % 4 == 1) {
      for (std::size_t i = members.size(); i > 1; --i) {
        const auto j = std::min(i - 1, static_cast<std::size_t>(rng.uniform(0.F, static_cast<float>(i))));
        std::swap(members[i - 1], members[j]);
      }
    } else if (trial % 4 == 2) {
      std::reverse(members.begin(), members.end());
    }
    const Clusters k = testing::clusters_of({members, {0U}});
    for (const bool with_guesses : {true, false}) {
      const std::span<const std::uint8_t> g =
          with_guesses ? std::span<const std::uint8_t>{guessed} : std::span<const std::uint8_t>{};
      bound_clusters(c, h, g, k, bounds);
      ASSERT_EQ(bounds.size(), 2U);
      expect_same_summary(summary_of(bounds[0], static_cast<std::uint32_t>(members.size())),
                          summarize(c, h, g, members), trial);
    }
  }
  // An index past the end inside a long cluster throws as in a short one.
  Cloud c;
  for (int i = 0; i < 12; ++i) c.push_back(static_cast<float>(i), 1.F, 1.F);
  const std::vector<float> h(12, 0.5F);
  std::vector<std::uint32_t> past{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
  for (const std::size_t at : {std::size_t{2}, std::size_t{9}}) {
    for (const std::uint32_t bad : {12U, 0x80000000U, 0xFFFFFFFFU}) {
      std::vector<std::uint32_t> members = past;
      members[at] = bad;
      EXPECT_THROW(bound_clusters(c, h, {}, testing::clusters_of({members}), bounds), std::out_of_range) << bad;
    }
  }
}

// Standing only on guessed ground (nothing measured near), a cluster's height is at most what it shows: one
// flat ring far out does not become a metre-high obstacle because the ground was extrapolated a metre low.
TEST(ClusterFilter, GuessedGroundLimitsTheHeightToTheClustersOwnExtent) {
  Cloud c;
  c.push_back(49.5F, -2.3F, -1.15F);
  c.push_back(49.8F, -2.8F, -1.16F);
  c.push_back(49.9F, -2.6F, -1.16F);
  const std::vector<float> heights{1.32F, 1.31F, 1.31F};
  const std::vector<std::uint32_t> members{0, 1, 2};
  const std::vector<std::uint8_t> guessed{1, 1, 1}, measured{0, 1, 1};
  ClusterSummary s = summarize(c, heights, guessed, members);
  EXPECT_TRUE(s.ground_guessed);
  limit_height_to_extent(s, s.min[2]);
  EXPECT_NEAR(s.height_above_ground_m, 0.01F, 1e-5F);
  // One point on measured ground: its height stands.
  s = summarize(c, heights, measured, members);
  EXPECT_FALSE(s.ground_guessed);
  limit_height_to_extent(s, s.min[2]);
  EXPECT_FLOAT_EQ(s.height_above_ground_m, 1.32F);
  // A person's chest seen by one ring, with its feet (labelled ground) 0.7 m below: 0.7 m.
  s = summarize(c, heights, guessed, members);
  limit_height_to_extent(s, -1.86F);
  EXPECT_NEAR(s.height_above_ground_m, 0.71F, 1e-5F);
}

// The pipeline rejects a cluster with fewer than least_min_points points without summarizing it: no summary may
// let such a cluster through, under any of the rules that lower the count (distance, floating), on or off.
TEST(ClusterFilter, NoClusterBelowTheLeastMinimumPasses) {
  testing::TestRng rng(5);
  const auto next = [&rng] { return rng.uniform(0.F, 1.F); };
  for (int variant = 0; variant < 16; ++variant) {
    FilterParams f;
    f.min_points = 6 + variant % 3;
    f.min_points_floor = variant % 4 == 3 ? -1 : 2 + variant % 2;
    f.min_points_full_range_m = (variant & 4) != 0 ? 0.0 : 12.0;
    f.float_min_height_m = (variant & 8) != 0 ? 0.0 : 1.0;
    f.float_min_points = variant % 5 == 4 ? 0 : 3;
    const std::uint32_t least = least_min_points(f);
    bool reached = false;  // some summary needs no more than `least`: it is the least, not merely a bound
    for (int i = 0; i < 20000; ++i) {
      ClusterSummary s;
      s.points = static_cast<std::uint32_t>(next() * 10.F);
      s.distance_m = i % 97 == 0 ? std::numeric_limits<float>::quiet_NaN() : 1e7F * next() * next() * next();
      s.lowest_above_ground_m = 3.F * next() - 1.F;
      s.height_above_ground_m = s.lowest_above_ground_m + 2.F;
      s.max = {1.F, 1.F, 1.F};
      if (s.points < least) {
        ASSERT_EQ(check_cluster(f, s), Rejection::TooFewPoints) << variant << " " << s.points;
      }
      reached = reached || min_points_of(f, s) == least;
    }
    EXPECT_TRUE(reached) << variant;
  }
}

}  // namespace
}  // namespace fieldguard::perception
