#include "fieldguard/perception/cluster_join.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fieldguard/perception/cluster_filter.hpp"

namespace fieldguard::perception {

namespace {

constexpr std::uint32_t kNone = 0xFFFFFFFFU;

void check_length(double v, const char* what) {
  if (!(v >= 0.0) || !std::isfinite(v)) {
    throw std::invalid_argument(std::string("ClusterJoiner: ") + what + " must be finite and not negative");
  }
}

}  // namespace

ClusterJoiner::ClusterJoiner(const ClusterJoinParams& params) : params_(params) {
  check_length(params.float_height_m, "float_height_m");
  check_length(params.gap_m, "gap_m");
  check_length(params.fragment_gap_m, "fragment_gap_m");
  if (!(params.fragment_factor >= 1.0) || !std::isfinite(params.fragment_factor)) {
    throw std::invalid_argument("ClusterJoiner: fragment_factor must be finite and at least 1");
  }
  check_length(params.stack_margin_m, "stack_margin_m");
}

std::uint32_t ClusterJoiner::find(std::uint32_t c) {
  while (parent_[c] != c) {
    parent_[c] = parent_[parent_[c]];  // path halving
    c = parent_[c];
  }
  return c;
}

bool ClusterJoiner::unite(std::uint32_t a, std::uint32_t b) {
  const std::uint32_t ra = find(a), rb = find(b);
  if (ra == rb) return false;
  parent_[std::max(ra, rb)] = std::min(ra, rb);
  return true;
}

float ClusterJoiner::gap_between(std::size_t a, std::size_t b) const {
  const Info& p = info_[a];
  const Info& q = info_[b];
  const float gx = std::max(p.lo[0], q.lo[0]) - std::min(p.hi[0], q.hi[0]);
  const float gy = std::max(p.lo[1], q.lo[1]) - std::min(p.hi[1], q.hi[1]);
  return std::hypot(std::max(gx, 0.F), std::max(gy, 0.F));
}

std::uint32_t ClusterJoiner::join(const Cloud& cloud, std::span<const float> height_m, const FilterParams& filters,
                                  Clusters& clusters, Buffer<ClusterBounds>* bounds) {
  const std::size_t nc = clusters.size();
  if (bounds != nullptr && bounds->size() != nc) throw std::invalid_argument("ClusterJoiner: one bounds per cluster");
  const bool fragments = params_.fragment_gap_m > 0.0, attach = params_.gap_m > 0.0;
  if (!(params_.float_height_m > 0.0) || (!fragments && !attach && !params_.stacked) || nc < 2) return 0;
  const std::size_t n = cloud.size();
  if (height_m.size() < n) throw std::out_of_range("ClusterJoiner: fewer heights than points");
  const auto float_h = static_cast<float>(params_.float_height_m);
  constexpr float kBig = std::numeric_limits<float>::max();
  info_.resize(nc);
  for (std::size_t c = 0; c < nc; ++c) {
    const auto members = clusters[c];
    Info s{{kBig, kBig}, {-kBig, -kBig}, false, false, members.empty()};
    float low = kBig, r2 = kBig;
    if (bounds != nullptr) {  // the same figures: each a least or a greatest over the members
      const ClusterBounds& b = (*bounds)[c];
      s.lo[0] = b.min[0];
      s.lo[1] = b.min[1];
      s.hi[0] = b.max[0];
      s.hi[1] = b.max[1];
      low = b.bottom;
      r2 = b.r2;
    }
    for (const std::uint32_t i : bounds != nullptr ? std::span<const std::uint32_t>{} : members) {
      if (i >= n) throw std::out_of_range("ClusterJoiner: a cluster indexes a point past the cloud's end");
      const float x = cloud.x[i], y = cloud.y[i];
      s.lo[0] = std::min(s.lo[0], x);
      s.hi[0] = std::max(s.hi[0], x);
      s.lo[1] = std::min(s.lo[1], y);
      s.hi[1] = std::max(s.hi[1], y);
      low = std::min(low, height_m[i]);
      r2 = std::min(r2, x * x + y * y);
    }
    if (!s.empty) {
      s.floats = low >= float_h;
      // In double: exact for these counts, and with a factor of 1 the filters' own test.
      s.small = static_cast<double>(members.size()) <
                params_.fragment_factor * static_cast<double>(min_points_at(filters, std::sqrt(r2)));
    }
    info_[c] = s;
  }
  parent_.resize(nc);
  for (std::size_t c = 0; c < nc; ++c) parent_[c] = static_cast<std::uint32_t>(c);
  std::uint32_t joined = 0;

  // The pairs are found by a sweep along x over boxes sorted by their low x edge: a frame of scattered single
  // returns (rain, dust) makes thousands of clusters, and comparing every pair took 0.9 s for 16,000. Union-find
  // joins make the same groups in any order, each rooted at its lowest cluster index, so the result is the same.
  const auto sweep = [&](auto&& wanted, float reach, auto&& pair) {
    order_.clear();
    for (std::size_t c = 0; c < nc; ++c) {
      if (wanted(c)) order_.push_back(static_cast<std::uint32_t>(c));
    }
    std::sort(order_.begin(), order_.end(), [&](std::uint32_t a, std::uint32_t b) {
      return info_[a].lo[0] < info_[b].lo[0] || (info_[a].lo[0] == info_[b].lo[0] && a < b);
    });
    for (std::size_t i = 0; i < order_.size(); ++i) {
      const float x_end = info_[order_[i]].hi[0] + reach;
      for (std::size_t j = i + 1; j < order_.size() && info_[order_[j]].lo[0] <= x_end; ++j) {
        pair(std::min(order_[i], order_[j]), std::max(order_[i], order_[j]));
      }
    }
  };

  if (fragments) {
    // 1. Fragments with fragments: over a wider gap than rule 2's (fieldguard.yaml: 1.0 against 0.6 m). Fragments
    // are a few returns each, of one porous crown seen through gaps; widening rule 2's gap instead bridges
    // neighbouring crowns through the fragments between them.
    const auto gap = static_cast<float>(params_.fragment_gap_m);
    sweep([&](std::size_t c) { return !info_[c].empty && info_[c].small; }, gap,
          [&](std::uint32_t a, std::uint32_t b) {
            if (!(info_[a].floats || info_[b].floats) || gap_between(a, b) > gap) return;
            joined += unite(a, b) ? 1U : 0U;
          });
  }
  if (attach) {
    const auto gap = static_cast<float>(params_.gap_m);
    // 2. Each group with a floating fragment: to its one nearest cluster that is no fragment. Every group's choice is
    // made before any is applied, on the groups of step 1.
    attach_.assign(nc, kNone);
    attach_gap_.assign(nc, kBig);
    group_floats_.assign(nc, 0);
    big_.clear();
    for (std::size_t c = 0; c < nc; ++c) {
      if (!info_[c].empty && !info_[c].small) big_.push_back(static_cast<std::uint32_t>(c));
    }
    for (std::size_t a = 0; a < nc; ++a) {
      if (info_[a].empty || !info_[a].small) continue;
      const std::uint32_t r = find(static_cast<std::uint32_t>(a));
      if (info_[a].floats) group_floats_[r] = 1;
      for (const std::uint32_t b : big_) {
        const float g = gap_between(a, b);
        if (g <= gap && (g < attach_gap_[r] || (g == attach_gap_[r] && b < attach_[r]))) {
          attach_gap_[r] = g;
          attach_[r] = b;
        }
      }
    }
    for (std::size_t r = 0; r < nc; ++r) {
      if (attach_[r] == kNone || group_floats_[r] == 0U) continue;
      joined += unite(static_cast<std::uint32_t>(r), attach_[r]) ? 1U : 0U;
    }
  }
  if (params_.stacked) {
    // 3. Stacked: x-y boxes that overlap, or nearly (stack_margin_m on each axis).
    const auto margin = static_cast<float>(params_.stack_margin_m);
    sweep([&](std::size_t c) { return !info_[c].empty; }, margin,
          [&](std::uint32_t a, std::uint32_t b) {
            const Info& p = info_[a];
            const Info& q = info_[b];
            if (!(p.floats || q.floats)) return;
            const float gx = std::max(p.lo[0], q.lo[0]) - std::min(p.hi[0], q.hi[0]);
            const float gy = std::max(p.lo[1], q.lo[1]) - std::min(p.hi[1], q.hi[1]);
            if (gx > margin || gy > margin) return;
            joined += unite(a, b) ? 1U : 0U;
          });
  }
  if (joined == 0) return 0;

  // Relabel the points and rebuild in the order of each cluster's lowest point index. (Points in no cluster
  // stay in none.)
  root_.resize(nc);
  for (std::size_t c = 0; c < nc; ++c) root_[c] = find(static_cast<std::uint32_t>(c));
  merge_clusters({root_.data(), nc}, n, clusters, of_point_, id_, count_);
  if (bounds != nullptr) merge_bounds({root_.data(), nc}, id_, clusters.size(), *bounds, merged_bounds_);
  return joined;
}

}  // namespace fieldguard::perception
