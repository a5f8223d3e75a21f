#pragma once
// Which clusters are obstacles: point count (its minimum falling with distance when configured), box volume,
// and height above the local ground (clods, ridges and furrows below it are terrain).

#include <array>
#include <cstdint>
#include <span>
#include <string_view>

#include "fieldguard/perception/canopy.hpp"
#include "fieldguard/perception/cloud.hpp"
#include "fieldguard/perception/euclidean_cluster.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

struct ClusterSummary {
  std::uint32_t points = 0;
  std::array<float, 3> min{};  // axis-aligned box (m)
  std::array<float, 3> max{};
  float distance_m = 0.F;             // horizontal distance from the sensor to the nearest point
  float height_above_ground_m = 0.F;  // of the highest point above its local ground
  float lowest_above_ground_m = 0.F;  // of the lowest point above its local ground
  bool ground_guessed = false;        // every point stands on guessed ground (GroundLabels::guessed)
  [[nodiscard]] float volume_m3() const { return (max[0] - min[0]) * (max[1] - min[1]) * (max[2] - min[2]); }
};

enum class Rejection : std::uint8_t { Kept = 0, TooFewPoints, TooManyPoints, TooSmall, TooLarge, TooLow, Porous };
[[nodiscard]] std::string_view to_string(Rejection r);

// `height_m`: every cloud point's height above its local ground; `guessed`: 1 where that ground is a guess
// (empty: none is). An index past the cloud's end throws std::out_of_range.
[[nodiscard]] ClusterSummary summarize(const Cloud& cloud, std::span<const float> height_m,
                                       std::span<const std::uint8_t> guessed, std::span<const std::uint32_t> indices);

// summarize's figures for every cluster of a frame in one pass, in a form that merges: each a least, a greatest or
// an all-of over the cluster's points, so the bounds of two clusters merged are the bounds of the two (the
// absorber and the joiner keep them so), and summary_of gives what summarize would. (The frame's clusters hold most
// of its points: one pass over them instead of one per stage.)
struct ClusterBounds {
  std::array<float, 3> min;  // axis-aligned box (m)
  std::array<float, 3> max;
  float r2;      // the least x^2 + y^2 (m^2)
  float top;     // the greatest height above the local ground
  float bottom;  // ... and the least
  bool ground_guessed;
};

// The bounds of each of `clusters` (of `cloud`'s points), `height_m` and `guessed` as for summarize. An index past
// the cloud's end, or fewer heights (or guesses, unless none) than points, throws std::out_of_range.
void bound_clusters(const Cloud& cloud, std::span<const float> height_m, std::span<const std::uint8_t> guessed,
                    const Clusters& clusters, Buffer<ClusterBounds>& out);

// The bounds after merge_clusters (euclidean_cluster.hpp) with `target` left `id` (each target's cluster after
// the merge, or none when it got no point), into `merged` clusters. `scratch` is reused.
void merge_bounds(std::span<const std::uint32_t> target, std::span<const std::uint32_t> id, std::size_t merged,
                  Buffer<ClusterBounds>& bounds, Buffer<ClusterBounds>& scratch);

// summarize's result for a cluster of `points` points (at least one) with bounds `b`.
[[nodiscard]] ClusterSummary summary_of(const ClusterBounds& b, std::uint32_t points);

// Where no ground was measured under a cluster (ground_guessed), its height above ground is a guess too: three
// flat returns of one ring far out are as likely the ground as anything standing on it. Such a cluster's
// height is then no more than it shows itself: from `floor_z` (its lowest point, or a lower ground-labelled
// point under it, such as a person's feet) to its top.
void limit_height_to_extent(ClusterSummary& s, float floor_z);

// The least point count of a cluster at `distance_m`: min_points, or beyond min_points_full_range_m
// min_points * (full_range / d)^2 rounded up, but not below min_points_floor.
[[nodiscard]] std::uint32_t min_points_at(const FilterParams& f, float distance_m);

// The least point count of the cluster `s`: min_points_at its distance, or float_min_points if lower and it floats
// (its lowest point at least float_min_height_m above its ground).
[[nodiscard]] std::uint32_t min_points_of(const FilterParams& f, const ClusterSummary& s);

// The least point count min_points_of can ask of any cluster, wherever it stands: a cluster with fewer points is
// TooFewPoints whatever its summary says, so the pipeline rejects it without summarizing it.
[[nodiscard]] std::uint32_t least_min_points(const FilterParams& f);

// The least height above ground of a cluster at `distance_m`: min_height_m, or beyond min_height_growth_from_m
// min_height_m + min_height_growth_per_m * (d - from), never above min_height_growth_max_m when that is set.
[[nodiscard]] double min_height_at(const FilterParams& f, float distance_m);

// Bounds are inclusive: a cluster of exactly min_points points, or exactly min_volume_m3, is kept.
[[nodiscard]] Rejection check_cluster(const FilterParams& f, const ClusterSummary& s);

// The frame around a cluster, for check_canopy's look at its surroundings: every point (`cloud`, the voxels) with
// its height above its ground; `in_cloud` maps each point of the cluster's cloud to its index in `cloud`; `marks`
// is scratch, one zero per point of `cloud` (left zero).
struct FrameSurroundings {
  const Cloud& cloud;
  std::span<const float> height_m;
  std::span<const std::uint32_t> in_cloud;
  std::span<std::uint8_t> marks;
};

// A second look at a cluster check_cluster kept, in its cloud (`indices` its points): Porous when it is no
// higher than canopy_max_height_m and its ring jitter (canopy.hpp) says canopy; else Kept. With fewer than
// canopy_min_triples triples of its own, `around` given and canopy_surroundings_m > 0, its jitter is measured
// together with its low surroundings instead (gather_low_surroundings: within canopy_surroundings_m of its x-y
// box, lower than min_height_m above their ground); `scratch` then holds the gathered points. A cluster with
// enough triples of its own is decided by them alone (a solid box standing in a crop stays a box).
// Throws std::invalid_argument when `around` has not one mark and one height per point of its cloud.
[[nodiscard]] Rejection check_canopy(const FilterParams& f, const ClusterSummary& s, const Cloud& cloud,
                                     std::span<const std::uint32_t> indices, RingJitterMeter& meter,
                                     const FrameSurroundings* around = nullptr, Cloud* scratch = nullptr);

}  // namespace fieldguard::perception
