// Clusters regrouped: from per-point cluster numbers or labels, and merged by a target per cluster.
#include <algorithm>
#include <cstring>
#include <utility>

#include "fieldguard/perception/euclidean_cluster.hpp"
#include "perception/simd.hpp"

namespace fieldguard::perception {

void group_points(std::span<const std::uint32_t> cluster_of_point, std::uint32_t count, std::uint32_t none,
                  Clusters& out, Buffer<std::uint32_t>& scratch) {
  scratch.assign(count, 0U);  // the size of each cluster, then where its next member goes
  std::size_t members = 0;
  for (const std::uint32_t c : cluster_of_point) {
    if (c == none) continue;
    ++scratch[c];
    ++members;
  }
  out.offsets.resize(count + 1);
  out.offsets[0] = 0;
  for (std::uint32_t c = 0; c < count; ++c) out.offsets[c + 1] = out.offsets[c] + scratch[c];
  out.indices.resize(members);
  for (std::uint32_t c = 0; c < count; ++c) scratch[c] = out.offsets[c];
  for (std::size_t i = 0; i < cluster_of_point.size(); ++i) {
    const std::uint32_t c = cluster_of_point[i];
    if (c != none) out.indices[scratch[c]++] = static_cast<std::uint32_t>(i);
  }
}

namespace {

using u32x4 = std::uint32_t __attribute__((vector_size(16)));

// Whether `k` is as the clusterer orders its clusters: the non-empty clusters by their first index, each one's
// indices ascending (within a cluster, a descent is only allowed where a cluster begins).
bool in_first_point_order(const Clusters& k) {
  const std::size_t total = k.indices.size();
  const std::uint32_t* const v = k.indices.data();
  std::size_t descents = 0;
  std::size_t j = 1;
  if (total >= 5) {
    // Four neighbour pairs at a time: one instruction and a half a point, where a scalar loop took six.
    simd::i32x4 minus = simd::splat(std::int32_t{0});  // a descent is -1
    for (; j + 4 <= total; j += 4) {
      u32x4 prev, next;
      std::memcpy(&prev, v + j - 1, sizeof prev);
      std::memcpy(&next, v + j, sizeof next);
      minus += next <= prev;
    }
    for (int lane = 0; lane < 4; ++lane) descents += static_cast<std::uint32_t>(-minus[lane]);
  }
  for (; j < total; ++j) descents += v[j] <= v[j - 1] ? 1U : 0U;
  bool any = false;
  std::uint32_t last_first = 0;
  for (std::size_t c = 0; c < k.size(); ++c) {
    const std::uint32_t b = k.offsets[c];
    if (b == k.offsets[c + 1]) continue;
    if (any && v[b] <= last_first) return false;
    if (b > 0 && v[b] <= v[b - 1]) --descents;
    last_first = v[b];
    any = true;
  }
  return descents == 0;
}

// merge_clusters on clusters in first-point order, cluster by cluster: a group's lowest point is its first
// non-empty cluster's first, so the groups come in the order their targets first appear; a group of one cluster
// is copied whole, and a group of several is its largest cluster with the others' indices merged in. (Labelling
// every point and regrouping them, as group_by_first_point does, took four passes over the points.)
void merge_in_order(std::span<const std::uint32_t> target, Clusters& clusters, Buffer<std::uint32_t>& out,
                    Buffer<std::uint32_t>& id, Buffer<std::uint32_t>& scratch) {
  constexpr std::uint32_t kNone = 0xFFFFFFFFU;
  const std::size_t nc = clusters.size();
  const auto size_of = [&](std::size_t c) { return clusters.offsets[c + 1] - clusters.offsets[c]; };
  id.assign(nc, kNone);  // each target's group
  // Per group: its points (then where its indices begin), its largest cluster, its clusters, how many of its
  // indices are placed.
  scratch.resize(4 * nc + 1);
  std::uint32_t* const start = scratch.data();
  std::uint32_t* const base = start + nc + 1;
  std::uint32_t* const parts = base + nc;
  std::uint32_t* const placed = parts + nc;
  std::uint32_t groups = 0;
  for (std::size_t c = 0; c < nc; ++c) {
    const std::uint32_t m = size_of(c);
    if (m == 0) continue;
    std::uint32_t& g = id[target[c]];
    if (g == kNone) {
      g = groups++;
      start[g] = 0;
      base[g] = static_cast<std::uint32_t>(c);
      parts[g] = 0;
    }
    start[g] += m;
    ++parts[g];
    if (m > size_of(base[g])) base[g] = static_cast<std::uint32_t>(c);
  }
  std::uint32_t total = 0;
  for (std::uint32_t g = 0; g < groups; ++g) {
    const std::uint32_t m = start[g];
    start[g] = total;
    placed[g] = 0;
    total += m;
  }
  start[groups] = total;
  out.resize(total);
  // A group of one is copied; a group of several gets the indices of all but its largest cluster at its front.
  for (std::size_t c = 0; c < nc; ++c) {
    const std::uint32_t m = size_of(c);
    if (m == 0) continue;
    const std::uint32_t g = id[target[c]];
    if (parts[g] > 1 && base[g] == c) continue;
    std::memcpy(out.data() + start[g] + placed[g], clusters.indices.data() + clusters.offsets[c],
                m * sizeof(std::uint32_t));
    placed[g] += m;
  }
  for (std::uint32_t g = 0; g < groups; ++g) {
    if (parts[g] == 1) continue;
    std::uint32_t* const dst = out.data() + start[g];
    const std::uint32_t* const big = clusters.indices.data() + clusters.offsets[base[g]];
    std::size_t s = placed[g], b = size_of(base[g]);
    if (parts[g] > 2) std::sort(dst, dst + s);
    // Merged from the back, into the same region: the others' unread indices stay below every write.
    if (s * 16 < b) {
      // Few into many: each of the few finds its place by bisection, the run above it is copied whole.
      while (s > 0) {
        const std::uint32_t e = dst[s - 1];
        const std::size_t p = static_cast<std::size_t>(std::upper_bound(big, big + b, e) - big);
        std::memmove(dst + p + s, big + p, (b - p) * sizeof(std::uint32_t));
        dst[p + s - 1] = e;
        b = p;
        --s;
      }
    } else {
      while (s > 0 && b > 0) {
        if (big[b - 1] > dst[s - 1]) {
          dst[b + s - 1] = big[b - 1];
          --b;
        } else {
          dst[b + s - 1] = dst[s - 1];
          --s;
        }
      }
    }
    std::memcpy(dst, big, b * sizeof(std::uint32_t));
  }
  clusters.offsets.assign(start, start + groups + 1);
  std::swap(clusters.indices, out);
}

}  // namespace

void merge_clusters(std::span<const std::uint32_t> target, std::size_t points, Clusters& clusters,
                    Buffer<std::uint32_t>& of_point, Buffer<std::uint32_t>& id, Buffer<std::uint32_t>& scratch) {
  constexpr std::uint32_t kNone = 0xFFFFFFFFU;
  const std::size_t nc = clusters.size();
  if (in_first_point_order(clusters)) {
    merge_in_order(target, clusters, of_point, id, scratch);
    return;
  }
  of_point.assign(points, kNone);
  for (std::size_t c = 0; c < nc; ++c) {
    for (const std::uint32_t i : clusters[c]) of_point[i] = target[c];
  }
  group_by_first_point(of_point, static_cast<std::uint32_t>(nc), kNone, clusters, id, scratch);
}

void group_by_first_point(Buffer<std::uint32_t>& of_point, std::uint32_t labels, std::uint32_t none, Clusters& out,
                          Buffer<std::uint32_t>& id, Buffer<std::uint32_t>& scratch) {
  id.assign(labels, none);
  std::uint32_t count = 0;
  for (std::uint32_t& label : of_point) {
    if (label == none) continue;
    std::uint32_t& k = id[label];
    if (k == none) k = count++;
    label = k;
  }
  group_points({of_point.data(), of_point.size()}, count, none, out, scratch);
}

}  // namespace fieldguard::perception
