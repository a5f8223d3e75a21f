#pragma once
// Parameters of the obstacle-detection pipeline: plain values, filled by the app's config loader.
// Units are in the names. Defaults are config/fieldguard.yaml's; config/published.yaml holds the
// published method's values (and switches every addition of ours off).

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace fieldguard::perception {

struct Box3 {
  std::array<double, 3> min{};  // m
  std::array<double, 3> max{};  // m
  [[nodiscard]] bool contains(const Box3& inner) const {
    for (std::size_t i = 0; i < 3; ++i) {
      if (inner.min[i] < min[i] || inner.max[i] > max[i]) return false;
    }
    return true;
  }
};

struct VoxelParams {
  double leaf_m = 0.15;  // edge of a voxel; each occupied voxel becomes the centroid of its points
  // Coarser leaf with range: 0 = off (one leaf everywhere). Otherwise a point at horizontal range r uses the
  // leaf leaf_m * max(1, floor(r / coarse_from_m)), capped at max_leaf_m (bands of whole multiples, so every
  // band is one regular grid).
  double coarse_from_m = 0.0;
  double max_leaf_m = 0.45;
};

// Ground segmentation. Ransac: the published method, one plane for the whole frame. Zones: local planes on
// a polar grid of concentric zones (after Patchwork++'s concentric zone model), for fields that are not one
// plane: slopes, furrows, ridges, the tractor's roll and pitch.
enum class GroundMethod : std::uint8_t { Ransac = 0, Zones = 1 };

struct RansacParams {
  int iterations = 60;      // maximum plane hypotheses; stops earlier at 99 % confidence, as PCL's RANSAC does
  double distance_m = 0.3;  // inlier distance from the plane
  std::uint32_t seed = 42;  // fixed, so replay output is reproducible
};

struct ZoneParams {
  // Concentric zones by horizontal range from the sensor: zone i spans [edges_m[i], edges_m[i+1]) and is cut
  // into rings[i] rings of equal width and sectors[i] sectors of equal angle. Points nearer than the first
  // edge belong to the first ring, points beyond the last edge to the last ring.
  std::vector<double> edges_m{2.0, 6.0, 14.0, 26.0, 50.0};
  std::vector<int> rings{2, 4, 4, 4};
  std::vector<int> sectors{16, 32, 48, 64};
  int min_bin_points = 4;             // a bin with fewer points takes the ground of the bin inside it
  int seed_lowest = 10;               // seeds: the mean of this many lowest points ...
  double seed_margin_m = 0.15;        // ... plus this margin; heights measured along the inner bin's slope
  double fit_distance_m = 0.15;       // refit: points nearer than this to the plane
  int fit_iterations = 3;             // plane refits
  double ground_threshold_m = 0.2;    // a point less than this above its local ground plane is ground
  double max_slope_deg = 25.0;        // a bin plane steeper than this is not ground
  double max_tilt_deg = 10.0;         // innermost ring: allowed tilt of the ground (vehicle roll and pitch)
  double max_step_m = 0.25;           // a bin's ground may differ this much from the inner bin's plane continued ...
  double max_slope_change_deg = 5.0;  // ... plus the rise of this slope change over the distance between them
  double min_spread_m = 0.8;          // a bin's ground points must spread at least this far (m, bbox diagonal)
  // Ground farther than this from any bin fitted to its own points is a guess (no ring reached it): a cluster
  // standing only on such ground counts its own vertical extent as its height above ground.
  double max_extrapolation_m = 20.0;
  // A point's ground: its bin's plane interpolated, by distance from the point to where each was fitted, with
  // the plane of the bin beyond it on its side (outside it or inside it) when that was fitted to points of its
  // own. Far out a bin's plane is fitted to one ring's arc of returns and carried to the bin's edge; the next
  // ring out, metres away, is where the ground there was measured: without this a ring's slice of a ridge at
  // a bin's outer edge stands tenths of a metre above a plane that the bin beyond contradicts.
  bool blend_radial = true;
  // The ground is the lower envelope of its bin's returns: a bin with a return of its own more than this below its
  // fitted plane keeps the plane continued from inside (m; 0 = off). Behind a tree row only the near-horizontal
  // lasers reach the next row's crowns; a plane fitted to their returns has a lower laser's crown return under it.
  double max_below_m = 0.3;
  double sensor_height_m = 0.95;  // the LiDAR above flat ground; the loader copies lidar.mounting.z_m
};

struct GroundParams {
  GroundMethod method = GroundMethod::Zones;
  RansacParams ransac;
  ZoneParams zones;
  // The ground stage also sees the points up to this far beyond the region of interest's far end (+x, m); they
  // are never clustered. Far out only one or two rings reach the ground, and the ground at the ROI's edge is
  // measured by the returns just beyond it: cut there, a ring's slice of a clod at the edge stands above a
  // plane carried on from metres nearer.
  double context_m = 15.0;
};

// Euclidean clustering. Fixed: one radius. Adaptive: the radius grows with range so that a sensor's rings,
// which drift apart with distance, still join: radius(r) = min(max_tolerance_m, max(tolerance_m,
// beam_factor * r * tan(beam_spacing_deg))) at 3D range r; two points join when nearer than the larger of
// their radii. Structure: KdTree (as PCL's EuclideanClusterExtraction) or Grid (cells of the radius); both
// give the same clusters.
// Anisotropic: two radii per point, both adaptive with range: a vertical one (the adaptive radius above: rings
// are stacked vertically, their gap grows with range) and a horizontal one (horizontal_beam_factor,
// horizontal_max_tolerance_m; same floor tolerance_m); two points join when (dxy / H)^2 + (dz / V)^2 < 1 with H
// and V the larger of their two horizontal and vertical radii. The ring slices of a porous crown far out join
// while two crowns side by side a few tenths of a metre apart stay two.
enum class ClusterMethod : std::uint8_t { Fixed = 0, Adaptive = 1, Anisotropic = 2 };
enum class ClusterStructure : std::uint8_t { KdTree = 0, Grid = 1 };

struct ClusterParams {
  ClusterMethod method = ClusterMethod::Anisotropic;
  ClusterStructure structure = ClusterStructure::Grid;
  double tolerance_m = 0.4;  // Euclidean clustering radius (fixed), smallest radius (adaptive, anisotropic)
  // Vertical angle between adjacent rings (degrees): 0 = auto, the sensor's own rings at each point's elevation
  // (beam_geometry.hpp; the HDL-32E's 1.33 until the sensor is known); above 0, that one for every sensor.
  double beam_spacing_deg = 0.0;
  double beam_factor = 4.0;                 // adaptive (anisotropic: vertical) radius as a multiple of the ring gap
  double max_tolerance_m = 3.0;             // adaptive (anisotropic: vertical) radius cap
  double horizontal_beam_factor = 1.7;      // anisotropic: horizontal radius as beam_factor is for the vertical
  double horizontal_max_tolerance_m = 1.5;  // anisotropic: horizontal radius cap
  // After clustering (cluster_absorb.hpp): a cluster of at most absorb_max_points points whose box lies inside a
  // bigger cluster's box grown by absorb_margin_m joins it. 0 = off.
  int absorb_max_points = 10;
  double absorb_margin_m = 0.3;
  // Then (cluster_join.hpp): a cluster whose lowest point is at least join_float_height_m above its ground
  // floats; floating fragments (fewer points than join_fragment_factor times the filters' minimum) join each other
  // within join_fragment_gap_m and then their one nearest bigger cluster within join_gap_m (x-y boxes); with
  // join_stacked a floating cluster joins every cluster whose x-y box is within join_stack_margin_m of its own on
  // each axis. join_float_height_m 0 = off.
  double join_float_height_m = 0.8;
  double join_fragment_factor = 1.5;
  double join_fragment_gap_m = 1.0;
  double join_gap_m = 0.6;
  bool join_stacked = true;
  double join_stack_margin_m = 0.4;
  // Last (cluster_split.hpp): a cluster at least split_min_length_m long along its long x-y axis is cut in two at the
  // widest empty slot across it that is at least split_gap_ratio times the horizontal radius there, when each part is
  // at least split_min_part_m long with split_min_part_points points (falling as (split_full_range_m / r)^2 beyond
  // split_full_range_m): two crowns side by side. split_min_length_m 0 = off.
  double split_min_length_m = 2.0;
  double split_min_part_m = 0.5;
  double split_gap_ratio = 0.6;
  int split_min_part_points = 40;
  double split_full_range_m = 10.0;
};

struct FilterParams {
  int min_points = 6;
  int max_points = 0;  // 0 = no upper limit
  double min_volume_m3 = 0.0;
  double max_volume_m3 = 0.0;  // 0 = no upper limit
  double min_height_m = 0.5;   // highest point above the local ground; 0 = off
  // Far out a ring's slice of a clod is a few returns whose height rests on ground measured by one or two rings:
  // beyond min_height_growth_from_m the least height grows by min_height_growth_per_m per metre, up to
  // min_height_growth_max_m (0 = no cap; a person, 1.4 m and more, should stay above it). from 0 = off.
  double min_height_growth_from_m = 25.0;
  double min_height_growth_per_m = 0.03;
  double min_height_growth_max_m = 0.75;
  // Far objects get few returns: beyond this distance the minimum point count falls as
  // min_points * (min_points_full_range_m / d)^2, never below min_points_floor. 0 = off.
  double min_points_full_range_m = 12.0;
  int min_points_floor = 2;
  // A cluster whose lowest point is at least float_min_height_m above its ground (a crown seen through gaps: crop,
  // terrain and people never float) needs no more than float_min_points points. 0 = off.
  double float_min_height_m = 1.0;
  int float_min_points = 3;
  // Crop canopy (canopy.hpp): a cluster no higher than canopy_max_height_m above its ground whose ring jitter
  // is at least canopy_min_jitter_m, over at least canopy_min_triples triples of ring neighbours no farther
  // apart than canopy_max_gap_m, is porous: a crop or low foliage, not an obstacle. Anything standing higher
  // (a person in the crop: 1.75 m) keeps the whole cluster. canopy_max_height_m 0 = off.
  double canopy_max_height_m = 0.9;
  double canopy_min_jitter_m = 0.12;
  int canopy_min_triples = 16;
  double canopy_max_gap_m = 0.5;
  // ... or (with any number of triples) reaches at least canopy_needle_depth_m along the rays and at least
  // canopy_needle_ratio times as deep as it is wide across them: a ray's returns inside a canopy. 0 = off.
  double canopy_needle_depth_m = 0.35;
  double canopy_needle_ratio = 3.0;
  // ... or (canopy_surroundings_m > 0, and with too few triples of its own) measured together with the low returns
  // within canopy_surroundings_m of its x-y box (ground-labelled, or lower than min_height_m above their ground):
  // a ring slice of a crop canopy's top, sitting in the canopy (canopy.hpp, LowSurroundings). 0 = off.
  double canopy_surroundings_m = 3.0;
};

// The 2D LiDAR's near field (near_field.hpp): the scan points of a merged frame become obstacles of their own,
// because a low box in the 3D LiDAR's blind zone in front of the tractor gives the 3D path nothing.
struct NearFieldParams {
  bool enabled = true;  // acts only on frames that carry 2D points
  // Where 2D points count, in the 3D LiDAR's levelled frame (m). x from the tractor's front (body max x):
  // behind it the scan's outer rays, swinging back past +-90 deg, hit the tractor's own wheels and weights.
  // x to 12 m: the stop zone at 20 km/h (2.8 m reaction, 5.2 m braking on friction 0.3, 1 m margin) fits,
  // and farther out a residual pitch of 1 deg moves the scan plane 0.2 m, most of its height above ground.
  // |y| 4 m: the stop zone's half width (2 m) and as much again for turns. z -3 .. 1 m: the ground lies near
  // -sensor_height (0.95 .. 1.8 m); room for ditches below and rising ground above.
  Box3 zone{{0.4, -4.0, -3.0}, {12.0, 4.0, 1.0}};
  // Consecutive scan points nearer than this are one segment. At 0.25 deg a step, rays are 4 cm apart at
  // 10 m, a surface seen at 10 deg grazing spreads them to 0.25 m; two objects less than this apart are one.
  double max_gap_m = 0.3;
  // A segment needs this many points standing min_height_m above the ground: dust, rain and a single crop
  // stalk give one or two; a 0.1 m post at 12 m still gives 2 (0.48 deg), a leg at 8 m 3-4.
  int min_points = 3;
  // A scan point less than this above the local ground is ground (ground hits when the nose pitches down,
  // clods, furrows) and is left out. The scan plane runs 0.3-0.45 m above flat ground, so what it hits stands
  // that high: half of it leaves room for clods (< 0.1 m) plus the ground estimate's error below, and for a
  // pitch error of 1.5 deg at 6 m above. Ploughed ridges (0.2-0.3 m over the furrows the ground plane
  // follows) need more: raise it to 0.25 there.
  double min_height_m = 0.15;
};

// Holding a recent obstacle's place (obstacle_hold.hpp): where an obstacle was reported by the filters within the
// last max_age_s and nothing is reported this frame, the frame's fragments there (groups of raised returns too
// few for the filters, fragments below) are reported together as the obstacle, when they hold min_points
// points. A tree crown seen through the gaps of a nearer row shows three to five returns more than a metre
// apart in one rotation and a full cluster in the next; a person behind a post likewise. Nothing is held
// without returns of this frame, and a held obstacle holds nothing itself: an obstacle last seen by the filters
// more than max_age_s ago is let go.
struct HoldParams {
  bool enabled = true;
  // From the last full detection. 0.35 s: three rotations at 10 Hz, one at 5 Hz (with its jitter).
  double max_age_s = 0.35;
  // Fragments count when their box comes this near the held box (m). The held box is where the obstacle was
  // in the sensor frame: the tractor's travel over max_age_s must fit in it (0.3 m: 0.85 m/s at 0.35 s, the
  // orchard's crawl), unless its speed is known (ObstacleHold::apply), which widens it along x by the travel.
  double gate_m = 0.3;
  // Points the fragments within the gate must hold together: the filters' own least far out (min_points_floor).
  int min_points = 2;
};

struct PipelineParams {
  VoxelParams voxel;
  Box3 roi{{-10.0, -10.0, -6.0}, {52.0, 10.0, 6.0}};
  Box3 body{{-5.0, -1.5, -1.5}, {0.4, 1.5, 1.5}};
  GroundParams ground;
  ClusterParams cluster;
  FilterParams filters;
  NearFieldParams near_field;
  HoldParams hold;
};

// The published pipeline's parameters (config/published.yaml): for tests and benchmarks.
[[nodiscard]] PipelineParams published_params();

}  // namespace fieldguard::perception
