#pragma once
// A crop block: dense vegetation standing on the field inside a rectangle, its canopy 0.5-0.8 m above the
// ground (varying smoothly). The canopy is a porous volume: a ray that enters it stops at an exponentially
// distributed depth (mean free path ~0.3 m), or passes on if that depth takes it out of the volume, so
// returns come from the top and the inside of the canopy and things inside the crop are partly hidden.

#include <cstdint>

#include "sim/geometry.hpp"
#include "sim/rng.hpp"
#include "sim/terrain.hpp"

namespace fieldguard::sim {

struct CropParams {
  double x_min = 0.0;
  double x_max = 0.0;
  double y_min = 0.0;
  double y_max = 0.0;
  double height_min_m = 0.5;
  double height_max_m = 0.8;
  double mean_free_path_m = 0.3;
  double reflectivity = 30.0;
};

class CropBlock {
 public:
  CropBlock(const CropParams& params, const Terrain& terrain, std::uint64_t seed);

  [[nodiscard]] double canopy_height(double x, double y) const;  // above the ground, m
  // Where the ray stops in the crop, if between tmin and tmax. Draws from `rng` only when the ray enters the canopy.
  [[nodiscard]] bool intersect(const Ray& ray, const Terrain& terrain, double tmin, double tmax, Rng& rng,
                               double& t_hit) const;
  [[nodiscard]] const Aabb& bounds() const { return bounds_; }  // world
  [[nodiscard]] const CropParams& params() const { return params_; }

 private:
  CropParams params_;
  std::uint64_t seed_;
  Aabb bounds_;
  double slope_bound_ = 0.0;
};

}  // namespace fieldguard::sim
