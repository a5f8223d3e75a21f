#pragma once
// Clusters that float join what they belong to.
//
// A porous crown seen through the gaps of a nearer row, or far out, returns a few points at random depths inside
// it, and its trunk a few more below. The anisotropic radius that keeps two crowns 0.3-0.5 m apart as two leaves
// such a crown as fragments of one to a handful of points, each dropped by the minimum point count (the crown is
// missed), or as two obstacles, one above the other (crown and trunk, or two slices of the crown: it is split).
// ClusterAbsorber only helps where one big cluster's box holds the fragments.
//
// A cluster "floats" when its lowest point stands at least `float_height_m` above its local ground: crop canopy
// and terrain never float, and a person's lowest returns are feet or legs. Every rule needs a floating cluster:
//   1. fragments: two clusters each with fewer points than `fragment_factor` times the filters' minimum at its
//      distance (min_points_at), one of them floating, whose x-y boxes are at most `fragment_gap_m` apart, join
//      (transitively);
//   2. each group of fragments holding a floating one joins the one nearest cluster that is no fragment whose x-y
//      box is at most `gap_m` from a fragment's (the nearest by that gap; the lower index on a tie). One only: a
//      fragment between two crowns must not make the two one;
//   3. stacked (`stacked`): a floating cluster joins every cluster whose x-y box is no farther than
//      `stack_margin_m` from its own along x and along y (a crown over its trunk, the slices of one crown).
// Gaps are between axis-aligned x-y boxes, whatever the heights. The result is a function of the input clusters
// and their order only.
//
// Output as EuclideanClusterer's: clusters in the order of their lowest point index, indices ascending within a
// cluster. Thread-compatible.

#include <cstdint>
#include <span>

#include "fieldguard/perception/cloud.hpp"
#include "fieldguard/perception/cluster_filter.hpp"
#include "fieldguard/perception/euclidean_cluster.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

struct ClusterJoinParams {
  double float_height_m = 0.0;  // lowest point at least this high above the local ground: floats; 0 = off
  double gap_m = 0.0;           // rule 2: horizontal gap between x-y boxes (m); 0 = rule 2 off
  bool stacked = false;         // rule 3 on
  double stack_margin_m = 0.0;  // rule 3: x-y boxes this far apart on each axis still stack (m)
  double fragment_gap_m = 0.0;  // rule 1: horizontal gap between x-y boxes (m); 0 = rule 1 off
  // Rules 1 and 2: a fragment has fewer points than this times min_points_at (at least 1: every cluster the filters
  // drop is a fragment).
  double fragment_factor = 1.0;
  [[nodiscard]] static ClusterJoinParams from(const ClusterParams& p) {
    return {p.join_float_height_m, p.join_gap_m,          p.join_stacked,
            p.join_stack_margin_m, p.join_fragment_gap_m, p.join_fragment_factor};
  }
};

class ClusterJoiner {
 public:
  // Throws std::invalid_argument for a negative or non-finite height, gap or margin.
  explicit ClusterJoiner(const ClusterJoinParams& params);

  // `height_m`: each of `cloud`'s points' height above its local ground; `filters`: the minimum point count at a
  // cluster's distance. `clusters` holds each point at most once; rewritten in place (empty clusters dropped when
  // anything joined). An index past the cloud's end, or fewer heights than points, throws std::out_of_range.
  // Returns the number of joins made. float_height_m 0: does nothing. `bounds`, when given: bound_clusters of
  // `clusters` with `height_m` (each cluster's box, lowest height and nearest point are taken from it), merged
  // along (one per cluster, or std::invalid_argument).
  std::uint32_t join(const Cloud& cloud, std::span<const float> height_m, const FilterParams& filters,
                     Clusters& clusters, Buffer<ClusterBounds>* bounds = nullptr);

 private:
  struct Info {
    float lo[2];  // x-y box
    float hi[2];
    bool floats;
    bool small;
    bool empty;
  };
  std::uint32_t find(std::uint32_t c);
  bool unite(std::uint32_t a, std::uint32_t b);
  [[nodiscard]] float gap_between(std::size_t a, std::size_t b) const;

  ClusterJoinParams params_;
  // Scratch, reused across frames.
  Buffer<Info> info_;
  Buffer<std::uint32_t> parent_;
  Buffer<std::uint32_t> attach_;  // per fragment group (its root): the cluster it joins
  Buffer<float> attach_gap_;
  Buffer<std::uint8_t> group_floats_;
  Buffer<std::uint32_t> order_;  // the sweep's clusters, by their low x edge
  Buffer<std::uint32_t> big_;    // clusters that are no fragments
  Buffer<std::uint32_t> root_;   // per cluster: its union-find root, the cluster it ends in
  Buffer<std::uint32_t> of_point_;
  Buffer<std::uint32_t> id_;
  Buffer<std::uint32_t> count_;
  Buffer<ClusterBounds> merged_bounds_;
};

}  // namespace fieldguard::perception
