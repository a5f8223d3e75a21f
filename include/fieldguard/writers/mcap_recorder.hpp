#pragma once
// Processed frames into an MCAP file on one timeline (each message's log time is its frame's time), on the
// channels a Foxglove or Lichtblick layout subscribes to:
//   /lidar/points          foxglove.PointCloud    the frame's points as measured (intensity, ring, source)
//   /detection/points      foxglove.PointCloud    what detection made of them (label, obstacle index)
//   /detection/obstacles   foxglove.SceneUpdate   the obstacle boxes with their distances
//   /detection/zones       foxglove.SceneUpdate   the stop zone (coloured by the decision), ROI and body box
//   /safety/decision       fieldguard.Decision    stop or go, the reasons, the headline
//   /tf                    foxglove.FrameTransform field -> lidar, for a fused frame levelled in full
//   /gnss/fix              foxglove.LocationFix   that frame's reference point in WGS84
// Thread-compatible: the thread that delivers frames in order writes them.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fieldguard/config/config.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/geo/projection.hpp"
#include "fieldguard/output/safety_monitor.hpp"
#include "fieldguard/writers/mcap_writer.hpp"

namespace fieldguard::app {

class McapRecorder {
 public:
  explicit McapRecorder(const Config& cfg);

  // Opens the file and writes the schemas and channels. False with error() set when it cannot.
  bool open(const std::string& path, const McapOptions& options);
  // One frame: `points` are the labelled points detection worked on (empty when detection did not run),
  // `decision` the safety monitor's for this frame (none when nothing decided). False with error() set when
  // the file cannot be written.
  bool frame(const LidarFrame& frame, const perception::FrameResult& result,
             std::span<const perception::LabeledPoint> points, const FusionInfo* fusion,
             const output::safety::Decision* decision);
  bool close();

  [[nodiscard]] const std::string& error() const { return writer_.error(); }
  [[nodiscard]] const McapStats& stats() const { return writer_.stats(); }

 private:
  bool put(std::uint16_t channel, std::int64_t stamp_ns);

  const Config& cfg_;
  McapWriter writer_;
  geo::GaussKrueger projection_;
  std::string message_;                    // scratch: one message's JSON
  std::vector<std::uint16_t> schema_ids_;  // by foxglove::schemas() index; 0 until written
  struct Channels {
    std::uint16_t raw = 0;
    std::uint16_t labelled = 0;
    std::uint16_t obstacles = 0;
    std::uint16_t zones = 0;
    std::uint16_t decision = 0;
    std::uint16_t tf = 0;
    std::uint16_t fix = 0;
  } ch_;
  std::optional<std::array<double, 3>> origin_;  // of the "field" frame: the first full pose, whole metres
};

}  // namespace fieldguard::app
