#pragma once
// Euclidean clustering: the connected components of the graph that joins two points nearer than the
// clustering radius, as pcl::EuclideanClusterExtraction finds them (breadth-first from the lowest
// unclustered index, radius searches, a point joins once).
//
// Fixed: one radius (d^2 < r^2 in float, as pcl::search::KdTree). Adaptive: each point has its radius from its
// 3D range (ClusterParams); two points join when nearer than the larger of their two radii, which is
// symmetric, so the clusters do not depend on the search order. Anisotropic: each point has a horizontal and a
// vertical radius, both growing with range; two points join inside the ellipsoid (dxy / H)^2 + (dz / V)^2 < 1
// with H and V the larger of their horizontal and vertical radii (again symmetric). Structures: KdTree (our k-d
// tree, the published way) or Grid (cells small enough that a cell's points always join: cubes, stacked into taller
// cells far out where the radii allow; union-find over cells, each cell looking back at the cells before it within
// a stencil that covers both sides' radii, so each pair is looked at once, nearest first, and joined by their first
// pair within reach, tested four at a time; column by column, a pair of columns each wholly in the same cluster
// passed over whole). Both find exactly the same clusters.
// Output: every point in exactly one cluster (singletons included); clusters in the order of their lowest
// point index, indices ascending within a cluster. Thread-compatible.

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "fieldguard/perception/beam_geometry.hpp"
#include "fieldguard/perception/cloud.hpp"
#include "fieldguard/perception/kdtree.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

struct Clusters {
  Buffer<std::uint32_t> indices;  // point indices grouped by cluster
  Buffer<std::uint32_t> offsets;  // cluster c is indices[offsets[c], offsets[c + 1])
  [[nodiscard]] std::size_t size() const { return offsets.empty() ? 0 : offsets.size() - 1; }
  [[nodiscard]] std::span<const std::uint32_t> operator[](std::size_t c) const {
    return {indices.data() + offsets[c], offsets[c + 1] - offsets[c]};
  }
};

// Clusters from each point's cluster number (0 .. count - 1, or `none`: the point is in no cluster), each
// cluster's members ascending (a counting sort). `scratch` is reused.
void group_points(std::span<const std::uint32_t> cluster_of_point, std::uint32_t count, std::uint32_t none,
                  Clusters& out, Buffer<std::uint32_t>& scratch);

// Clusters from each point's label (any number below `labels`, or `none`: in no cluster), numbered by first
// appearance in point order: the clusters in the order of each one's lowest point index, members ascending, a
// label no point carries left out. `of_point` is renumbered on the way; `id` and `scratch` are reused.
void group_by_first_point(Buffer<std::uint32_t>& of_point, std::uint32_t labels, std::uint32_t none, Clusters& out,
                          Buffer<std::uint32_t>& id, Buffer<std::uint32_t>& scratch);

// Clusters merged in place: cluster c's points go to cluster target[c] (a cluster that is its own target), then
// the clusters are rebuilt by group_by_first_point (points of a cloud of `points` in no cluster stay in none). The
// three buffers are scratch, reused; `id` is left holding each target's cluster after the merge (merge_bounds).
void merge_clusters(std::span<const std::uint32_t> target, std::size_t points, Clusters& clusters,
                    Buffer<std::uint32_t>& of_point, Buffer<std::uint32_t>& id, Buffer<std::uint32_t>& scratch);

class EuclideanClusterer {
 public:
  // Throws std::invalid_argument for a radius that is not positive, or an adaptive growth of 0.5 m per metre
  // of range or more. The ring spacing: params.beam_spacing_deg when it is set (> 0), else the HDL-32E's until
  // set_beams() gives the sensor's.
  explicit EuclideanClusterer(const ClusterParams& params);

  // The sensor's rings (params.beam_spacing_deg 0: auto): the adaptive radius (anisotropic: the vertical one)
  // grows with the spacing of the rings at each point's elevation (z / 3D range from the frame's origin), at most
  // kMaxGrowth a metre (an RS-32's outermost gaps, 4 to 10 degrees, would give 0.3 to 0.7). Even rings (HDL-32E,
  // VLP-16) keep one growth for every point. The anisotropic horizontal radius keeps the HDL-32E's spacing: the
  // gaps it bridges along a ring are a surface's own (a porous crown's), not the distance between rings.
  void set_beams(const BeamGeometry& beams);
  static constexpr float kMaxGrowth = 0.45F;

  void extract(const Cloud& in, Clusters& out);

  // The clustering radius of a point at 3D range `range_m` (the fixed radius when not adaptive).
  [[nodiscard]] float radius_at(float range_m) const;
  // Anisotropic: the horizontal radius at 3D range `range_m` (radius_at is the vertical one); else radius_at.
  // With uneven rings radius_at takes the largest growth; the overload the point's own (its elevation's sine).
  [[nodiscard]] float horizontal_radius_at(float range_m) const;
  [[nodiscard]] float horizontal_radius_at(float range_m, float sin_elevation) const;
  [[nodiscard]] const ClusterParams& params() const { return params_; }

