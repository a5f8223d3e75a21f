#pragma once
// One LiDAR rotation in, obstacles out: ROI and body removal, voxel grid, ground segmentation, Euclidean
// clustering, cluster filters, obstacle boxes; the 2D LiDAR's points of a merged frame (LidarPoint::source)
// go to the near-field stage instead (near_field.hpp), whose obstacles are merged with the 3D ones. Value
// types only: no sockets, no config parsing, no logging.
// Thread-compatible: a Pipeline holds scratch buffers, so each worker thread owns one; the output depends
// only on the input points and the parameters (deterministic, whatever thread runs it).

#include <memory>
#include <span>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/perception/beam_geometry.hpp"
#include "fieldguard/perception/obstacle.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

class Pipeline {
 public:
  // Throws std::invalid_argument for parameters no pipeline can run with (the config loader has already
  // reported anything a user could get wrong, so this is a programming error).
  explicit Pipeline(const PipelineParams& params);
  ~Pipeline();
  Pipeline(Pipeline&&) noexcept;
  Pipeline& operator=(Pipeline&&) noexcept;

  [[nodiscard]] FrameResult process(std::span<const LidarPoint> points);
  // The same into `result`, over an earlier frame's result whose vectors keep their room: once warm, a frame
  // allocates nothing.
  void process(std::span<const LidarPoint> points, FrameResult& result);

  // The 3D points of the last processed frame after ROI and voxel grid, labelled (no 2D point); valid until
  // the next process().
  [[nodiscard]] std::span<const LabeledPoint> last_points() const;

  // The local ground height (m, sensor frame) under (x, y) as the last processed frame found it: the RANSAC
  // plane, or the plane of the zone bin (x, y) falls in. The level plane at -sensor_height before any frame.
  [[nodiscard]] float ground_z(float x, float y) const;

  [[nodiscard]] const PipelineParams& params() const;

  // The sensor's rings, for the rules whose scale is the gap between them (the clustering radii, the canopy's
  // ring neighbours): taken when perception.cluster.beam_spacing_deg is auto (0), ignored when it fixes one.
  // Until then the HDL-32E's (1.33 degrees). Returns whether it is in force.
  bool set_beams(const BeamGeometry& beams);
  // The ring geometry in force.
  [[nodiscard]] const BeamGeometry& beams() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldguard::perception
