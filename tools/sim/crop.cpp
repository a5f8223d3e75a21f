#include "sim/crop.hpp"

#include <algorithm>
#include <cmath>

namespace fieldguard::sim {

namespace {
constexpr double kCanopyCellM = 3.0;
}  // namespace

CropBlock::CropBlock(const CropParams& params, const Terrain& terrain, std::uint64_t seed)
    : params_(params), seed_(hash64(seed, 0xc409)) {
  for (double x = params.x_min; x <= params.x_max + 0.5; x += 1.0) {
    for (double y = params.y_min; y <= params.y_max + 0.5; y += 1.0) {
      const double cx = std::min(x, params.x_max);
      const double cy = std::min(y, params.y_max);
      const double g = terrain.base(cx, cy);
      bounds_.add(Vec3{cx, cy, g - terrain.furrow_bound()});
      bounds_.add(Vec3{cx, cy, g + canopy_height(cx, cy)});
    }
  }
  // Canopy height varies by (max - min) over one lattice cell at most.
  slope_bound_ = terrain.base_slope_bound() + 1.5 * (params.height_max_m - params.height_min_m) / kCanopyCellM;
}

double CropBlock::canopy_height(double x, double y) const {
  const double gx = x / kCanopyCellM;
  const double gy = y / kCanopyCellM;
  const double fx = std::floor(gx);
  const double fy = std::floor(gy);
  auto node = [&](double i, double j) {
    const std::uint64_t h = hash64(seed_, static_cast<std::uint64_t>(static_cast<std::int64_t>(i)),
                                   static_cast<std::uint64_t>(static_cast<std::int64_t>(j)));
    return static_cast<double>(h >> 11U) * 0x1.0p-53;
  };
  auto smooth = [](double u) { return u * u * (3.0 - 2.0 * u); };
  const double u = smooth(gx - fx);
  const double v = smooth(gy - fy);
  const double a = node(fx, fy) + (node(fx + 1, fy) - node(fx, fy)) * u;
  const double b = node(fx, fy + 1) + (node(fx + 1, fy + 1) - node(fx, fy + 1)) * u;
  return params_.height_min_m + (params_.height_max_m - params_.height_min_m) * (a + (b - a) * v);
}

bool CropBlock::intersect(const Ray& ray, const Terrain& terrain, double tmin, double tmax, Rng& rng,
                          double& t_hit) const {
  // Clip the ray to the rectangle in x-y.
  double ta = tmin;
  double tb = tmax;
  const std::array<double, 2> o{ray.origin.x, ray.origin.y};
  const std::array<double, 2> d{ray.dir.x, ray.dir.y};
  const std::array<double, 2> lo{params_.x_min, params_.y_min};
  const std::array<double, 2> hi{params_.x_max, params_.y_max};
  for (std::size_t a = 0; a < 2; ++a) {
    if (std::abs(d[a]) < 1e-12) {
      if (o[a] < lo[a] || o[a] > hi[a]) return false;
      continue;
    }
    double t0 = (lo[a] - o[a]) / d[a];
    double t1 = (hi[a] - o[a]) / d[a];
    if (t0 > t1) std::swap(t0, t1);
    ta = std::max(ta, t0);
    tb = std::min(tb, t1);
  }
  if (ta >= tb) return false;
  if (ray.origin.z + ray.dir.z * ta > bounds_.max.z && ray.dir.z >= 0.0) return false;
  // March to the canopy top.
  const double dxy = std::hypot(ray.dir.x, ray.dir.y);
  const double closing = -ray.dir.z + slope_bound_ * dxy;
  double t = ta;
  for (int iter = 0; iter < 2000; ++iter) {
    if (t >= tb) return false;
    const Vec3 p = ray.origin + ray.dir * t;
    const double above = p.z - (terrain.base(p.x, p.y) + canopy_height(p.x, p.y));
    if (above <= 0.0) break;
    if (closing <= 1e-9) return false;
    t += std::max(above / closing, 0.02);
  }
  const double t_stop = t + rng.exponential(params_.mean_free_path_m);
  if (t_stop >= std::min(tb, tmax)) return false;
  const Vec3 q = ray.origin + ray.dir * t_stop;
  if (q.z > terrain.base(q.x, q.y) + canopy_height(q.x, q.y)) return false;  // left through the top
  t_hit = t_stop;
  return true;
}

}  // namespace fieldguard::sim