 private:
  void apply_beams(const BeamGeometry& beams, bool configured);
  void prepare(const Cloud& in);
  void extract_kdtree(const Cloud& in, Clusters& out);
  void extract_grid(const Cloud& in, Clusters& out);
  void finish_cluster(Clusters& out);
  [[nodiscard]] float grown(float growth, float cap, float range_m) const;
  struct RadiusModel;  // the radii, for the hot loops (src/perception/euclidean_cluster_radius.hpp)
  [[nodiscard]] RadiusModel radius_model() const;
  // Inside the ellipsoid of horizontal radius sqrt(h2), vertical sqrt(v2): dxy2 / h2 + dz2 / v2 < 1, without
  // dividing.
  static bool joins_anisotropic(float dxy2, float dz2, float h2, float v2) { return dxy2 * v2 + dz2 * h2 < h2 * v2; }

  ClusterParams params_;
  float base_r2_ = 0.F;    // fixed radius squared, as PCL rounds it
  float growth_ = 0.F;     // adaptive: radius per metre of range
  float cap_ = 0.F;        // adaptive radius cap
  bool adaptive_ = false;  // Adaptive or Anisotropic: r2_ holds each point's (vertical) radius
  bool anisotropic_ = false;
  float growth_h_ = 0.F;  // anisotropic: horizontal radius per metre of range
  float cap_h_ = 0.F;     // anisotropic: horizontal radius cap
  // Uneven rings (set_beams): each point's growths from its elevation; growth_ and growth_h_ are then the largest
  // (what the search bounds take), these the smallest (what a stack of grid cells may rely on).
  bool per_point_ = false;
  BeamGeometry beams_;
  float min_growth_ = 0.F;
  float min_growth_h_ = 0.F;
  [[nodiscard]] float growth_at(float factor, float sin_elevation) const {
    return std::min(kMaxGrowth, factor * beams_.tan_spacing(sin_elevation));
  }

  KdTree tree_;
  // Scratch, reused across frames.
  Buffer<float> r2_;     // per point (adaptive): its radius squared
  Buffer<float> h2_;     // per point (anisotropic): its horizontal radius squared
  Buffer<float> query_;  // per point: the search radius that finds every neighbour
  Buffer<std::uint8_t> done_;
  Buffer<std::uint32_t> queue_;
  Buffer<std::uint32_t> pos_of_;  // cloud index -> position in the structure's order (grid: its cell)
  // Grid (extract_grid), reused across frames.
  Buffer<std::uint32_t> col_start_;   // per x-y column: its first point in grid order
  Buffer<std::uint32_t> z_start_;     // per z cell: its first point in z order
  Buffer<std::uint32_t> cell_of_;     // per point: its x-y column
  Buffer<std::uint32_t> z_of_;        // per point: its z cell
  Buffer<std::uint32_t> by_z_;        // point indices in z order
  Buffer<std::uint32_t> grid_index_;  // grid order -> point index
  Buffer<float> grid_xyz_;            // x, y, z, vertical and horizontal radius squared in grid order, one array each
  Buffer<float> grid_point_;          // x, y, z and 3D range (adaptive) of each point in grid order, side by side
  Buffer<std::uint32_t> grid_z_;      // z cell in grid order
  struct Cell {
    std::uint32_t first;  // its points: grid order [first, next cell's first)
    std::uint32_t col;    // x-y column
    float reach2;         // the largest radius of its points, squared (anisotropic: the vertical one)
    float hreach2;        // the largest horizontal radius of its points, squared (= reach2 unless anisotropic)
  };
  static constexpr std::uint32_t kNoCluster = 0xFFFFFFFFU;
  Buffer<Cell> cells_;
  struct ZSpan {           // per cell, apart: the neighbour scan reads only these, packed
    std::uint32_t iz;      // its lowest z cell
    std::uint32_t iz_top;  // its highest z cell (far out a cell stacks several: see extract_grid)
  };
  Buffer<ZSpan> cell_z_;
  Buffer<float> cell_box_;           // per cell, the box of its points (min x, y, z, -, max x, y, z, range)
  Buffer<std::uint32_t> col_cells_;  // per column: its first cell (cells of a column ascend in z)
  struct Stencil {                   // per cell: the cells it looks at (extract_grid)
    std::uint32_t hreach;            // columns apart on x and on y
    std::uint32_t z_lo, z_hi;        // z cells
  };
  Buffer<Stencil> stencil_;
  Buffer<std::uint32_t> col_rep_;    // per column, once its joins are done: a cell of it if all are in one cluster
  Buffer<std::uint32_t> parent_;     // union-find over cells
  Buffer<std::uint32_t> root_size_;  // per root cell: its cluster's size
  Buffer<std::uint32_t> cluster_of_root_;
  Buffer<std::uint8_t> mark_;  // k-d tree: finish_cluster's bitmap
};

}  // namespace fieldguard::perception
