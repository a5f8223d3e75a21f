#pragma once
// A cluster holding two objects side by side is cut in two at the empty slot between them.
//
// Two orchard crowns in a row, 0.3-0.5 m apart, are joined by the clusterer wherever the tips of their porous
// crowns come within its horizontal radius of each other: near the sensor the radius (0.4 m) is hardly more than
// the gap, far out (1.2 m at 30 m) it is more than twice the gap. What stays of the gap is a slot with no returns
// across the whole cluster: project the cluster's points on its long horizontal axis (the principal axis of their
// x-y spread) and the two crowns are two runs of projections with a gap between them, while a single crown seen
// from the side is returns all along (a ring sweeps it in steps of a few centimetres; only its thin ends let rays
// through).
//
// The rule, on each cluster whose projections span at least `min_length_m`: the widest gap between consecutive
// projections, relative to the clusterer's horizontal radius at the gap's range, among the gaps that leave on each
// side a part at least `min_part_m` long with at least the part points below; the cluster is cut there when that
// gap is at least `gap_ratio` times the radius. A part needs at least 10 % of the cluster's points, at least 3,
// and at least `min_part_points` scaled by (full_range_m / r)^2 beyond full_range_m (r: the gap's 3D range):
// a crown seen in full within 10 m gives hundreds of returns, and the slot an occluding nearer crown leaves in a
// crown of the next row (seen through the gaps of the row in front) leaves it as a few dozen scattered ones.
// One cut per cluster. A person, a bale, a house wall or an implement has no such slot (its returns are
// continuous, or it is shorter than min_length_m).
//
// Output as EuclideanClusterer's: clusters in the order of their lowest point index, indices ascending within a
// cluster. Thread-compatible.

#include <cstddef>
#include <cstdint>
#include <span>

#include "fieldguard/perception/cloud.hpp"
#include "fieldguard/perception/euclidean_cluster.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

struct ClusterSplitParams {
  double min_length_m = 0.0;  // a cluster at least this long along its long axis is examined; 0 = off
  double min_part_m = 0.5;    // each part at least this long along the axis
  double gap_ratio = 0.6;     // the empty slot at least this times the clusterer's horizontal radius there
  int min_part_points = 40;   // each part's points within full_range_m (falling as (full_range_m / r)^2 beyond)
  double full_range_m = 10.0;
  [[nodiscard]] static ClusterSplitParams from(const ClusterParams& p) {
    return {p.split_min_length_m, p.split_min_part_m, p.split_gap_ratio, p.split_min_part_points, p.split_full_range_m};
  }
};

class ClusterSplitter {
 public:
  // Throws std::invalid_argument for a negative or non-finite length, a ratio or full range that is not finite and
  // positive, or a negative point count.
  explicit ClusterSplitter(const ClusterSplitParams& params);

  // `clusterer`: whose horizontal radius the gaps are measured against. `clusters` holds each of `cloud`'s points at
  // most once; rewritten in place when anything is cut (empty clusters dropped then). An index past the cloud's end
  // throws std::out_of_range. Returns the number of cuts. min_length_m 0: does nothing.
  std::uint32_t split(const Cloud& cloud, const EuclideanClusterer& clusterer, Clusters& clusters);

 private:
  // One cluster's cut: true with `cut` the projection on the long axis where it falls (each member's projection
  // left in t_, in the order of `members`); false when it stays whole.
  struct Spread {
    double x0, y0;                 // the first member: the moments are about it
    double sx, sy, sxx, sxy, syy;  // sums of dx, dy, dx^2, dx dy, dy^2
    float lo[2], hi[2];            // x-y box
  };
  bool find_cut(const Cloud& cloud, const EuclideanClusterer& clusterer, std::span<const std::uint32_t> members,
                const Spread& spread, float& cut);

  ClusterSplitParams params_;
  // Scratch, reused across frames.
  struct Slot {
    std::uint32_t count;
    float lo, hi;              // the lowest and highest projection in it
    std::uint32_t lo_i, hi_i;  // ... and the first members reaching them (looked for only when a gap may count)
  };
  Buffer<float> t_;  // per member of the cluster looked at: its projection on the long axis
  Buffer<Slot> slots_;
  Buffer<std::uint32_t> of_point_, id_, scratch_;  // each point's cluster after the cuts; group_by_first_point's
};

}  // namespace fieldguard::perception
