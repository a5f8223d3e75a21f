#include "fieldguard/perception/cluster_split.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "perception/indices.hpp"
#include "perception/simd.hpp"

namespace fieldguard::perception {

namespace {

using f64x2 = double __attribute__((vector_size(16)));

// A part also needs this share of the cluster's points, and never fewer than kMinPartPoints: a handful of stray
// returns at one end of a crown is not a second crown.
constexpr double kMinPartShare = 0.1;
constexpr std::size_t kMinPartPoints = 3;
// Slots along a cluster's axis at most: 4096 slots of 0.24 m (the narrowest gap fieldguard.yaml's radius and the
// ratio 0.6 can count) span 980 m; a longer cluster gets wider slots, and a narrower gap inside one goes unseen.
constexpr std::size_t kMaxSlots = 4096;
constexpr std::uint32_t kNone = 0xFFFFFFFFU;  // a point in no cluster

void check(double v, const char* what) {
  if (!(v >= 0.0) || !std::isfinite(v)) {
    throw std::invalid_argument(std::string("ClusterSplitter: ") + what + " must be finite and not negative");
  }
}

}  // namespace

ClusterSplitter::ClusterSplitter(const ClusterSplitParams& params) : params_(params) {
  check(params.min_length_m, "min_length_m");
  check(params.min_part_m, "min_part_m");
  if (params.min_part_points < 0) throw std::invalid_argument("ClusterSplitter: min_part_points must not be negative");
  if (!(params.full_range_m > 0.0) || !std::isfinite(params.full_range_m)) {
    throw std::invalid_argument("ClusterSplitter: full_range_m must be finite and positive");
  }
  // A ratio of 0 would count every gap between two returns.
  if (!(params.gap_ratio > 0.0) || !std::isfinite(params.gap_ratio)) {
    throw std::invalid_argument("ClusterSplitter: gap_ratio must be finite and positive");
  }
}

bool ClusterSplitter::find_cut(const Cloud& cloud, const EuclideanClusterer& clusterer,
                               std::span<const std::uint32_t> members, const Spread& sp, float& cut) {
  const std::size_t m = members.size();
  // The long axis: the principal axis of the x-y spread (moments about the first point: a cluster 40 m out spread
  // over centimetres keeps its digits).
  const double inv_m = 1.0 / static_cast<double>(m);
  const double dmx = sp.sx * inv_m, dmy = sp.sy * inv_m;
  const double sxx = sp.sxx * inv_m - dmx * dmx, sxy = sp.sxy * inv_m - dmx * dmy, syy = sp.syy * inv_m - dmy * dmy;
  const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
  const auto ax = static_cast<float>(std::cos(angle)), ay = static_cast<float>(std::sin(angle));
  const auto mx = static_cast<float>(sp.x0 + dmx), my = static_cast<float>(sp.y0 + dmy);
  // The projections lie within those of the x-y box's corners.
  float t_lo = std::numeric_limits<float>::max(), t_hi = std::numeric_limits<float>::lowest();
  for (const float cx : {sp.lo[0], sp.hi[0]}) {
    for (const float cy : {sp.lo[1], sp.hi[1]}) {
      const float t = (cx - mx) * ax + (cy - my) * ay;
      t_lo = std::min(t_lo, t);
      t_hi = std::max(t_hi, t);
    }
  }
  if (t_hi - t_lo < static_cast<float>(params_.min_length_m)) return false;
  // A cluster spanning most of the float range (nothing a sensor returns) overflows its projections: left whole.
  // Otherwise every projection is finite (the largest and least are at corners), so every slot's least and
  // greatest are reached by a member.
  if (!std::isfinite(t_hi - t_lo)) return false;

  // Slots along the axis no wider than the narrowest gap that can count (no radius is below tolerance_m): two
  // projections in one slot are never a gap, so the gaps between occupied slots are all the gaps there are
  // between the sorted projections that could reach the ratio, found without sorting.
  const auto ratio_min = static_cast<float>(params_.gap_ratio);
  const float gap_floor = ratio_min * static_cast<float>(clusterer.params().tolerance_m);
  const float width = std::max(gap_floor, (t_hi - t_lo) / static_cast<float>(kMaxSlots - 1));
  const float inv_width = 1.F / width;
  const auto slots = std::min<std::size_t>(kMaxSlots, static_cast<std::size_t>((t_hi - t_lo) * inv_width) + 1);
  const auto last_slot = static_cast<float>(slots - 1);
  // Each slot's least and greatest projection only; the points reaching them are looked for after, in the rare
  // cluster with a gap worth weighing (keeping them here, a branch per point, took a third of this loop).
  constexpr float kInf = std::numeric_limits<float>::infinity();
  slots_.assign(slots, Slot{0U, kInf, -kInf, kNone, kNone});
  const auto slot_of = [&](float t) {
    // As std::clamp to [0, last_slot] (a -0 gives slot 0 either way).
    return static_cast<std::size_t>(
        static_cast<std::int32_t>(std::min(std::max(0.F, (t - t_lo) * inv_width), last_slot)));
  };
  const auto add = [&](float t, std::int32_t s) {
    Slot& slot = slots_[static_cast<std::size_t>(s)];
    ++slot.count;
    slot.lo = std::min(slot.lo, t);
    slot.hi = std::max(slot.hi, t);
  };
  t_.resize(m);
  const float* const px = cloud.x.data();
  const float* const py = cloud.y.data();
  std::size_t k = 0;
  {
    // Four members a turn, their projections and slots lane by lane as slot_of's (the same operations in the same
    // order: the same bits), a run of four points loaded as vectors (most of a cluster's members are runs).
    const simd::f32x4 vmx = simd::splat(mx), vmy = simd::splat(my), vax = simd::splat(ax), vay = simd::splat(ay);
    const simd::f32x4 lo = simd::splat(t_lo), inv = simd::splat(inv_width), zero = simd::splat(0.F),
                      top = simd::splat(last_slot);
    const bool run_safe = cloud.size() < kRunSafe;  // every member is below the cloud's size (split checked)
    for (; k + 4 <= m; k += 4) {
      simd::f32x4 x, y;
      if (run_safe && run_of_four(members.data() + k)) {
        x = simd::load(px + members[k]);
        y = simd::load(py + members[k]);
      } else {
        const std::uint32_t i0 = members[k], i1 = members[k + 1], i2 = members[k + 2], i3 = members[k + 3];
        x = simd::f32x4{px[i0], px[i1], px[i2], px[i3]};
        y = simd::f32x4{py[i0], py[i1], py[i2], py[i3]};
      }
      const simd::f32x4 t = (x - vmx) * vax + (y - vmy) * vay;
      std::memcpy(t_.data() + k, &t, sizeof t);
      const simd::i32x4 s =
          __builtin_convertvector(simd::min_or_bound(simd::max_or_bound((t - lo) * inv, zero), top), simd::i32x4);
      add(t[0], s[0]);
      add(t[1], s[1]);
      add(t[2], s[2]);
      add(t[3], s[3]);
    }
  }
  for (; k < m; ++k) {
    const std::uint32_t i = members[k];
    const float t = (px[i] - mx) * ax + (py[i] - my) * ay;
    t_[k] = t;
    add(t, static_cast<std::int32_t>(slot_of(t)));
  }
  float front = 0.F, back = 0.F;
  for (const Slot& slot : slots_) {
    if (slot.count != 0) {
      front = slot.lo;
      break;
    }
  }
  for (std::size_t s = slots; s-- > 0;) {
    if (slots_[s].count != 0) {
      back = slots_[s].hi;
      break;
    }
  }
  if (back - front < static_cast<float>(params_.min_length_m)) return false;

  const auto min_part_m = static_cast<float>(params_.min_part_m);
  const std::size_t share =
      std::max(kMinPartPoints, static_cast<std::size_t>(std::ceil(kMinPartShare * static_cast<double>(m))));
  const auto full = static_cast<float>(params_.full_range_m);
  const auto part_points = static_cast<float>(params_.min_part_points);
  const auto range_of = [&cloud](std::uint32_t i) {
    return std::sqrt(cloud.x[i] * cloud.x[i] + cloud.y[i] * cloud.y[i] + cloud.z[i] * cloud.z[i]);
  };
  // Whether a gap between two occupied slots passes the tests that need no range.
  const auto may_cut = [&](const Slot& left, const Slot& right, float first, float end, std::size_t before) {
    const std::size_t after = m - before;
    return right.lo - left.hi >= gap_floor && before >= share && after >= share && left.hi - first >= min_part_m &&
           end - right.lo >= min_part_m;
  };
  {
    bool any = false;
    std::size_t before = 0;
    const Slot* last = nullptr;
    for (const Slot& slot : slots_) {
      if (slot.count == 0) continue;
      if (last != nullptr && may_cut(*last, slot, front, back, before)) {
        any = true;
        break;
      }
      before += slot.count;
      last = &slot;
    }
    if (!any) return false;
  }
  // The first member (in the order of `members`) reaching each slot's least and greatest projection: a gap's
  // range is taken at those two points.
  for (k = 0; k < m; ++k) {
    const float t = t_[k];
    Slot& slot = slots_[slot_of(t)];
    if (slot.lo_i == kNone && t == slot.lo) slot.lo_i = members[k];
    if (slot.hi_i == kNone && t == slot.hi) slot.hi_i = members[k];
  }
  bool found = false;
  float best_ratio = 0.F;
  std::size_t before = 0;  // points up to the last occupied slot
  const Slot* last = nullptr;
  for (const Slot& slot : slots_) {
    if (slot.count == 0) continue;
    if (last != nullptr && may_cut(*last, slot, front, back, before)) {
      const std::size_t after = m - before;
      const float gap = slot.lo - last->hi;
      const float r = 0.5F * (range_of(last->hi_i) + range_of(slot.lo_i));
      const float scale = r > full ? (full / r) * (full / r) : 1.F;
      const auto need = static_cast<std::size_t>(std::ceil(part_points * scale));
      // The horizontal radius between the two points beside the gap (at their mean elevation's rings).
      const auto sin_of = [&](std::uint32_t i) {
        const float ri = range_of(i);
        return ri > 0.F ? cloud.z[i] / ri : 0.F;
      };
      const float sin_mid = 0.5F * (sin_of(last->hi_i) + sin_of(slot.lo_i));
      const float ratio = gap / clusterer.horizontal_radius_at(r, sin_mid);
      if (before >= need && after >= need && ratio >= ratio_min && ratio > best_ratio) {
        best_ratio = ratio;
        cut = 0.5F * (last->hi + slot.lo);
        found = true;
      }
    }
    before += slot.count;
    last = &slot;
  }
  return found;
}

std::uint32_t ClusterSplitter::split(const Cloud& cloud, const EuclideanClusterer& clusterer, Clusters& clusters) {
  const std::size_t nc = clusters.size();
  if (!(params_.min_length_m > 0.0) || nc == 0) return 0;
  const std::size_t n = cloud.size();
  const auto min_len = static_cast<float>(params_.min_length_m);
  if (!all_below(clusters.indices, n)) {
    throw std::out_of_range("ClusterSplitter: a cluster indexes a point past the cloud's end");
  }
  std::uint32_t cuts = 0;
  for (std::size_t c = 0; c < nc; ++c) {
    const auto members = clusters[c];
    if (members.size() < 2 * kMinPartPoints) continue;
    // Its x-y box (whose diagonal bounds its extent along any axis: most clusters end here) and moments, in one pass.
    // x and y side by side in one vector: each lane's sums take the same steps in the same order as two scalars
    // would (the same bits), in half the instructions.
    const float x0 = cloud.x[members[0]], y0 = cloud.y[members[0]];
    const f64x2 origin = {static_cast<double>(x0), static_cast<double>(y0)};
    f64x2 sum = {0.0, 0.0}, square = {0.0, 0.0};
    double sxy = 0.0;
    simd::f32x4 lo = {x0, y0, 0.F, 0.F}, hi = lo;
    for (const std::uint32_t i : members) {
      const simd::f32x4 p = {cloud.x[i], cloud.y[i], 0.F, 0.F};
      lo = simd::min_or_bound(p, lo);  // p < lo ? p : lo, as std::min(lo, p)
      hi = simd::max_or_bound(p, hi);  // p > hi ? p : hi, as std::max(hi, p)
      const f64x2 d = __builtin_convertvector(__builtin_shufflevector(p, p, 0, 1), f64x2) - origin;
      sum += d;
      square += d * d;
      sxy += d[0] * d[1];
    }
    const Spread sp{origin[0], origin[1], sum[0], sum[1], square[0], sxy, square[1], {lo[0], lo[1]}, {hi[0], hi[1]}};
    if (std::hypot(sp.hi[0] - sp.lo[0], sp.hi[1] - sp.lo[1]) < min_len) continue;
    // A point not finite leaves no axis (and no slot to put it in): the cluster stays whole.
    if (!std::isfinite(sum[0] + sum[1] + square[0] + square[1] + sxy)) continue;
    float cut = 0.F;
    if (!find_cut(cloud, clusterer, members, sp, cut)) continue;
    if (cuts == 0) {  // the first cut: every point labelled with its cluster
      of_point_.assign(n, kNone);
      for (std::size_t d = 0; d < nc; ++d) {
        for (const std::uint32_t i : clusters[d]) of_point_[i] = static_cast<std::uint32_t>(d);
      }
    }
    // find_cut left each member's projection in t_: the part beyond the cut becomes a cluster of its own.
    const auto beyond = static_cast<std::uint32_t>(nc + cuts);
    for (std::size_t k = 0; k < members.size(); ++k) {
      if (!(t_[k] < cut)) of_point_[members[k]] = beyond;
    }
    ++cuts;
  }
  if (cuts == 0) return 0;
  // Rebuilt as the clusterer orders its clusters (by each one's lowest point index, members ascending); an empty
  // cluster is dropped, as the joiner drops them.
  group_by_first_point(of_point_, static_cast<std::uint32_t>(nc + cuts), kNone, clusters, id_, scratch_);
  return cuts;
}

}  // namespace fieldguard::perception
