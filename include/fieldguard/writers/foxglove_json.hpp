#pragma once
// A processed frame as Foxglove messages, JSON-encoded (MCAP message encoding "json", schema encoding
// "jsonschema"): the shapes of Foxglove's well-known schemas (foxglove.PointCloud, foxglove.SceneUpdate,
// foxglove.FrameTransform, foxglove.LocationFix), so Foxglove and Lichtblick draw them without a plugin, and
// fieldguard's own fieldguard.Decision and fieldguard.Health. JSON and not protobuf: no protobuf library or generated
// code in the daemon, every message readable as text, and each message checked against @foxglove/schemas' JSON schemas
// by a test (tests/interop/node/mcap_check.mjs). What it costs: a point cloud's bytes are base64 (4/3 as many, before
// the chunk's compression). Each schema's text, written for fieldguard from the fields it writes, goes into the file
// with its messages (schemas()).

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/geo/projection.hpp"
#include "fieldguard/output/safety_monitor.hpp"
#include "fieldguard/perception/obstacle.hpp"
#include "fieldguard/perception/obstacle_hold.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::app::foxglove {

struct Schema {
  std::string_view name;  // "foxglove.PointCloud", ..., "fieldguard.Decision"
  std::string_view json;  // its JSON Schema
};
// Every schema a recording uses, in a fixed order.
[[nodiscard]] std::span<const Schema> schemas();
[[nodiscard]] const Schema& schema(std::string_view name);  // throws std::out_of_range for a name not there

// The frames the messages name: the detection frame ("lidar": the 3D LiDAR's, levelled in a fused frame) and,
// for a fused frame levelled in full, "field": the plane (east, north, up) less a fixed origin, whole metres
// near the first pose, so that viewers draw in single precision without jitter.
inline constexpr std::string_view kLidarFrame = "lidar";
inline constexpr std::string_view kFieldFrame = "field";

// The frame's points as measured: x, y, z (float32), intensity (uint8), source (uint8: 0 3D LiDAR, 1 2D
// LiDAR), ring (uint16): 16 bytes a point.
void raw_cloud(std::string& out, std::int64_t stamp_ns, const LidarFrame& frame);
// The points detection worked on (after the region of interest and the voxel grid) with what it made of them:
// x, y, z (float32), label (uint8: 0 ground, 1 obstacle, 2 clustered but filtered out, 3 not clustered),
// obstacle (int16 at 14: the index in `obstacles` of the box that holds an obstacle point, -1 otherwise).
void labelled_cloud(std::string& out, std::int64_t stamp_ns, std::span<const perception::LabeledPoint> points,
                    std::span<const perception::Obstacle> obstacles);
// One entity "obstacles": each obstacle's oriented box (red when it is in the stop zone, orange otherwise,
// blue when held) and a text with its distance and height; an empty entity when there is none.
void obstacles_scene(std::string& out, std::int64_t stamp_ns, std::span<const perception::Obstacle> obstacles,
                     const output::safety::Zone* zone);
// One entity "zones": the stop zone (when decided; red while stopped, green at go) and the region of interest
// and the body box as outlines on the ground plane z = ground_z.
void zones_scene(std::string& out, std::int64_t stamp_ns, const perception::Box3& roi, const perception::Box3& body,
                 double ground_z, const output::safety::Decision* decision);
// fieldguard.Decision: {timestamp, frame, on, stop, reason, reasons, headline, nearest_m (null when none),
// obstacles_in_zone, zone {x_min, x_max, half_width, speed_known}}. "on": "frame" for a frame's decision,
// "clock" for one the daemon took between frames (a sensor gone silent; `frame` is then the last frame's).
void decision(std::string& out, std::int64_t stamp_ns, std::uint64_t frame, const output::safety::Decision& d,
              int clear_frames, bool on_clock = false);
// foxglove.FrameTransform field -> lidar from a fused frame's detection pose, less `origin` (east, north, up).
void frame_transform(std::string& out, std::int64_t stamp_ns, const perception::FramePose& pose,
                     const std::array<double, 3>& origin);
// One sensor as the daemon reports it: "lidar", "ok" | "silent 1.4 s" | "never heard" | "off", its rate.
struct SensorState {
  std::string name;
  std::string state;
  double rate_hz = 0.0;
};
// fieldguard.Health: {timestamp, sensors [{name, state, rate_hz}], status (the STATUS= line)}. The texts are the
// daemon's own words and numbers: nothing JSON must escape.
void health(std::string& out, std::int64_t stamp_ns, std::span<const SensorState> sensors, std::string_view status);
// foxglove.LocationFix of the vehicle's reference point (WGS84 degrees, ellipsoidal height).
void location_fix(std::string& out, std::int64_t stamp_ns, const geo::Geodetic& g);

// Standard base64 (RFC 4648, with padding), appended to `out`.
void base64(std::string& out, std::span<const std::byte> bytes);

}  // namespace fieldguard::app::foxglove
