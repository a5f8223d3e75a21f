#pragma once
// What the detection pipeline reports: one obstacle per kept cluster, in the 3D LiDAR's sensor frame
// (x forward, y left, z up, metres).

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

namespace fieldguard::perception {

// Which sensors saw an obstacle (Obstacle::sources, a bit mask): the 3D LiDAR's clusters, the 2D LiDAR's
// near-field segments (near_field.hpp), or both when a segment was merged into a cluster.
inline constexpr std::uint8_t kSeenBy3d = 1U;  // bit 0
inline constexpr std::uint8_t kSeenBy2d = 2U;  // bit 1

// small: person-sized (fits in 1.2 m x 1.2 m x 2.2 m); large: implement, haystack, building, tree.
enum class SizeClass : std::uint8_t { Small = 0, Large = 1 };
[[nodiscard]] std::string_view to_string(SizeClass c);

struct Obstacle {
  std::array<float, 3> min{};  // axis-aligned box (m)
  std::array<float, 3> max{};
  // Oriented box in x-y (minimum-area rectangle of the cluster's footprint), z from the axis-aligned box.
  std::array<float, 2> obb_center{};  // (m)
  float obb_length_m = 0.F;           // along obb_yaw
  float obb_width_m = 0.F;
  float obb_yaw_rad = 0.F;            // of the length axis from x, counter-clockwise, in (-pi/2, pi/2]
  std::uint32_t points = 0;           // points in the cluster (after voxel downsampling)
  float distance_m = 0.F;             // horizontal distance from the sensor to the nearest point of the cluster
  float bearing_deg = 0.F;            // atan2(y, x) of the box centre, degrees, + to the left
  float height_above_ground_m = 0.F;  // highest point above the local ground under the cluster
  SizeClass size_class = SizeClass::Small;
  std::uint8_t sources = kSeenBy3d;  // kSeenBy3d | kSeenBy2d: which sensors' points it holds
  // Reported by ObstacleHold (obstacle_hold.hpp) from this frame's fragments where an obstacle was reported
  // lately, not by the filters: its boxes are the fragments' (axis-aligned; the oriented box is the same).
  bool held = false;
};

// A group of returns the filters found too few for its distance, but standing high enough above its ground to
// count (min_height_at); its ground measured, not guessed. Not an obstacle on its own: ObstacleHold's evidence.
struct Fragment {
  std::array<float, 3> min{};  // axis-aligned box (m)
  std::array<float, 3> max{};
  std::uint32_t points = 0;
  float distance_m = 0.F;             // as Obstacle's
  float height_above_ground_m = 0.F;  // its highest point's
};

// Points of the processed frame with what the pipeline made of them, for pictures and debugging.
enum class PointLabel : std::uint8_t {
  Ground = 0,
  Obstacle = 1,
  Rejected = 2 /* clustered, filtered out */,
  Unclustered = 3
};
struct LabeledPoint {
  float x = 0.F;
  float y = 0.F;
  float z = 0.F;
  PointLabel label = PointLabel::Unclustered;
};

// How many points each stage kept, for the summary, the benchmarks and the status.
struct StageCounts {
  std::uint32_t input = 0;
  std::uint32_t after_roi = 0;  // inside the ROI and outside the body box
  std::uint32_t after_voxel = 0;
  std::uint32_t ground = 0;
  std::uint32_t clusters = 0;   // before the filters
  std::uint32_t obstacles = 0;  // after the filters
  // The 2D LiDAR's near-field path (near_field.hpp); none of its points is counted above. Obstacles
  // reported = obstacles + near_obstacles - near_merged + held.
  std::uint32_t near_input = 0;      // 2D LiDAR points in the frame
  std::uint32_t near_in_zone = 0;    // of them, finite and inside the near zone
  std::uint32_t near_obstacles = 0;  // segments kept as obstacles
  std::uint32_t near_merged = 0;     // of them, merged into a 3D obstacle they overlap
  // ObstacleHold's, after process() (obstacle_hold.hpp): obstacles reported from fragments.
  std::uint32_t held = 0;
  std::uint32_t fragments = 0;  // fragments of the frame (FrameResult::fragments)
};

// How long each stage took on this frame (steady clock, microseconds), measured inside process(): in the
// pipeline's own context, after the frame was decoded and the last frame processed. A stage benchmark that
// repeats one stage on one frame runs it with warm caches and a branch predictor that has learned the frame,
// and can flatter it: on the shed 5 Hz rotation the voxel grid takes 0.45 ms so and 0.55 ms here, and the
// crop took 0.12 ms so and 0.24-0.35 ms here until it prefetched (BM_PacketsToObstacles prints these).
struct StageTimes {
  float crop_us = 0.F;     // ROI and body box
  float voxel_us = 0.F;    // voxel grid
  float ground_us = 0.F;   // ground segmentation, and the split of the voxels into ground and the rest
  float cluster_us = 0.F;  // Euclidean clustering
  float merge_us = 0.F;    // cluster summaries, absorption, joins and splits
  float boxes_us = 0.F;    // the filters, and each kept cluster's boxes
  float near_us = 0.F;     // the 2D LiDAR's near field, and the sort of the obstacles
  float total_us = 0.F;    // all of process()
};

// Sorts by distance_m, nearest first; ties by bearing_deg, then by the box's min corner (deterministic).
void sort_obstacles(std::vector<Obstacle>& obstacles);

struct FrameResult {
  std::vector<Obstacle> obstacles;  // sorted by distance_m, nearest first; ties by bearing (sort_obstacles)
  std::vector<Fragment> fragments;  // when HoldParams::enabled; in cluster order
  StageCounts counts;
  StageTimes times;
};

}  // namespace fieldguard::perception
