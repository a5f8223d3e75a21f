#include "fieldguard/perception/cluster_filter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

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

ClusterSummary summarize(const Cloud& cloud, std::span<const float> height_m, std::span<const std::uint8_t> guessed,
                         std::span<const std::uint32_t> indices) {
  ClusterSummary s;
  if (indices.empty()) return s;
  constexpr float kBig = std::numeric_limits<float>::max();
  float lo[3] = {kBig, kBig, kBig}, hi[3] = {-kBig, -kBig, -kBig};
  float r2 = kBig, top = -kBig, bottom = kBig;
  bool all_guessed = !guessed.empty();
  for (const std::uint32_t i : indices) {
    all_guessed = all_guessed && guessed[i] != 0U;
    const float x = cloud.x[i], y = cloud.y[i], z = cloud.z[i];
    lo[0] = std::min(lo[0], x);
    hi[0] = std::max(hi[0], x);
    lo[1] = std::min(lo[1], y);
    hi[1] = std::max(hi[1], y);
    lo[2] = std::min(lo[2], z);
    hi[2] = std::max(hi[2], z);
    r2 = std::min(r2, x * x + y * y);
    top = std::max(top, height_m[i]);
    bottom = std::min(bottom, height_m[i]);
  }
  s.points = static_cast<std::uint32_t>(indices.size());
  s.min = {lo[0], lo[1], lo[2]};
  s.max = {hi[0], hi[1], hi[2]};
  s.distance_m = std::sqrt(r2);
  s.height_above_ground_m = top;
  s.lowest_above_ground_m = bottom;
  s.ground_guessed = all_guessed;
  return s;
}

namespace {

constexpr float kBig = std::numeric_limits<float>::max();

// The bounds of no point: what summarize's running figures start from.
ClusterBounds no_bounds(bool all_guessed) {
  return ClusterBounds{{kBig, kBig, kBig}, {-kBig, -kBig, -kBig}, kBig, -kBig, kBig, all_guessed};
}

}  // namespace

void bound_clusters(const Cloud& cloud, std::span<const float> height_m, std::span<const std::uint8_t> guessed,
                    const Clusters& clusters, Buffer<ClusterBounds>& out) {
  const std::size_t n = cloud.size(), nc = clusters.size();
  if (height_m.size() < n || (!guessed.empty() && guessed.size() < n)) {
    throw std::out_of_range("bound_clusters: fewer heights or guesses than points");
  }
  out.resize(nc);
  // summarize's loop, step for step (the same figures in the same order, so the same bits), over every cluster.
  for (std::size_t c = 0; c < nc; ++c) {
    float lo[3] = {kBig, kBig, kBig}, hi[3] = {-kBig, -kBig, -kBig};
    float r2 = kBig, top = -kBig, bottom = kBig;
    bool all_guessed = !guessed.empty();
    for (const std::uint32_t i : clusters[c]) {
      if (i >= n) throw std::out_of_range("bound_clusters: a cluster indexes a point past the cloud's end");
      all_guessed = all_guessed && guessed[i] != 0U;
      const float x = cloud.x[i], y = cloud.y[i], z = cloud.z[i];
      lo[0] = std::min(lo[0], x);
      hi[0] = std::max(hi[0], x);
      lo[1] = std::min(lo[1], y);
      hi[1] = std::max(hi[1], y);
      lo[2] = std::min(lo[2], z);
      hi[2] = std::max(hi[2], z);
      r2 = std::min(r2, x * x + y * y);
      top = std::max(top, height_m[i]);
      bottom = std::min(bottom, height_m[i]);
    }
    out[c] = ClusterBounds{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}, r2, top, bottom, all_guessed};
  }
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
