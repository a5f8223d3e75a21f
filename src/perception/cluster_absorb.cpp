#include "fieldguard/perception/cluster_absorb.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fieldguard::perception {

ClusterAbsorber::ClusterAbsorber(int absorb_max_points, double absorb_margin_m) {
  if (absorb_max_points < 0) throw std::invalid_argument("ClusterAbsorber: absorb_max_points must not be negative");
  if (!(absorb_margin_m >= 0.0) || !std::isfinite(absorb_margin_m)) {
    throw std::invalid_argument("ClusterAbsorber: absorb_margin_m must be finite and not negative");
  }
  max_points_ = static_cast<std::uint32_t>(absorb_max_points);
  margin_ = static_cast<float>(absorb_margin_m);
}

std::uint32_t ClusterAbsorber::absorb(const Cloud& cloud, Clusters& clusters) {
  const std::size_t nc = clusters.size();
  if (max_points_ == 0 || nc < 2) return 0;
  const std::size_t n = cloud.size();
  boxes_.resize(nc);
  big_.clear();
  for (std::size_t c = 0; c < nc; ++c) {
    const auto members = clusters[c];
    for (const std::uint32_t i : members) {
      if (i >= n) throw std::out_of_range("ClusterAbsorber: a cluster indexes a point past the cloud's end");
    }
    if (members.empty()) {  // stays out of every test below: an empty box would hold nothing, fit anywhere
      boxes_[c] = Box{{0.F, 0.F, 0.F}, {0.F, 0.F, 0.F}};
      continue;
    }
    Box b{{cloud.x[members[0]], cloud.y[members[0]], cloud.z[members[0]]},
          {cloud.x[members[0]], cloud.y[members[0]], cloud.z[members[0]]}};
    for (const std::uint32_t i : members) {
      const float p[3] = {cloud.x[i], cloud.y[i], cloud.z[i]};
      for (int k = 0; k < 3; ++k) {
        b.lo[k] = std::min(b.lo[k], p[k]);
        b.hi[k] = std::max(b.hi[k], p[k]);
      }
    }
    boxes_[c] = b;
    if (members.size() > max_points_) big_.push_back(static_cast<std::uint32_t>(c));
  }
  if (big_.empty()) return 0;
  // Most points first (then lowest index: clusters are in the order of their lowest point), so a fragment
  // inside two overlapping boxes goes to the bigger cluster whatever the cloud's order.
  std::sort(big_.begin(), big_.end(), [&](std::uint32_t a, std::uint32_t b) {
    const std::size_t na = clusters[a].size(), nb = clusters[b].size();
    return na != nb ? na > nb : a < b;
  });
  target_.resize(nc);
  std::uint32_t moved = 0;
  for (std::size_t c = 0; c < nc; ++c) {
    target_[c] = static_cast<std::uint32_t>(c);
    if (clusters[c].empty() || clusters[c].size() > max_points_) continue;
    const Box& s = boxes_[c];
    for (const std::uint32_t b : big_) {
      const Box& g = boxes_[b];
      bool inside = true;
      for (int k = 0; k < 3 && inside; ++k) inside = s.lo[k] >= g.lo[k] - margin_ && s.hi[k] <= g.hi[k] + margin_;
      if (inside) {
        target_[c] = b;
        ++moved;
        break;
      }
    }
  }
  if (moved == 0) return 0;

  merge_clusters({target_.data(), nc}, n, clusters, of_point_, id_, count_);
  return moved;
}

}  // namespace fieldguard::perception
