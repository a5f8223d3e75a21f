#pragma once
// Casts one LiDAR ray into a scene: the tractor's body (sensor frame), the terrain, crop blocks and the
// objects (world frame); returns the nearest surface and what it belongs to. Objects are found through
// 0.5-degree bins of world azimuth around the sensor, rebuilt once per rotation and sorted by distance, so
// a ray tests only the few objects in its direction nearer than what it has already hit. Thread-compatible: cast() may
// run on several threads at once (each with its own Rng), prepare() alone.

#include <cstdint>
#include <span>
#include <vector>

#include "sim/rng.hpp"
#include "sim/scene.hpp"

namespace fieldguard::sim {

struct CastHit {
  double range_m = 0.0;
  // What was hit: kNone, kTerrain, an object index, objects.size() + crop index, or body_target().
  std::int64_t target = -1;
  double cos_incidence = 1.0;
  double reflectivity = 0.0;
  bool porous = false;  // stopped inside a porous volume (crop, crown): the rest of the beam goes on
};

class RayCaster {
 public:
  static constexpr std::int64_t kNone = -1;
  static constexpr std::int64_t kTerrain = -2;

  explicit RayCaster(const Scene& scene) : scene_(scene) {}

  // Bins objects by the world azimuth under which they appear from `sensor` (world). `swept` holds each
  // object's bounds over the coming rotation (moving objects) and `margin_m` covers the sensor's own motion.
  void prepare(Vec3 sensor, double margin_m, std::span<const Aabb> swept);
  // The tractor's body alone (fixed in the sensor frame, so callers compute it once per firing ray).
  [[nodiscard]] CastHit cast_body(Vec3 origin_sensor, Vec3 dir_sensor) const;
  // Everything, from pose.position: `body` is cast_body() of the same ray. `moving`, if given, stands in for the
  // scene's pedestrian (each thread animates its own copy). Only what lies beyond `from_m` along the ray counts: a
  // ray that stopped in a porous volume at from_m goes on from there (and may stop again in the same volume).
  [[nodiscard]] CastHit cast(const SensorPose& pose, Vec3 dir_sensor, const CastHit& body, Rng& rng,
                             const SceneObject* moving = nullptr, double from_m = 0.0) const;

  [[nodiscard]] std::int64_t crop_target(std::size_t crop) const {
    return static_cast<std::int64_t>(scene_.objects.size() + crop);
  }
  [[nodiscard]] std::int64_t body_target() const {
    return static_cast<std::int64_t>(scene_.objects.size() + scene_.crops.size());
  }
  [[nodiscard]] std::size_t target_count() const { return scene_.objects.size() + scene_.crops.size() + 1; }

 private:
  static constexpr int kBins = 720;
  struct Candidate {
    double near_m;        // horizontal distance from the sensor to the object's bounds, less the margin
    std::uint32_t index;  // into scene.objects
  };
  const Scene& scene_;
  std::vector<std::vector<Candidate>> bins_ = std::vector<std::vector<Candidate>>(kBins);  // nearest first
};

}  // namespace fieldguard::sim
