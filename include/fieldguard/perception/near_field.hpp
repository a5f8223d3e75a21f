#pragma once
// The 2D LiDAR's near field: obstacles from the scan of a merged frame. The 3D LiDAR, mounted high, reaches
// the ground only metres ahead of the bumper, and whatever it sees there is a few points of a low object
// that its height and point filters drop; the 2D LiDAR's near-horizontal scan, 0.3-0.45 m above the ground
// on the bumper, cuts every such object as a line of points.
//
// The scan's points inside the near zone that stand at least min_height_m above the local ground (the
// 3D ground segmentation's surface of the same frame, `ground_z`) are taken in scan-step order; consecutive
// ones nearer than max_gap_m form a segment, and a segment of at least min_points points is an obstacle.
// Points below min_height_m are ground (the scan plane meets the ground a few metres ahead when the nose
// pitches down; clods, furrows): they neither count nor join segments, so a ground-hit line with a speck of
// dust over it stays ground and an obstacle's box does not stretch over the ground hits beside it.
// In the near zone the 3D LiDAR's rings mostly do not reach the ground, so `ground_z` there is the innermost
// bins' plane continued towards the sensor (zone ground) or the frame's one plane (RANSAC): the vehicle's
// roll and pitch are in it, local bumps nearer than the first ring are not.
//
// The box: x and y from the points, z from the local ground under them up to the highest point. Its height
// is a lower bound: the scan sees one slice of the object. Thread-compatible: holds scratch buffers.

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/perception/obstacle.hpp"
#include "fieldguard/perception/obstacle_box.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

class NearField {
 public:
  // The local ground height (m) under (x, y) in the frame the points are in.
  using GroundFn = std::function<float(float x, float y)>;

  struct Counts {
    std::uint32_t in_zone = 0;    // finite points inside the zone
    std::uint32_t obstacles = 0;  // obstacles appended
  };

  // Throws std::invalid_argument for parameters no stage can run with (zone min >= max on an axis, a gap or
  // point count that is not positive, a negative height): the loader reports those to the user first.
  explicit NearField(const NearFieldParams& params);

  // Appends one obstacle per segment of `scan` (2D points of one scan, in step order: `ring` is the step)
  // to `out`, with sources kSeenBy2d. Points with a non-finite coordinate are dropped (counted out of the
  // zone); a step that does not follow the previous one's (a second scan, reordered data) starts a segment.
  Counts detect(std::span<const LidarPoint> scan, const GroundFn& ground_z, std::vector<Obstacle>& out);

  // Merges each near obstacle out[first_near ..] whose footprint (axis-aligned, x-y) comes nearer than
  // tolerance_m to a 3D obstacle's out[.. first_near) into the nearest such one (ties: the first), as the
  // Euclidean clustering would have joined their points: box and point count extended, distance, bearing,
  // height and oriented box (around both oriented boxes) recomputed, sources ORed. Merged near obstacles are
  // removed; the others keep their order. Returns how many were merged.
  std::uint32_t fuse(std::vector<Obstacle>& out, std::size_t first_near, float tolerance_m);

  [[nodiscard]] const NearFieldParams& params() const { return params_; }

 private:
  struct Point {
    float x, y, z, ground;
  };
  void emit(std::vector<Obstacle>& out);

  NearFieldParams params_;
  std::vector<Point> segment_;
  std::vector<std::array<float, 2>> footprint_, hull_;
  HullScratch hull_scratch_;
};

}  // namespace fieldguard::perception
