#pragma once
// The obstacles' footprints on the ground as GeoJSON (RFC 7946) for `replay --geojson-out`: a FeatureCollection
// with one Polygon per obstacle of each fused frame levelled in full (position and attitude known), its oriented
// box's footprint turned from the plane of the configured Gauss-Krueger projection back into WGS84 longitude and
// latitude (GeographicLib's reverse). A frame without a full pose has no place on the earth and gives no feature
// (counted). The projection the plane coordinates were in is named in the collection's "fieldguard" member.
// Thread-compatible: one thread writes one file.

#include <cstdint>
#include <cstdio>
#include <string>

#include "fieldguard/core/mounting.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/geo/projection.hpp"
#include "fieldguard/perception/obstacle.hpp"

namespace fieldguard::app {

// "Gauss-Krueger, CGCS2000, 3-degree zones, central meridian of each fix's zone, no zone prefix"
[[nodiscard]] std::string describe(const geo::ProjectionParams& p);

struct GeoJsonCounts {
  std::uint64_t features = 0;
  std::uint64_t frames_placed = 0;    // frames with a full pose
  std::uint64_t frames_unplaced = 0;  // frames without one: their obstacles are not in the file
};

class GeoJsonWriter {
 public:
  GeoJsonWriter(const geo::ProjectionParams& projection, const Mounting& lidar);
  ~GeoJsonWriter();
  GeoJsonWriter(const GeoJsonWriter&) = delete;
  GeoJsonWriter& operator=(const GeoJsonWriter&) = delete;

  // False with error() set when the file cannot be created.
  bool open(const std::string& path);
  // One frame's obstacles. False with error() set when the file cannot be written.
  bool frame(const LidarFrame& frame, const perception::FrameResult& result, const FusionInfo* fusion);
  // The collection's end. False with error() set when the file could not be written.
  bool close();

  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] const GeoJsonCounts& counts() const { return counts_; }

 private:
  geo::GaussKrueger projection_;
  Mounting lidar_;
  std::FILE* file_ = nullptr;
  std::string path_;
  std::string error_;
  GeoJsonCounts counts_;
  std::string buf_;
};

}  // namespace fieldguard::app
