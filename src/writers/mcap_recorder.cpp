#include "fieldguard/writers/mcap_recorder.hpp"

#include <algorithm>
#include <cmath>

#include "fieldguard/core/version.hpp"
#include "fieldguard/writers/foxglove_json.hpp"

namespace fieldguard::app {

McapRecorder::McapRecorder(const Config& cfg) : cfg_(cfg), projection_(cfg.geo.projection) {}

bool McapRecorder::open(const std::string& path, const McapOptions& options) {
  McapOptions o = options;
  if (o.library.empty()) o.library = std::string("fieldguard ") + version_string();
  if (!writer_.open(path, o)) return false;
  schema_ids_.assign(foxglove::schemas().size(), 0);
  auto channel = [&](std::string_view topic, std::string_view schema_name) {
    const foxglove::Schema& s = foxglove::schema(schema_name);
    // One schema record per schema, however many channels use it.
    for (std::size_t i = 0; i < foxglove::schemas().size(); ++i) {
      if (foxglove::schemas()[i].name == schema_name) {
        if (schema_ids_[i] == 0) schema_ids_[i] = writer_.add_schema(s.name, "jsonschema", s.json);
        return writer_.add_channel(schema_ids_[i], topic, "json");
      }
    }
    return std::uint16_t{0};
  };
  ch_.raw = channel("/lidar/points", "foxglove.PointCloud");
  ch_.labelled = channel("/detection/points", "foxglove.PointCloud");
  ch_.obstacles = channel("/detection/obstacles", "foxglove.SceneUpdate");
  ch_.zones = channel("/detection/zones", "foxglove.SceneUpdate");
  ch_.decision = channel("/safety/decision", "fieldguard.Decision");
  ch_.tf = channel("/tf", "foxglove.FrameTransform");
  ch_.fix = channel("/gnss/fix", "foxglove.LocationFix");
  return writer_.error().empty();
}

bool McapRecorder::put(std::uint16_t channel, std::int64_t stamp_ns) {
  return writer_.write(channel, static_cast<std::uint64_t>(std::max<std::int64_t>(stamp_ns, 0)), message_);
}

bool McapRecorder::frame(const LidarFrame& frame, const perception::FrameResult& result,
                         std::span<const perception::LabeledPoint> points, const FusionInfo* fusion,
                         const output::safety::Decision* decision) {
  const std::int64_t t = frame.host_stamp.ns;
  // The detection frame's z = 0 is the sensor: the ground drawn at the mounting height below it.
  const double ground_z = -cfg_.perception.ground.zones.sensor_height_m;
  foxglove::raw_cloud(message_, t, frame);
  put(ch_.raw, t);
  foxglove::labelled_cloud(message_, t, points, result.obstacles);
  put(ch_.labelled, t);
  foxglove::obstacles_scene(message_, t, result.obstacles, decision != nullptr ? &decision->zone : nullptr);
  put(ch_.obstacles, t);
  foxglove::zones_scene(message_, t, cfg_.perception.roi, cfg_.perception.body, ground_z, decision);
  put(ch_.zones, t);
  if (decision != nullptr) {
    foxglove::decision(message_, t, frame.index, *decision, cfg_.safety.clear_frames);
    put(ch_.decision, t);
  }
  if (fusion != nullptr) {
    if (const auto pose = detection_pose(*fusion, cfg_.lidar.mounting)) {
      if (!origin_)
        origin_ = std::array<double, 3>{std::round(pose->x_m), std::round(pose->y_m), std::round(pose->z_m)};
      foxglove::frame_transform(message_, t, *pose, *origin_);
      put(ch_.tf, t);
      if (const auto g = projection_.reverse(*fusion->reference)) {
        foxglove::location_fix(message_, t, *g);
        put(ch_.fix, t);
      }
    }
  }
  return writer_.error().empty();
}

bool McapRecorder::close() { return writer_.close(); }

}  // namespace fieldguard::app
