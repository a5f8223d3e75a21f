#include "fieldguard/perception/cluster_filter.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "perception/indices.hpp"
#include "perception/simd.hpp"

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

// One point into a cluster's figures (a tie keeps what the figure has).
inline void fold_point(ClusterBounds& b, float x, float y, float z, float h) {
  b.min[0] = std::min(b.min[0], x);
  b.max[0] = std::max(b.max[0], x);
  b.min[1] = std::min(b.min[1], y);
  b.max[1] = std::max(b.max[1], y);
  b.min[2] = std::min(b.min[2], z);
  b.max[2] = std::max(b.max[2], z);
  b.r2 = std::min(b.r2, x * x + y * y);
  b.top = std::max(b.top, h);
  b.bottom = std::min(b.bottom, h);
}

// One cluster's figures, its points folded in in order (a tie keeps what it has): what summarize reports and
// bound_clusters keeps, so that both give the same bits. `n` is the cloud's size, for the index check.
ClusterBounds fold_points(const Cloud& cloud, std::span<const float> height_m, std::span<const std::uint8_t> guessed,
                          std::span<const std::uint32_t> indices, std::size_t n, const char* who) {
  ClusterBounds b = no_bounds(!guessed.empty());
  for (const std::uint32_t i : indices) {
    if (i >= n) throw std::out_of_range(std::string(who) + ": a cluster indexes a point past the cloud's end");
    b.ground_guessed = b.ground_guessed && guessed[i] != 0U;
    fold_point(b, cloud.x[i], cloud.y[i], cloud.z[i], height_m[i]);
  }
  return b;
}

// fold_points for a cluster of at least 4 points whose indices are all below the cloud's size: four at a time,
// lane k folding every fourth point from the k-th, then the lanes folded in lane order, a contiguous run of four
// indices loaded as vectors. A least or a greatest does not depend on the order its values come in (NaN is passed
// over in any order), but for -0 and +0: a tie, where the first seen stays. So a figure that comes out zero is
// found again one point at a time. (One point at a time took 26 instructions a point; this is the frame's one
// pass over its clustered points.)
template <bool kGuessed>
ClusterBounds fold_wide(const Cloud& cloud, std::span<const float> height_m, std::span<const std::uint8_t> guessed,
                        std::span<const std::uint32_t> indices) {
  using simd::f32x4;
  const f32x4 big = simd::splat(kBig), least = simd::splat(-kBig);
  f32x4 lo_x = big, lo_y = big, lo_z = big, lo_r2 = big, lo_h = big;
  f32x4 hi_x = least, hi_y = least, hi_z = least, hi_h = least;
  unsigned all = 1;
  const float* const px = cloud.x.data();
  const float* const py = cloud.y.data();
  const float* const pz = cloud.z.data();
  const float* const ph = height_m.data();
  const std::size_t m = indices.size();
  std::size_t k = 0;
  for (; k + 4 <= m; k += 4) {
    f32x4 x, y, z, h;
    if (run_of_four(indices.data() + k)) {  // straight loads (i0 < n < kRunSafe)
      const std::uint32_t i0 = indices[k];
      x = simd::load(px + i0);
      y = simd::load(py + i0);
      z = simd::load(pz + i0);
      h = simd::load(ph + i0);
      if constexpr (kGuessed) {
        std::uint32_t g4 = 0;
        std::memcpy(&g4, guessed.data() + i0, sizeof g4);
        // All four bytes nonzero: the expression is nonzero exactly when one of them is zero.
        all &= ((g4 - 0x01010101U) & ~g4 & 0x80808080U) == 0U ? 1U : 0U;
      }
    } else {
      const std::uint32_t i0 = indices[k], i1 = indices[k + 1], i2 = indices[k + 2], i3 = indices[k + 3];
      x = f32x4{px[i0], px[i1], px[i2], px[i3]};
      y = f32x4{py[i0], py[i1], py[i2], py[i3]};
      z = f32x4{pz[i0], pz[i1], pz[i2], pz[i3]};
      h = f32x4{ph[i0], ph[i1], ph[i2], ph[i3]};
      if constexpr (kGuessed) {
        all &= (guessed[i0] != 0U ? 1U : 0U) & (guessed[i1] != 0U ? 1U : 0U) & (guessed[i2] != 0U ? 1U : 0U) &
               (guessed[i3] != 0U ? 1U : 0U);
      }
    }
    lo_x = simd::min_or_bound(x, lo_x);
    hi_x = simd::max_or_bound(x, hi_x);
    lo_y = simd::min_or_bound(y, lo_y);
    hi_y = simd::max_or_bound(y, hi_y);
    lo_z = simd::min_or_bound(z, lo_z);
    hi_z = simd::max_or_bound(z, hi_z);
    lo_r2 = simd::min_or_bound(x * x + y * y, lo_r2);
    lo_h = simd::min_or_bound(h, lo_h);
    hi_h = simd::max_or_bound(h, hi_h);
  }
  ClusterBounds b = no_bounds(kGuessed && all != 0U);
  for (int j = 0; j < 4; ++j) {
    b.min[0] = std::min(b.min[0], lo_x[j]);
    b.max[0] = std::max(b.max[0], hi_x[j]);
    b.min[1] = std::min(b.min[1], lo_y[j]);
    b.max[1] = std::max(b.max[1], hi_y[j]);
    b.min[2] = std::min(b.min[2], lo_z[j]);
    b.max[2] = std::max(b.max[2], hi_z[j]);
    b.r2 = std::min(b.r2, lo_r2[j]);
    b.top = std::max(b.top, hi_h[j]);
    b.bottom = std::min(b.bottom, lo_h[j]);
  }
  for (; k < m; ++k) {
    const std::uint32_t i = indices[k];
    if constexpr (kGuessed) b.ground_guessed = b.ground_guessed && guessed[i] != 0U;
    fold_point(b, px[i], py[i], pz[i], ph[i]);
  }
  // (x^2 + y^2 is never -0.)
  const bool zero = b.min[0] == 0.F || b.max[0] == 0.F || b.min[1] == 0.F || b.max[1] == 0.F || b.min[2] == 0.F ||
                    b.max[2] == 0.F || b.top == 0.F || b.bottom == 0.F;
  return zero ? fold_points(cloud, height_m, guessed, indices, cloud.size(), "bound_clusters") : b;
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
  for (std::size_t c = 0; c < nc; ++c) {
    const auto members = clusters[c];
    if (members.size() < 8 || n >= kRunSafe ||
        !all_below(members, n)) {  // (an index past the end throws in fold_points)
      out[c] = fold_points(cloud, height_m, guessed, members, n, "bound_clusters");
    } else if (guessed.empty()) {
      out[c] = fold_wide<false>(cloud, height_m, guessed, members);
    } else {
      out[c] = fold_wide<true>(cloud, height_m, guessed, members);
    }
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
