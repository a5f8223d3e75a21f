#include "fieldguard/perception/cluster_absorb.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "perception/simd.hpp"

namespace fieldguard::perception {

ClusterAbsorber::ClusterAbsorber(int absorb_max_points, double absorb_margin_m) {
  if (absorb_max_points < 0) throw std::invalid_argument("ClusterAbsorber: absorb_max_points must not be negative");
  if (!(absorb_margin_m >= 0.0) || !std::isfinite(absorb_margin_m)) {
    throw std::invalid_argument("ClusterAbsorber: absorb_margin_m must be finite and not negative");
  }
  max_points_ = static_cast<std::uint32_t>(absorb_max_points);
  margin_ = static_cast<float>(absorb_margin_m);
}

std::uint32_t ClusterAbsorber::absorb(const Cloud& cloud, Clusters& clusters, Buffer<ClusterBounds>* bounds) {
  const std::size_t nc = clusters.size();
  if (bounds != nullptr && bounds->size() != nc) {
    throw std::invalid_argument("ClusterAbsorber: one bounds per cluster");
  }
  if (max_points_ == 0 || nc < 2) return 0;
  const std::size_t n = cloud.size();
  boxes_.resize(nc);
  big_.clear();
  for (std::size_t c = 0; c < nc; ++c) {
    const auto members = clusters[c];
    if (members.empty()) {  // stays out of every test below: an empty box would hold nothing, fit anywhere
      boxes_[c] = Box{{0.F, 0.F, 0.F}, {0.F, 0.F, 0.F}};
      continue;
    }
    if (bounds != nullptr) {  // the same box: the least and greatest of each coordinate
      const ClusterBounds& b = (*bounds)[c];
      boxes_[c] = Box{{b.min[0], b.min[1], b.min[2]}, {b.max[0], b.max[1], b.max[2]}};
      if (members.size() > max_points_) big_.push_back(static_cast<std::uint32_t>(c));
      continue;
    }
    // One pass, each index checked before its point is read; the bounds in six scalars (written as a loop over
    // three axes, g++ -O2 kept the loop, and it cost most of this stage's instructions).
    const std::uint32_t first = members[0];
    if (first >= n) throw std::out_of_range("ClusterAbsorber: a cluster indexes a point past the cloud's end");
    float lx = cloud.x[first], ly = cloud.y[first], lz = cloud.z[first];
    float hx = lx, hy = ly, hz = lz;
    for (const std::uint32_t i : members) {
      if (i >= n) throw std::out_of_range("ClusterAbsorber: a cluster indexes a point past the cloud's end");
      const float x = cloud.x[i], y = cloud.y[i], z = cloud.z[i];
      lx = std::min(lx, x);
      hx = std::max(hx, x);
      ly = std::min(ly, y);
      hy = std::max(hy, y);
      lz = std::min(lz, z);
      hz = std::max(hz, z);
    }
    boxes_[c] = Box{{lx, ly, lz}, {hx, hy, hz}};
    if (members.size() > max_points_) big_.push_back(static_cast<std::uint32_t>(c));
  }
  if (big_.empty()) return 0;
  // Most points first (then lowest index: clusters are in the order of their lowest point), so a fragment
  // inside two overlapping boxes goes to the bigger cluster whatever the cloud's order.
  std::sort(big_.begin(), big_.end(), [&](std::uint32_t a, std::uint32_t b) {
    const std::size_t na = clusters[a].size(), nb = clusters[b].size();
    return na != nb ? na > nb : a < b;
  });
  // The big clusters' boxes grown by the margin, one array per bound in big_'s order, padded to a multiple of
  // four with boxes that hold nothing (lower bounds +inf, upper -inf): each small cluster is tested against four
  // at a time, and takes the first that holds it, as one at a time in big_'s order would.
  const std::size_t nb = big_.size(), padded = (nb + 3) & ~std::size_t{3};
  for (auto& a : grown_) a.resize(padded);
  constexpr float kInf = std::numeric_limits<float>::infinity();
  for (std::size_t j = 0; j < padded; ++j) {
    for (std::size_t k = 0; k < 3; ++k) {
      grown_[k][j] = j < nb ? boxes_[big_[j]].lo[k] - margin_ : kInf;
      grown_[3 + k][j] = j < nb ? boxes_[big_[j]].hi[k] + margin_ : -kInf;
    }
  }
  target_.resize(nc);
  std::uint32_t moved = 0;
  for (std::size_t c = 0; c < nc; ++c) {
    target_[c] = static_cast<std::uint32_t>(c);
    if (clusters[c].empty() || clusters[c].size() > max_points_) continue;
    const Box& s = boxes_[c];
    const simd::f32x4 lx = simd::splat(s.lo[0]), ly = simd::splat(s.lo[1]), lz = simd::splat(s.lo[2]);
    const simd::f32x4 hx = simd::splat(s.hi[0]), hy = simd::splat(s.hi[1]), hz = simd::splat(s.hi[2]);
    for (std::size_t j = 0; j < padded; j += 4) {
      const simd::i32x4 inside = (lx >= simd::load(grown_[0].data() + j)) & (ly >= simd::load(grown_[1].data() + j)) &
                                 (lz >= simd::load(grown_[2].data() + j)) & (hx <= simd::load(grown_[3].data() + j)) &
                                 (hy <= simd::load(grown_[4].data() + j)) & (hz <= simd::load(grown_[5].data() + j));
      const unsigned hits = simd::mask_bits(inside);
      if (hits == 0U) continue;
      target_[c] = big_[j + static_cast<std::size_t>(std::countr_zero(hits))];
      ++moved;
      break;
    }
  }
  if (moved == 0) return 0;

  merge_clusters({target_.data(), nc}, n, clusters, of_point_, id_, count_);
  if (bounds != nullptr) merge_bounds({target_.data(), nc}, id_, clusters.size(), *bounds, merged_bounds_);
  return moved;
}

}  // namespace fieldguard::perception
