#include "sim/scene.hpp"

#include <algorithm>
#include <cmath>

namespace fieldguard::sim {

std::string_view to_string(ObjectClass c) {
  switch (c) {
    case ObjectClass::Pedestrian: return "pedestrian";
    case ObjectClass::Implement: return "implement";
    case ObjectClass::Haystack: return "haystack";
    case ObjectClass::House: return "house";
    case ObjectClass::Tree: return "tree";
    case ObjectClass::Crown: return "crown";
    case ObjectClass::Pole: return "pole";
    case ObjectClass::Box: return "box";
    case ObjectClass::Clod: return "clod";
    case ObjectClass::Ridge: return "ridge";
    case ObjectClass::Crop: return "crop";
    case ObjectClass::Body: return "body";
  }
  return "?";
}

bool is_terrain(ObjectClass c) {
  return c == ObjectClass::Clod || c == ObjectClass::Ridge || c == ObjectClass::Crop || c == ObjectClass::Body;
}

std::pair<double, double> Scene::travel_at(double t_s) const {
  const MotionParams& m = motion;
  if (!std::isfinite(m.stop_x_m) || m.speed_mps <= 0.0 || m.decel_mps2 <= 0.0) {
    return {m.start_x_m + m.speed_mps * t_s, m.speed_mps};
  }
  const double v = m.speed_mps;
  const double brake_s = v / m.decel_mps2;
  const double t_brake = std::max(0.0, (m.stop_x_m - m.start_x_m - 0.5 * v * brake_s) / v);
  if (t_s < t_brake) return {m.start_x_m + v * t_s, v};
  const double tau = std::min(t_s - t_brake, brake_s);
  return {m.start_x_m + v * t_brake + v * tau - 0.5 * m.decel_mps2 * tau * tau, v - m.decel_mps2 * tau};
}

SensorPose Scene::pose_at(double t_s) const {
  const MotionParams& m = motion;
  const auto [x, speed] = travel_at(t_s);
  const double ground = terrain.base(x, 0.0);
  const double rock = m.rock_with_speed && m.speed_mps > 0.0 ? speed / m.speed_mps : 1.0;
  double roll = m.roll_deg + rock * m.roll_amp_deg * std::sin(2.0 * kPi * t_s / m.roll_period_s);
  double pitch = m.pitch_deg + rock * m.pitch_amp_deg * std::sin(2.0 * kPi * t_s / m.pitch_period_s + 1.3);
  if (m.vibration_deg != 0.0) {
    roll += m.vibration_deg * std::sin(2.0 * kPi * 2.3 * t_s + 0.4);
    pitch += m.vibration_deg * std::sin(2.0 * kPi * 3.1 * t_s + 2.1);
  }
  if (m.follow_terrain) {
    // Rear axle 3.6 m behind the sensor, track 1.8 m: the chassis lies on the smooth ground under it.
    const double dzdx = (terrain.base(x, 0.0) - terrain.base(x - 3.6, 0.0)) / 3.6;
    const double dzdy = (terrain.base(x - 1.8, 0.9) - terrain.base(x - 1.8, -0.9)) / 1.8;
    pitch -= std::atan(dzdx) / kDegToRad;  // nose up on a climb is a negative rotation about y
    roll += std::atan(dzdy) / kDegToRad;   // left side up is a positive rotation about x
  }
  SensorPose pose;
  pose.position = {x, 0.0, ground + m.sensor_height_m};
  pose.roll_deg = roll;
  pose.pitch_deg = pitch;
  pose.rot = attitude(roll * kDegToRad, pitch * kDegToRad);
  return pose;
}

void Scene::animate(double t_s) {
  if (!pedestrian) return;
  SceneObject& o = objects[pedestrian_index];
  pedestrian->parts_at(t_s, terrain, o.parts);
  o.bounds = Aabb{};
  for (const Primitive& p : o.parts) o.bounds.add(bounds(p));
}

}  // namespace fieldguard::sim
