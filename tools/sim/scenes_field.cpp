// Scenes of bare fields and the walking pedestrian: flat, pedestrian, rough, rough-pedestrian.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "sim/props.hpp"
#include "sim/scene_builders.hpp"

namespace fieldguard::sim::detail {

namespace {

TerrainParams rough_terrain() {
  TerrainParams p;
  p.grade_x = 0.015;
  p.grade_y = -0.01;
  p.undulations = {{0.25, 70.0, 10.0, 0.3}, {0.10, 31.0, 75.0, 1.9}, {0.04, 13.0, 140.0, 4.0}};
  p.rise_start_x = 90.0;
  p.rise_grade = 0.04;
  p.rise_width_m = 10.0;
  p.furrow_amplitude_m = 0.045;
  p.furrow_period_m = 0.8;
  p.furrow_heading_deg = 30.0;
  p.furrow_variation = 0.4;
  return p;
}

void rough_clods(Scene& s, Rng& rng, double x0, double x1) {
  scatter_clods(s, rng, x0, x1, -60.0, 60.0, 0.08, 0.04, 0.15, 2.0, "clod-s");
  scatter_clods(s, rng, x0, x1, -60.0, 60.0, 0.01, 0.15, 0.40, 1.5, "clod-l");
}

}  // namespace

Scene flat(const SceneSetup& setup) {
  Scene s = base_scene("flat", TerrainParams{}, 0.0, 0.0, setup);
  s.motion.follow_terrain = false;
  s.noise = {0.01, 0.01, 100.0};
  s.objects.push_back(make_implement("implement-1", 12.0, 0.0, 0.0, s.terrain));
  s.objects.push_back(make_round_bale("haystack-1", 8.0, 4.0, kPi / 2.0, s.terrain));
  return s;
}

Scene pedestrian(const SceneSetup& setup) {
  TerrainParams tp;
  tp.grade_x = 0.01;
  tp.grade_y = -0.015;
  tp.rise_start_x = 22.0;
  tp.rise_grade = 0.05;
  tp.rise_width_m = 6.0;
  tp.undulations = {{0.15, 45.0, 30.0, 0.7}, {0.08, 23.0, 110.0, 2.2}};
  tp.furrow_amplitude_m = 0.03;
  tp.furrow_period_m = 0.75;
  Scene s = base_scene("pedestrian", tp, 0.0, 0.0, setup);
  Rng rng(setup.seed, 0x9ed);
  scatter_clods(s, rng, -60.0, 80.0, -60.0, 60.0, 0.05, 0.03, 0.15, 2.5, "clod-s");
  scatter_clods(s, rng, -60.0, 80.0, -60.0, 60.0, 0.003, 0.15, 0.25, 1.0, "clod-l");
  s.motion.roll_deg = 1.0;
  s.motion.pitch_deg = -0.6;
  s.motion.vibration_deg = 0.15;
  s.noise = {0.015, 0.02, 100.0};
  add_crossings(s, setup);
  return s;
}

Scene rough(const SceneSetup& setup) {
  const double speed = 1.6;
  const double travel = speed * setup.rotations * setup.period_s;
  Scene s = base_scene("rough", rough_terrain(), 0.0, travel, setup);
  Rng rng(setup.seed, 0x2046);
  rough_clods(s, rng, -60.0, travel + 90.0);
  add_ridge(s, "ridge-left", -30.0, 5.5, travel + 90.0, 5.5, 0.35, 1.8);
  add_ridge(s, "ridge-right", 30.0, -6.5, 90.0, -7.5, 0.30, 1.5);
  add_ridge(s, "ridge-cross", travel + 8.0, -40.0, travel + 32.0, 40.0, 0.38, 2.0);
  s.motion.speed_mps = speed;
  s.motion.roll_amp_deg = 3.5;
  s.motion.roll_period_s = 5.3;
  s.motion.pitch_amp_deg = 3.0;
  s.motion.pitch_period_s = 3.7;
  s.motion.vibration_deg = 0.3;
  s.noise = {0.02, 0.03, 100.0};
  return s;
}

Scene rough_pedestrian(const SceneSetup& setup) {
  Scene s = base_scene("rough-pedestrian", rough_terrain(), 0.0, 0.0, setup);
  Rng rng(setup.seed, 0x2047);
  rough_clods(s, rng, -60.0, 90.0);
  add_ridge(s, "ridge-left", -30.0, 9.5, 90.0, 9.5, 0.35, 1.8);
  s.motion.follow_terrain = false;
  s.motion.roll_deg = 3.5;
  s.motion.pitch_deg = -3.0;
  s.motion.roll_amp_deg = 0.5;
  s.motion.pitch_amp_deg = 0.4;
  s.motion.vibration_deg = 0.3;
  s.noise = {0.02, 0.03, 100.0};
  add_crossings(s, setup);
  return s;
}

Scene uneven_drive(const SceneSetup& setup) {
  constexpr double kSpeed = 1.5;
  constexpr double kDecel = 0.75;
  constexpr double kMastM = 1.8;  // LiDAR height: its lowest beam (-30.67 deg) reaches the ground 3 m ahead
  const double total_s = setup.rotations * setup.period_s;
  const double stand_s = std::min(6.0, 0.25 * total_s);
  const double brake_s = kSpeed / kDecel;
  const double stop_x = kSpeed * std::max(0.0, total_s - stand_s - brake_s) + 0.5 * kSpeed * brake_s;
  TerrainParams tp;
  tp.grade_x = 0.01;
  tp.grade_y = -0.01;
  // Swells: 0.45 m over 40 m and 0.3 m over 22 m, crossing the path at angles so that both pitch and roll
  // change as the tractor drives; with the rocking, roll and pitch reach about 8 deg.
  tp.undulations = {{0.45, 40.0, 20.0, 0.3}, {0.20, 22.0, 75.0, 1.1}, {0.05, 9.0, 130.0, 2.0}};
  tp.furrow_amplitude_m = 0.03;
  tp.furrow_period_m = 0.75;
  tp.furrow_heading_deg = 10.0;
  Scene s = base_scene("uneven-drive", tp, 0.0, stop_x, setup);
  s.motion.sensor_height_m = kMastM;
  // The tractor stays on the ground: the body hangs that much further below the higher sensor.
  for (Primitive& p : s.body) p.center.z -= kMastM - 0.95;
  s.motion.speed_mps = kSpeed;
  s.motion.stop_x_m = stop_x;
  s.motion.decel_mps2 = kDecel;
  s.motion.rock_with_speed = true;
  s.motion.roll_amp_deg = 2.0;
  s.motion.roll_period_s = 4.7;
  s.motion.pitch_amp_deg = 2.5;
  s.motion.pitch_period_s = 3.3;
  s.motion.vibration_deg = 0.15;
  s.noise = {0.015, 0.02, 100.0};

  // Small clods everywhere except around where the tractor stops (nothing between the bumper and the box).
  Rng rng(setup.seed, 0x0e7e);
  scatter_clods(s, rng, -60.0, stop_x + 90.0, -60.0, 60.0, 0.03, 0.03, 0.15, 2.0, "clod-s");
  std::erase_if(s.objects, [&](const SceneObject& o) {
    const Vec3 c = o.bounds.center();
    return o.cls == ObjectClass::Clod && c.x > stop_x - 3.0 && c.x < stop_x + 6.0 && std::abs(c.y) < 3.0;
  });

  auto standing_box = [&](const std::string& id, ObjectClass cls, double x, double y, Vec3 size, double refl) {
    // Sunk 5 cm into the furrowed ground, so that no ray passes under it.
    const double g = s.terrain.base(x, y);
    Primitive p = make_box_minmax({x - 0.5 * size.x, y - 0.5 * size.y, g - 0.05},
                                  {x + 0.5 * size.x, y + 0.5 * size.y, g + size.z});
    p.reflectivity = refl;
    SceneObject o;
    o.id = id;
    o.cls = cls;
    o.parts = {p};
    o.bounds = bounds(p);
    o.bounds.min.z = g;  // the part above the ground
    return o;
  };
  s.objects.push_back(standing_box("pole-1", ObjectClass::Pole, 0.5 * stop_x + 4.0, 3.0, {0.1, 0.1, 2.0}, 80.0));
  // The bumper (the front weights' face, 0.3 m ahead of the sensor) where the tractor stands, at the 2D
  // LiDAR's height (0.3 m): the box's near face 1 m ahead of it. Where the tractor stands nose up, the
  // bumper is further ahead than the sensor above it.
  const SensorPose standing = s.pose_at(total_s + 10.0);
  const Vec3 bumper = standing.position + standing.rot * Vec3{0.3, 0.0, 0.3 - kMastM};
  s.objects.push_back(standing_box("box-1", ObjectClass::Box, bumper.x + 1.0 + 0.2, 0.0, {0.4, 0.6, 0.4}, 60.0));
  return s;
}

}  // namespace fieldguard::sim::detail
