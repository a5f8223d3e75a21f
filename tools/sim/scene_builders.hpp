#pragma once
// Private to tools/sim: the pieces scenes are assembled from, and one builder per named scene.

#include <string>

#include "sim/rng.hpp"
#include "sim/scenes.hpp"

namespace fieldguard::sim::detail {

// Terrain grid covering everything the sensor can reach while it drives `travel` metres from `start_x`.
[[nodiscard]] TerrainExtent extent_for(double start_x, double travel);
// An empty scene on the given terrain, with the tractor's body, starting at `start_x`.
[[nodiscard]] Scene base_scene(const std::string& name, const TerrainParams& tp, double start_x, double travel,
                               const SceneSetup& setup);
// Clods scattered over a rectangle: `density` per m2, heights from h_min to h_max, skewed towards small ones
// (height = h_min + (h_max - h_min) * u^skew).
void scatter_clods(Scene& s, Rng& rng, double x0, double x1, double y0, double y1, double density, double h_min,
                   double h_max, double skew, const std::string& prefix);
void add_ridge(Scene& s, const std::string& id, double x0, double y0, double x1, double y1, double h, double w);
// The pedestrian's crossings at kCrossingDistancesM: one per sixth of the run (whole rotations), alternating
// direction, at most 1.4 m/s over at most +-8 m.
void add_crossings(Scene& s, const SceneSetup& setup);

[[nodiscard]] Scene flat(const SceneSetup& setup);
[[nodiscard]] Scene pedestrian(const SceneSetup& setup);
[[nodiscard]] Scene rough(const SceneSetup& setup);
[[nodiscard]] Scene rough_pedestrian(const SceneSetup& setup);
[[nodiscard]] Scene farmyard(const SceneSetup& setup);
[[nodiscard]] Scene orchard(const SceneSetup& setup);
[[nodiscard]] Scene shed(const SceneSetup& setup);
[[nodiscard]] Scene uneven_drive(const SceneSetup& setup);

}  // namespace fieldguard::sim::detail
