// Scenes of things on the field: farmyard, orchard, shed.
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "sim/props.hpp"
#include "sim/scene_builders.hpp"

namespace fieldguard::sim::detail {

Scene farmyard(const SceneSetup& setup) {
  const double speed = 1.5;
  const double travel = speed * setup.rotations * setup.period_s;
  TerrainParams tp;
  tp.grade_x = 0.01;
  tp.undulations = {{0.3, 80.0, 20.0, 1.0}, {0.1, 27.0, 100.0, 0.2}};
  tp.furrow_amplitude_m = 0.02;
  tp.furrow_period_m = 0.25;  // stubble rows
  tp.furrow_variation = 0.3;
  Scene s = base_scene("farmyard", tp, 0.0, travel, setup);
  Rng rng(setup.seed, 0xfa4);
  scatter_clods(s, rng, -60.0, travel + 90.0, -60.0, 60.0, 0.02, 0.03, 0.15, 2.0, "clod-s");
  s.objects.push_back(make_implement("implement-1", 22.0, -4.0, 25.0 * kDegToRad, s.terrain));
  s.objects.push_back(make_round_bale("haystack-1", 14.0, 3.2, 80.0 * kDegToRad, s.terrain));
  s.objects.push_back(make_bale_stack("haystack-2", 48.0, -5.5, 10.0 * kDegToRad, s.terrain));
  s.objects.push_back(make_house("house-1", 75.0, 9.5, 5.0 * kDegToRad, s.terrain));
  Rng trees(setup.seed, 0x74ee);
  int k = 0;
  for (double x = 30.0; x < travel + 110.0; x += trees.uniform(9.5, 12.5)) {
    const double y = -9.0 + trees.uniform(-0.4, 0.4);
    s.objects.push_back(make_roadside_tree("tree-" + std::to_string(k++), x, y, s.terrain, trees));
  }
  CropParams crop;
  crop.x_min = 95.0;
  crop.x_max = 160.0;
  crop.y_min = 2.5;
  crop.y_max = 40.0;
  s.crops.emplace_back(crop, s.terrain, hash64(setup.seed, 0xc40));
  s.motion.speed_mps = speed;
  s.motion.roll_deg = 0.5;
  s.motion.roll_amp_deg = 1.0;
  s.motion.pitch_amp_deg = 0.8;
  s.motion.vibration_deg = 0.2;
  s.noise = {0.015, 0.02, 100.0};
  return s;
}

Scene orchard(const SceneSetup& setup) {
  const double speed = 0.8;
  const double travel = speed * setup.rotations * setup.period_s;
  TerrainParams tp;
  tp.grade_x = 0.005;
  tp.grade_y = 0.01;
  tp.undulations = {{0.15, 60.0, 45.0, 0.5}};
  tp.furrow_amplitude_m = 0.015;
  tp.furrow_period_m = 1.8;  // wheel tracks and grass
  tp.furrow_variation = 0.5;
  Scene s = base_scene("orchard", tp, 0.0, travel, setup);
  Rng rng(setup.seed, 0x0c4a);
  scatter_clods(s, rng, -60.0, travel + 90.0, -60.0, 60.0, 0.01, 0.03, 0.12, 2.0, "clod-s");
  const std::array<double, 4> rows{-8.2, -3.7, 3.7, 8.2};
  for (std::size_t r = 0; r < rows.size(); ++r) {
    double x = 8.0;
    double prev_a = 0.0;
    int k = 0;
    while (true) {
      const double a = rng.uniform(0.75, 1.75);
      const double u = rng.uniform();
      const double gap = u < 0.45 ? rng.uniform(0.3, 0.5) : u < 0.8 ? rng.uniform(0.6, 1.5) : rng.uniform(2.0, 3.5);
      x += k == 0 ? a : prev_a + gap + a;
      if (x > travel + 60.0) break;
      const double b = std::min(1.75, a * rng.uniform(0.85, 1.0));
      const double c = a * rng.uniform(0.8, 1.1);
      const double y = rows[r] + rng.uniform(-0.15, 0.15);
      const std::string id = "crown-r" + std::to_string(r) + "-" + std::to_string(k);
      s.objects.push_back(make_orchard_tree(id, x, y, {a, b, c}, rng.uniform(0.6, 1.0), s.terrain, rng));
      prev_a = a;
      ++k;
    }
  }
  s.motion.speed_mps = speed;
  s.motion.roll_amp_deg = 0.8;
  s.motion.pitch_amp_deg = 0.6;
  s.motion.vibration_deg = 0.2;
  s.noise = {0.015, 0.02, 100.0};
  return s;
}

Scene shed(const SceneSetup& setup) {
  Scene s = base_scene("shed", TerrainParams{}, 0.0, 0.0, setup);
  s.motion.follow_terrain = false;
  s.motion.vibration_deg = 0.05;  // engine idling
  s.noise = {0.01, 0.003, 100.0};
  const double x0 = -12.0;
  const double x1 = 18.0;
  const double y0 = -9.0;
  const double y1 = 9.0;
  const double h = 5.5;
  const double w = 0.25;
  auto wall = [&](const std::string& id, Vec3 lo, Vec3 hi, double refl) {
    SceneObject o;
    o.id = id;
    o.cls = ObjectClass::House;
    Primitive p = make_box_minmax(lo, hi);
    p.reflectivity = refl;
    o.parts.push_back(p);
    o.bounds = bounds(p);
    s.objects.push_back(std::move(o));
  };
  wall("shed-front", {x1, y0 - w, 0.0}, {x1 + w, y1 + w, h}, 90.0);
  wall("shed-back", {x0 - w, y0 - w, 0.0}, {x0, y1 + w, h}, 90.0);
  wall("shed-left", {x0, y1, 0.0}, {x1, y1 + w, h}, 90.0);
  wall("shed-right", {x0, y0 - w, 0.0}, {x1, y0, h}, 90.0);
  wall("shed-roof", {x0 - w, y0 - w, h}, {x1 + w, y1 + w, h + w}, 60.0);
  s.objects.push_back(make_implement("implement-1", 9.0, -5.0, 0.3, s.terrain));
  s.objects.push_back(make_bale_stack("haystack-1", 12.0, 5.5, 0.0, s.terrain));
  s.objects.push_back(make_round_bale("haystack-2", -9.0, -6.0, 0.0, s.terrain));
  s.objects.push_back(make_standing_person("pedestrian-1", 6.0, 1.5, -kPi / 2.0, s.terrain));
  return s;
}

}  // namespace fieldguard::sim::detail
