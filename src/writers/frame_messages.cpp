#include "fieldguard/writers/frame_messages.hpp"

#include <cmath>

#include "fieldguard/writers/foxglove_json.hpp"

namespace fieldguard::app {

FrameEncoder::FrameEncoder(const Config& cfg) : cfg_(cfg), projection_(cfg.geo.projection) {}

void FrameEncoder::encode(const LidarFrame& frame, const perception::FrameResult& result,
                          std::span<const perception::LabeledPoint> points, const FusionInfo* fusion,
                          const output::safety::Decision* decision, const Emit& emit) {
  const std::int64_t t = frame.host_stamp.ns;
  // The detection frame's z = 0 is the sensor: the ground drawn at the mounting height below it.
  const double ground_z = -cfg_.perception.ground.zones.sensor_height_m;
  foxglove::raw_cloud(message_, t, frame);
  emit(Topic::RawPoints, t, message_);
  foxglove::labelled_cloud(message_, t, points, result.obstacles);
  emit(Topic::LabelledPoints, t, message_);
  foxglove::obstacles_scene(message_, t, result.obstacles, decision != nullptr ? &decision->zone : nullptr);
  emit(Topic::Obstacles, t, message_);
  foxglove::zones_scene(message_, t, cfg_.perception.roi, cfg_.perception.body, ground_z, decision);
  emit(Topic::Zones, t, message_);
  if (decision != nullptr) {
    foxglove::decision(message_, t, frame.index, *decision, cfg_.safety.clear_frames);
    emit(Topic::Decision, t, message_);
  }
  if (fusion == nullptr) return;
  const auto pose = detection_pose(*fusion, cfg_.lidar.mounting);
  if (!pose) return;
  if (!origin_) origin_ = std::array<double, 3>{std::round(pose->x_m), std::round(pose->y_m), std::round(pose->z_m)};
  foxglove::frame_transform(message_, t, *pose, *origin_);
  emit(Topic::Transform, t, message_);
  if (const auto g = projection_.reverse(*fusion->reference)) {
    foxglove::location_fix(message_, t, *g);
    emit(Topic::Fix, t, message_);
  }
}

}  // namespace fieldguard::app
