#pragma once
// A scene: the field (heightfield terrain, crop blocks), the things on it (objects the detector must report,
// and terrain features it must not: clods, field ridges), the tractor's own body in the sensor frame, a
// walking pedestrian, how the tractor moves and rolls/pitches, and the sensor's noise. Plain data built by
// scenes.cpp; the simulator only reads it (apart from animating the pedestrian).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "sim/crop.hpp"
#include "sim/geometry.hpp"
#include "sim/pedestrian.hpp"
#include "sim/primitives.hpp"
#include "sim/terrain.hpp"

namespace fieldguard::sim {

enum class ObjectClass : std::uint8_t {
  Pedestrian,
  Implement,
  Haystack,
  House,
  Tree,
  Crown,  // real objects: a detector must report them
  Pole,
  Box,
  Clod,
  Ridge,
  Crop,
  Body,  // terrain and the tractor: it must not
};
[[nodiscard]] std::string_view to_string(ObjectClass c);
[[nodiscard]] bool is_terrain(ObjectClass c);

struct SceneObject {
  std::string id;
  ObjectClass cls = ObjectClass::Implement;
  std::vector<Primitive> parts;  // world frame
  Aabb bounds;                   // world; for buried solids (clods, ridges) only the part above the ground
};

struct MotionParams {
  double start_x_m = 0.0;         // where the sensor starts (world x)
  double speed_mps = 0.0;         // along world x
  double sensor_height_m = 0.95;  // above the smooth ground below the sensor
  bool follow_terrain = true;     // add the attitude of the ground under the tractor (over a 3 m wheelbase)
  double roll_deg = 0.0;          // constant part
  double pitch_deg = 0.0;
  double roll_amp_deg = 0.0;  // slow rocking: amplitude and period
  double roll_period_s = 5.0;
  double pitch_amp_deg = 0.0;
  double pitch_period_s = 4.0;
  double vibration_deg = 0.0;  // engine/ride vibration, a few Hz, on both axes
  // Braking: the tractor slows at decel_mps2 to stand with its sensor at world x = stop_x_m (inf = never).
  double stop_x_m = kInf;
  double decel_mps2 = 0.5;
  bool rock_with_speed = false;  // the rocking amplitudes scale with the speed: a standing tractor does not rock
  double lidar_forward_m = 3.6;  // the sensor's x in the vehicle frame (origin on the ground below the rear axle)
};

struct SensorNoise {
  double range_sigma_m = 0.015;  // Gaussian range noise
  double dropout = 0.02;         // fraction of rays lost at any range
  double max_range_m = 100.0;    // no return beyond; the loss grows as (range / max_range)^4 before it
};

struct SensorPose {
  Vec3 position;  // world
  Mat3 rot;       // sensor -> world
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
};

struct Scene {
  std::string name;
  Terrain terrain;
  std::vector<CropBlock> crops;
  std::vector<SceneObject> objects;      // objects and terrain features (clods, ridge segments)
  std::optional<Pedestrian> pedestrian;  // animated into objects[pedestrian_index]
  std::size_t pedestrian_index = 0;
  std::vector<Primitive> body;  // the tractor, in the SENSOR frame
  MotionParams motion;
  SensorNoise noise;

  [[nodiscard]] SensorPose pose_at(double t_s) const;
  // The sensor's world x and the speed (m/s) at t_s.
  [[nodiscard]] std::pair<double, double> travel_at(double t_s) const;
  // Moves the pedestrian (if any) to time t_s.
  void animate(double t_s);
};

}  // namespace fieldguard::sim
