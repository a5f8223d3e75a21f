#include "fieldguard/perception/cluster_filter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace fieldguard::perception {

std::string_view to_string(Rejection r) {
  switch (r) {
    case Rejection::Kept: return "kept";
    case Rejection::TooFewPoints: return "too few points";
    case Rejection::TooManyPoints: return "too many points";
    case Rejection::TooSmall: return "box too small";
    case Rejection::TooLarge: return "box too large";
    case Rejection::TooLow: return "too low above the ground";
    case Rejection::Porous: return "porous (crop canopy)";
  }
  return "?";
}

namespace {

constexpr float kBig = std::numeric_limits<float>::max();

// The bounds of no point: what a cluster's running figures start from.
ClusterBounds no_bounds(bool all_guessed) {
  return ClusterBounds{{kBig, kBig, kBig}, {-kBig, -kBig, -kBig}, kBig, -kBig, kBig, all_guessed};
}

// One cluster's figures, its points folded in in order (a tie keeps what it has): what summarize reports and
// bound_clusters keeps, so that both give the same bits. `n` is the cloud's size, for the index check.
ClusterBounds fold_points(const Cloud& cloud, std::span<const float> height_m, std::span<const std::uint8_t> guessed,
                          std::span<const std::uint32_t> indices, std::size_t n, const char* who) {
  ClusterBounds b = no_bounds(!guessed.empty());
  for (const std::uint32_t i : indices) {
    if (i >= n) throw std::out_of_range(std::string(who) + ": a cluster indexes a point past the cloud's end");
    b.ground_guessed = b.ground_guessed && guessed[i] != 0U;
    const float x = cloud.x[i], y = cloud.y[i], z = cloud.z[i];
    b.min[0] = std::min(b.min[0], x);
    b.max[0] = std::max(b.max[0], x);
    b.min[1] = std::min(b.min[1], y);
    b.max[1] = std::max(b.max[1], y);
    b.min[2] = std::min(b.min[2], z);
    b.max[2] = std::max(b.max[2], z);
    b.r2 = std::min(b.r2, x * x + y * y);
    b.top = std::max(b.top, height_m[i]);
    b.bottom = std::min(b.bottom, height_m[i]);
  }
  return b;
}

}  // namespace

ClusterSummary summarize(const Cloud& cloud, std::span<const float> height_m, std::span<const std::uint8_t> guessed,
                         std::span<const std::uint32_t> indices) {
  if (indices.empty()) return ClusterSummary{};
  return summary_of(fold_points(cloud, height_m, guessed, indices, cloud.size(), "summarize"),
                    static_cast<std::uint32_t>(indices.size()));
}

void bound_clusters(const Cloud& cloud, std::span<const float> height_m, std::span<const std::uint8_t> guessed,
                    const Clusters& clusters, Buffer<ClusterBounds>& out) {
  const std::size_t n = cloud.size(), nc = clusters.size();
  if (height_m.size() < n || (!guessed.empty() && guessed.size() < n)) {
    throw std::out_of_range("bound_clusters: fewer heights or guesses than points");
  }
  out.resize(nc);
  for (std::size_t c = 0; c < nc; ++c) out[c] = fold_points(cloud, height_m, guessed, clusters[c], n, "bound_clusters");
}

void merge_bounds(std::span<const std::uint32_t> target, std::span<const std::uint32_t> id, std::size_t merged,
                  Buffer<ClusterBounds>& bounds, Buffer<ClusterBounds>& scratch) {
  constexpr std::uint32_t kNone = 0xFFFFFFFFU;
  if (bounds.size() != target.size()) throw std::invalid_argument("merge_bounds: one target per cluster's bounds");
  // Every merged cluster has a part, whose own all-of started from whether there are guesses at all.
  scratch.assign(merged, no_bounds(true));
  // In cluster order, each part folded in as summarize folds in points (a tie keeps what it has).
  for (std::size_t c = 0; c < target.size(); ++c) {
    const std::uint32_t g = id[target[c]];
    if (g == kNone) continue;  // an empty cluster whose group got no point
    if (g >= merged) throw std::out_of_range("merge_bounds: a cluster past the merged ones");
    ClusterBounds& a = scratch[g];
    const ClusterBounds& b = bounds[c];
    for (std::size_t k = 0; k < 3; ++k) {
      a.min[k] = std::min(a.min[k], b.min[k]);
      a.max[k] = std::max(a.max[k], b.max[k]);
    }
    a.r2 = std::min(a.r2, b.r2);
    a.top = std::max(a.top, b.top);
    a.bottom = std::min(a.bottom, b.bottom);
    a.ground_guessed = a.ground_guessed && b.ground_guessed;
  }
  std::swap(bounds, scratch);
}

ClusterSummary summary_of(const ClusterBounds& b, std::uint32_t points) {
  ClusterSummary s;
  s.points = points;
  s.min = b.min;
  s.max = b.max;
  s.distance_m = std::sqrt(b.r2);
  s.height_above_ground_m = b.top;
  s.lowest_above_ground_m = b.bottom;
  s.ground_guessed = b.ground_guessed;
  return s;
}

void limit_height_to_extent(ClusterSummary& s, float floor_z) {
  if (!s.ground_guessed) return;
  s.height_above_ground_m = std::min(s.height_above_ground_m, s.max[2] - std::min(floor_z, s.min[2]));
}

