#pragma once
// The field surface as a heightfield: a smooth base (grade, a change of slope ahead, long undulations) on a
// 1 m grid, plus furrows (a periodic ridged profile across the furrow direction whose amplitude varies
// smoothly along the field). Clods, field ridges and crops are separate solids (see scene.hpp); the
// heightfield is what they sit on.
//
// Ray casting marches along the ray in two regimes: far above the furrow envelope it steps by the height
// over the envelope divided by the steepest the base can rise (safe, large steps); inside the envelope by
// the height over the surface divided by the steepest the furrowed surface can rise, never less than a
// range-proportional minimum; then it bisects the last step.

#include <cstdint>
#include <vector>

#include "sim/geometry.hpp"

namespace fieldguard::sim {

struct Undulation {
  double amplitude_m = 0.0;
  double wavelength_m = 100.0;
  double heading_deg = 0.0;  // direction of the wave vector
  double phase_rad = 0.0;
};

struct TerrainParams {
  double grade_x = 0.0;  // dz/dx of the base plane
  double grade_y = 0.0;  // dz/dy
  // A change of slope: from about rise_start_x on, the ground climbs an extra rise_grade (dz/dx),
  // blended in over rise_width_m.
  double rise_start_x = 1e9;
  double rise_grade = 0.0;
  double rise_width_m = 8.0;
  std::vector<Undulation> undulations;
  double furrow_period_m = 0.75;
  double furrow_amplitude_m = 0.0;  // half the crest-to-trough height
  double furrow_heading_deg = 0.0;  // direction the furrows run (0 = along x)
  double furrow_variation = 0.3;    // relative amplitude variation, smooth over a few metres
};

struct TerrainExtent {
  double x_min = -120.0;
  double x_max = 120.0;
  double y_min = -120.0;
  double y_max = 120.0;
};

class Terrain {
 public:
  Terrain() = default;
  Terrain(const TerrainParams& params, const TerrainExtent& extent, std::uint64_t seed);

  [[nodiscard]] double base(double x, double y) const;    // smooth ground, no furrows
  [[nodiscard]] double height(double x, double y) const;  // surface including furrows
  [[nodiscard]] Vec3 normal(double x, double y) const;    // upward unit normal of the surface
  // Nearest surface hit in (0, tmax); false if none.
  [[nodiscard]] bool intersect(const Ray& ray, double tmax, double& t_hit) const;
  // Steepest slope of the base (used by callers that march over base-relative layers, e.g. crops).
  [[nodiscard]] double base_slope_bound() const { return base_slope_; }
  [[nodiscard]] double furrow_bound() const { return envelope_; }

 private:
  struct Cell {
    double base;
    double amp;
  };
  struct Sample {
    double base;
    double amp;  // furrow amplitude here
  };
  [[nodiscard]] Sample sample(double x, double y) const;
  [[nodiscard]] double furrow(double x, double y) const;  // profile in [-1, 1]
  [[nodiscard]] double refine(const Ray& ray, double lo, double hi, double f_hi) const;
  [[nodiscard]] double analytic_base(double x, double y) const;

  TerrainParams params_;
  TerrainExtent extent_;
  int nx_ = 0;
  int ny_ = 0;
  std::vector<Cell> grid_;       // (nx_ x ny_) nodes, 1 m apart
  std::vector<double> profile_;  // one furrow period, kProfileSize + 1 samples in [-1, 1]
  double dir_x_ = 0.0;           // unit vector across the furrows
  double dir_y_ = 1.0;
  double base_slope_ = 0.0;     // bound on |grad base|
  double surface_slope_ = 0.0;  // bound on |grad height|
  double envelope_ = 0.0;       // bound on |height - base|
};

}  // namespace fieldguard::sim
