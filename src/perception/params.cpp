#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

PipelineParams published_params() {
  PipelineParams p;
  p.voxel = VoxelParams{};
  p.voxel.leaf_m = 0.15;
  p.voxel.coarse_from_m = 0.0;
  p.roi = Box3{{-10.0, -10.0, -1.5}, {50.0, 10.0, 6.0}};
  p.body = Box3{{-5.0, -1.5, -1.5}, {0.4, 1.5, 1.5}};
  p.ground.method = GroundMethod::Ransac;
  p.ground.ransac = RansacParams{60, 0.3, 42};
  p.ground.context_m = 0.0;
  p.cluster.method = ClusterMethod::Fixed;
  p.cluster.structure = ClusterStructure::KdTree;
  p.cluster.tolerance_m = 0.6;
  p.cluster.absorb_max_points = 0;
  p.cluster.join_float_height_m = 0.0;
  p.cluster.split_min_length_m = 0.0;
  p.filters.min_points = 10;
  p.filters.max_points = 240;
  p.filters.min_volume_m3 = 0.06;
  p.filters.max_volume_m3 = 1.2;
  p.filters.min_height_m = 0.0;
  p.filters.min_points_full_range_m = 0.0;
  p.filters.canopy_max_height_m = 0.0;
  // The published method had no 2D LiDAR: 2D points of a merged frame are left out of it entirely.
  p.near_field.enabled = false;
  // Nor did it hold anything from one rotation to the next.
  p.hold.enabled = false;
  return p;
}

}  // namespace fieldguard::perception
