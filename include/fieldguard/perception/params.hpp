#pragma once
// Parameters of the obstacle-detection pipeline: plain values, filled by the app's config loader.
// Units are in the names. Defaults are config/fieldguard.yaml's; config/published.yaml holds the
// published method's values.

#include <array>
#include <cstdint>

namespace fieldguard::perception {

struct Box3 {
  std::array<double, 3> min{};  // m
  std::array<double, 3> max{};  // m
  [[nodiscard]] bool contains(const Box3& inner) const {
    for (int i = 0; i < 3; ++i) {
      if (inner.min[static_cast<std::size_t>(i)] < min[static_cast<std::size_t>(i)] ||
          inner.max[static_cast<std::size_t>(i)] > max[static_cast<std::size_t>(i)]) {
        return false;
      }
    }
    return true;
  }
};

struct VoxelParams {
  double leaf_m = 0.15;             // edge of a voxel near the sensor
  double range_growth_per_m = 0.0;  // leaf grows by this much per metre of range (0 = fixed leaf)
  double max_leaf_m = 0.15;         // cap for the growing leaf
};

enum class GroundMethod : std::uint8_t { Ransac, ZoneGrid };

struct RansacParams {
  int iterations = 60;
  double distance_m = 0.3;          // inlier distance from the plane
  std::uint32_t seed = 42;          // fixed, so replay output is reproducible
};

struct ZoneGridParams {
  int rings = 4;                    // concentric zones
  double max_slope_deg = 15.0;      // a local plane steeper than this is not ground
  double distance_m = 0.15;         // inlier distance from a local plane
};

struct GroundParams {
  GroundMethod method = GroundMethod::Ransac;
  RansacParams ransac;
  ZoneGridParams zone_grid;
};

enum class ClusterRadius : std::uint8_t { Fixed, Adaptive };

struct ClusterParams {
  ClusterRadius radius = ClusterRadius::Fixed;
  double tolerance_m = 0.6;            // fixed radius, and the adaptive radius's lower bound
  double beam_spacing_deg = 1.33;      // vertical spacing of adjacent rings, for the adaptive radius
  double adaptive_factor = 1.5;        // radius = max(tolerance, factor * range * tan(spacing))
  double max_tolerance_m = 2.0;        // upper bound of the adaptive radius
};

struct FilterParams {
  int min_points = 10;
  int max_points = 240;
  double min_volume_m3 = 0.06;
  double max_volume_m3 = 1.2;
  double min_height_above_ground_m = 0.0;  // 0 = off (published); 0.5 in our default
  double min_points_at_10m = 0.0;          // distance-scaled minimum: min(min_points, this * (10/d)^2); 0 = off
};

struct PipelineParams {
  VoxelParams voxel;
  Box3 roi{{-10.0, -10.0, -1.5}, {50.0, 10.0, 6.0}};
  Box3 body{{-5.0, -1.5, -1.5}, {0.4, 1.5, 1.5}};
  GroundParams ground;
  ClusterParams cluster;
  FilterParams filters;
};

}  // namespace fieldguard::perception
