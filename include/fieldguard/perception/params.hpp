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
    for (std::size_t i = 0; i < 3; ++i) {
      if (inner.min[i] < min[i] || inner.max[i] > max[i]) return false;
    }
    return true;
  }
};

struct VoxelParams {
  double leaf_m = 0.15;  // edge of a voxel; each occupied voxel becomes the centroid of its points
};

// Ground segmentation. The published method is one RANSAC plane; the issue that builds the detection
// pipeline adds a method for fields that are not one plane.
enum class GroundMethod : std::uint8_t { Ransac };

struct RansacParams {
  int iterations = 60;
  double distance_m = 0.3;  // inlier distance from the plane
  std::uint32_t seed = 42;  // fixed, so replay output is reproducible
};

struct GroundParams {
  GroundMethod method = GroundMethod::Ransac;
  RansacParams ransac;
};

struct ClusterParams {
  double tolerance_m = 0.6;  // Euclidean clustering radius
};

struct FilterParams {
  int min_points = 10;
  int max_points = 240;
  double min_volume_m3 = 0.06;
  double max_volume_m3 = 1.2;
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