std::uint32_t min_points_at(const FilterParams& f, float distance_m) {
  const auto full = static_cast<std::uint32_t>(std::max(f.min_points, 0));
  if (!(f.min_points_full_range_m > 0.0) || !(static_cast<double>(distance_m) > f.min_points_full_range_m)) return full;
  const double ratio = f.min_points_full_range_m / static_cast<double>(distance_m);
  const auto scaled = static_cast<std::uint32_t>(std::ceil(static_cast<double>(full) * ratio * ratio - 1e-9));
  const auto floor = static_cast<std::uint32_t>(std::max(f.min_points_floor, 0));
  return std::min(full, std::max(floor, scaled));
}

std::uint32_t min_points_of(const FilterParams& f, const ClusterSummary& s) {
  const std::uint32_t need = min_points_at(f, s.distance_m);
  if (!(f.float_min_height_m > 0.0) || !(static_cast<double>(s.lowest_above_ground_m) >= f.float_min_height_m)) {
    return need;
  }
  return std::min(need, static_cast<std::uint32_t>(std::max(f.float_min_points, 1)));
}

std::uint32_t least_min_points(const FilterParams& f) {
  // min_points_at never goes below min_points_floor beyond the full range (nor above min_points anywhere), and
  // min_points_of lowers that to float_min_points at most.
  const auto full = static_cast<std::uint32_t>(std::max(f.min_points, 0));
  std::uint32_t least = full;
  if (f.min_points_full_range_m > 0.0)
    least = std::min(least, static_cast<std::uint32_t>(std::max(f.min_points_floor, 0)));
  if (f.float_min_height_m > 0.0) least = std::min(least, static_cast<std::uint32_t>(std::max(f.float_min_points, 1)));
  return least;
}

double min_height_at(const FilterParams& f, float distance_m) {
  const double d = static_cast<double>(distance_m);
  if (!(f.min_height_growth_from_m > 0.0) || !(d > f.min_height_growth_from_m)) return f.min_height_m;
  const double grown = f.min_height_m + f.min_height_growth_per_m * (d - f.min_height_growth_from_m);
  return f.min_height_growth_max_m > 0.0 ? std::max(f.min_height_m, std::min(grown, f.min_height_growth_max_m)) : grown;
}

Rejection check_cluster(const FilterParams& f, const ClusterSummary& s) {
  if (s.points < min_points_of(f, s)) return Rejection::TooFewPoints;
  if (f.max_points > 0 && s.points > static_cast<std::uint32_t>(f.max_points)) return Rejection::TooManyPoints;
  const double v = static_cast<double>(s.volume_m3());
  if (v < f.min_volume_m3) return Rejection::TooSmall;
  if (f.max_volume_m3 > 0.0 && v > f.max_volume_m3) return Rejection::TooLarge;
  if (f.min_height_m > 0.0 && static_cast<double>(s.height_above_ground_m) < min_height_at(f, s.distance_m)) {
    return Rejection::TooLow;
  }
  return Rejection::Kept;
}

namespace {

// Porous when the ring jitter, over enough triples to tell, reaches canopy_min_jitter_m.
Rejection by_jitter(const FilterParams& f, const RingJitter& j, std::uint32_t min_triples) {
  if (j.triples < min_triples) return Rejection::Kept;
  return static_cast<double>(j.median_m) >= f.canopy_min_jitter_m ? Rejection::Porous : Rejection::Kept;
}

}  // namespace

Rejection check_canopy(const FilterParams& f, const ClusterSummary& s, const Cloud& cloud,
                       std::span<const std::uint32_t> indices, RingJitterMeter& meter, const FrameSurroundings* around,
                       Cloud* scratch) {
  if (!(f.canopy_max_height_m > 0.0) || static_cast<double>(s.height_above_ground_m) > f.canopy_max_height_m) {
    return Rejection::Kept;
  }
  const RingJitter j = meter.measure(cloud, indices);
  // Two returns 0.5 m apart along a ray are as likely a person and the ground behind: a needle needs three.
  constexpr std::uint32_t kNeedleMinPoints = 3;
  if (f.canopy_needle_depth_m > 0.0 && s.points >= kNeedleMinPoints &&
      static_cast<double>(j.depth_m) >= f.canopy_needle_depth_m &&
      static_cast<double>(j.depth_m) >= f.canopy_needle_ratio * static_cast<double>(j.width_m)) {
    return Rejection::Porous;
  }
  const auto min_triples = static_cast<std::uint32_t>(std::max(f.canopy_min_triples, 1));
  if (j.triples >= min_triples || around == nullptr || scratch == nullptr || !(f.canopy_surroundings_m > 0.0)) {
    return by_jitter(f, j, min_triples);
  }
  const FrameSurroundings& frame = *around;
  if (frame.marks.size() != frame.cloud.size() || frame.height_m.size() != frame.cloud.size()) {
    throw std::invalid_argument("check_canopy: one mark and one height per point of the frame");
  }
  for (const std::uint32_t i : indices) frame.marks[frame.in_cloud[i]] = 1U;
  LowSurroundings low;
  low.min = {s.min[0], s.min[1]};
  low.max = {s.max[0], s.max[1]};
  low.radius_m = static_cast<float>(f.canopy_surroundings_m);
  low.max_height_m = static_cast<float>(f.min_height_m);
  gather_low_surroundings(cloud, indices, frame.cloud, frame.height_m, frame.marks, low, *scratch);
  for (const std::uint32_t i : indices) frame.marks[frame.in_cloud[i]] = 0U;
  return by_jitter(f, meter.measure_all(*scratch), min_triples);
}

}  // namespace fieldguard::perception
