#pragma once
// A processed frame as the Foxglove messages of its channels (foxglove_json.hpp), for every output that shows
// frames: the MCAP recording (mcap_recorder.hpp) and the daemon's live view. One list of channels, so a
// recording and a live connection carry the same topics:
//   /lidar/points          foxglove.PointCloud     the frame's points as measured (intensity, ring, source)
//   /detection/points      foxglove.PointCloud     what detection made of them (label, obstacle index)
//   /detection/obstacles   foxglove.SceneUpdate    the obstacle boxes with their distances
//   /detection/zones       foxglove.SceneUpdate    the stop zone (coloured by the decision), ROI and body box
//   /safety/decision       fieldguard.Decision     stop or go, the reasons, the headline
//   /tf                    foxglove.FrameTransform field -> lidar, for a fused frame levelled in full
//   /gnss/fix              foxglove.LocationFix    that frame's reference point in WGS84
//   /health                fieldguard.Health       each sensor's state and rate, the status line (the daemon's, once a
//                                                  second and on a change of decision; encode() writes none)
// Thread-compatible.

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "fieldguard/config/config.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/geo/projection.hpp"
#include "fieldguard/output/safety_monitor.hpp"

namespace fieldguard::app {

struct FrameChannel {
  std::string_view topic;
  std::string_view schema;  // a name of foxglove::schemas()
};
enum class Topic : std::uint8_t { RawPoints, LabelledPoints, Obstacles, Zones, Decision, Transform, Fix, Health };
inline constexpr std::array<FrameChannel, 8> kFrameChannels = {{
    {"/lidar/points", "foxglove.PointCloud"},
    {"/detection/points", "foxglove.PointCloud"},
    {"/detection/obstacles", "foxglove.SceneUpdate"},
    {"/detection/zones", "foxglove.SceneUpdate"},
    {"/safety/decision", "fieldguard.Decision"},
    {"/tf", "foxglove.FrameTransform"},
    {"/gnss/fix", "foxglove.LocationFix"},
    {"/health", "fieldguard.Health"},
}};

class FrameEncoder {
 public:
  explicit FrameEncoder(const Config& cfg);

  // Each message of one frame, in kFrameChannels' order, to `emit` (valid during the call only): `points` are
  // the labelled points detection worked on (empty when it did not run), `decision` the safety monitor's for
  // this frame (none when nothing decided it). Each message's time is the frame's.
  using Emit = std::function<void(Topic, std::int64_t stamp_ns, std::string_view json)>;
  void encode(const LidarFrame& frame, const perception::FrameResult& result,
              std::span<const perception::LabeledPoint> points, const FusionInfo* fusion,
              const output::safety::Decision* decision, const Emit& emit);

 private:
  const Config& cfg_;
  geo::GaussKrueger projection_;
  std::string message_;                          // scratch: one message's JSON
  std::optional<std::array<double, 3>> origin_;  // of the "field" frame: the first full pose, whole metres
};

}  // namespace fieldguard::app
