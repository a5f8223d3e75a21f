#include "sim/scene_builders.hpp"

#include <algorithm>
#include <cmath>

#include "sim/props.hpp"

namespace fieldguard::sim::detail {

TerrainExtent extent_for(double start_x, double travel) {
  return {start_x - 115.0, start_x + travel + 115.0, -115.0, 115.0};
}

void scatter_clods(Scene& s, Rng& rng, double x0, double x1, double y0, double y1, double density, double h_min,
                   double h_max, double skew, const std::string& prefix) {
  const auto count = static_cast<int>(density * (x1 - x0) * (y1 - y0));
  for (int k = 0; k < count; ++k) {
    const double x = rng.uniform(x0, x1);
    const double y = rng.uniform(y0, y1);
    const double h = h_min + (h_max - h_min) * std::pow(rng.uniform(), skew);
    s.objects.push_back(make_clod(prefix + std::to_string(k), x, y, h, s.terrain, rng));
  }
}

void add_ridge(Scene& s, const std::string& id, double x0, double y0, double x1, double y1, double h, double w) {
  for (SceneObject& o : make_ridge(id, x0, y0, x1, y1, h, w, s.terrain)) s.objects.push_back(std::move(o));
}

void add_crossings(Scene& s, const SceneSetup& setup) {
  std::vector<Crossing> crossings;
  const auto n = static_cast<int>(kCrossingDistancesM.size());
  for (int i = 0; i < n; ++i) {
    const int r0 = setup.rotations * i / n;
    const int r1 = setup.rotations * (i + 1) / n;
    const double t0 = r0 * setup.period_s;
    const double t1 = r1 * setup.period_s;
    const double half = std::min(8.0, 0.5 * 1.4 * (t1 - t0));
    Crossing c;
    c.x_m = kCrossingDistancesM[static_cast<std::size_t>(i)] + 0.2 + kPedestrianHalfWidthM;
    c.y_from_m = i % 2 == 0 ? -half : half;
    c.y_to_m = -c.y_from_m;
    c.t_begin_s = t0;
    c.t_end_s = t1;
    crossings.push_back(c);
  }
  s.pedestrian.emplace(std::move(crossings));
  s.pedestrian_index = s.objects.size();
  SceneObject person;
  person.id = "pedestrian";
  person.cls = ObjectClass::Pedestrian;
  s.objects.push_back(std::move(person));
  s.animate(0.0);
}

Scene base_scene(const std::string& name, const TerrainParams& tp, double start_x, double travel,
                 const SceneSetup& setup) {
  Scene s;
  s.name = name;
  s.terrain = Terrain(tp, extent_for(start_x, travel), hash64(setup.seed, 0x7e88a1));
  s.body = tractor_body();
  s.motion.start_x_m = start_x;
  return s;
}

}  // namespace fieldguard::sim::detail
