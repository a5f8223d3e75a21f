#pragma once
// Builders of the things scenes put on the field, at physically plausible sizes. Positions are world x-y;
// each builder stands its object on the terrain. Sizes are documented at each builder.

#include <string>
#include <vector>

#include "sim/rng.hpp"
#include "sim/scene.hpp"

namespace fieldguard::sim {

// The tractor seen from its own LiDAR (sensor frame; the sensor sits 0.95 m up on the front weight
// carrier): weights, front wheels, hood, cab, rear wheels; all inside (-5,-1.5,-1.5)..(0.4,1.5,1.5).
[[nodiscard]] std::vector<Primitive> tractor_body();

// A parked seed drill / cultivator, ~3 x 2.5 x 1.5 m: frame, hopper, two wheels, drawbar and tines.
[[nodiscard]] SceneObject make_implement(const std::string& id, double x, double y, double yaw, const Terrain& t);
// One round bale lying on its side: 1.5 m diameter, 1.2 m wide.
[[nodiscard]] SceneObject make_round_bale(const std::string& id, double x, double y, double yaw, const Terrain& t);
// A stack of five round bales (three below, two on top): ~4.5 x 1.2 x 2.8 m.
[[nodiscard]] SceneObject make_bale_stack(const std::string& id, double x, double y, double yaw, const Terrain& t);
// A person standing still (mid-stride) at (x, y), facing `heading` (rad): see pedestrian.hpp for the body.
[[nodiscard]] SceneObject make_standing_person(const std::string& id, double x, double y, double heading,
                                               const Terrain& t);
// A low farm house, 8 x 6 m, walls 2.4 m, stepped roof to 3.0 m (eaves overhang 0.2 m).
[[nodiscard]] SceneObject make_house(const std::string& id, double x, double y, double yaw, const Terrain& t);
// A roadside tree: trunk r 0.15-0.25 m, crown base 1.8-2.6 m, porous crown 3-5 m across and 3-4.4 m tall.
[[nodiscard]] SceneObject make_roadside_tree(const std::string& id, double x, double y, const Terrain& t, Rng& rng);
// An orchard tree: trunk (r 6-10 cm) up to the crown, porous ellipsoid crown with the given semi-axes
// (x along the row, y across, z vertical), its bottom `crown_base_m` above the ground.
[[nodiscard]] SceneObject make_orchard_tree(const std::string& id, double x, double y, Vec3 semi_axes,
                                            double crown_base_m, const Terrain& t, Rng& rng);
// A clod or stone: a partly buried ellipsoid showing `height_m` above the furrowed ground.
[[nodiscard]] SceneObject make_clod(const std::string& id, double x, double y, double height_m, const Terrain& t,
                                    Rng& rng);
// A field ridge (bank) from (x0,y0) to (x1,y1): `height_m` above the ground, `width_m` at its foot; a chain
// of buried capsules following the ground, one object per segment (~4 m).
[[nodiscard]] std::vector<SceneObject> make_ridge(const std::string& id_prefix, double x0, double y0, double x1,
                                                  double y1, double height_m, double width_m, const Terrain& t);

// Bounds of the parts, clipped below at `ground_z` (the part of a buried solid a sensor can see).
[[nodiscard]] Aabb visible_bounds(const std::vector<Primitive>& parts, double ground_z);

}  // namespace fieldguard::sim
