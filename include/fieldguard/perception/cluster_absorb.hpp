#pragma once
// Small clusters inside a bigger one's box join it.
//
// A porous crown returns points at a random depth inside it, so a small clustering radius (needed to keep two
// crowns a few tenths of a metre apart as two) leaves a few of its returns as fragments of one to a handful of
// points, away from the rest by more than the radius but inside the crown's extent. Left alone, they are
// either dropped by the minimum point count (and with them a far or occluded crown that returns only a few
// points) or reported as obstacles of their own on the same crown. The rule: a cluster of at most
// `absorb_max_points` points whose box lies inside the box of a cluster with more points, grown by
// `absorb_margin_m` on every side, becomes part of it (of the one with the most points when several hold it).
// Only small clusters move, and only into big ones, so the result does not depend on any order.
//
// Output as EuclideanClusterer's: clusters in the order of their lowest point index, indices ascending within a
// cluster. Thread-compatible.

#include <array>
#include <cstdint>

#include "fieldguard/perception/cloud.hpp"
#include "fieldguard/perception/cluster_filter.hpp"
#include "fieldguard/perception/euclidean_cluster.hpp"

namespace fieldguard::perception {

class ClusterAbsorber {
 public:
  // Throws std::invalid_argument for a negative or non-finite margin or a negative point count.
  ClusterAbsorber(int absorb_max_points, double absorb_margin_m);

  // `clusters` holds each of `cloud`'s points at most once (EuclideanClusterer's hold each exactly once); rewritten
  // in place. An index past the cloud's end throws std::out_of_range. Returns how many clusters were absorbed.
  // absorb_max_points 0: does nothing. `bounds`, when given: bound_clusters of `clusters` (their boxes are taken
  // from it), merged along (one per cluster, or std::invalid_argument).
  std::uint32_t absorb(const Cloud& cloud, Clusters& clusters, Buffer<ClusterBounds>* bounds = nullptr);

 private:
  struct Box {
    float lo[3];
    float hi[3];
  };
  std::uint32_t max_points_;
  Buffer<ClusterBounds> merged_bounds_;
  float margin_;
  // Scratch, reused across frames.
  Buffer<Box> boxes_;
  Buffer<std::uint32_t> big_;           // clusters with more than max_points_ points, most points first
  std::array<Buffer<float>, 6> grown_;  // the big clusters' boxes grown by margin_: lo x, y, z, hi x, y, z
  Buffer<std::uint32_t> target_;        // per cluster: the cluster it ends in
  Buffer<std::uint32_t> of_point_;
  Buffer<std::uint32_t> id_;
  Buffer<std::uint32_t> count_;
};

}  // namespace fieldguard::perception
