#include "sim/terrain.hpp"

#include <algorithm>
#include <cmath>

#include "sim/rng.hpp"

namespace fieldguard::sim {

namespace {

constexpr int kProfileSize = 512;
constexpr double kCellM = 1.0;
constexpr double kNoiseCellM = 4.0;  // furrow amplitude varies over this scale

// Smooth value noise in [-1, 1]: random values on a kNoiseCellM lattice, smoothstep-interpolated.
double value_noise(std::uint64_t seed, double x, double y) {
  const double gx = x / kNoiseCellM;
  const double gy = y / kNoiseCellM;
  const double fx0 = std::floor(gx);
  const double fy0 = std::floor(gy);
  const auto ix = static_cast<std::int64_t>(fx0);
  const auto iy = static_cast<std::int64_t>(fy0);
  auto node = [&](std::int64_t i, std::int64_t j) {
    const std::uint64_t h = hash64(seed, static_cast<std::uint64_t>(i), static_cast<std::uint64_t>(j));
    return static_cast<double>(h >> 11U) * 0x1.0p-52 - 1.0;
  };
  auto smooth = [](double u) { return u * u * (3.0 - 2.0 * u); };
  const double u = smooth(gx - fx0);
  const double v = smooth(gy - fy0);
  const double a = node(ix, iy) + (node(ix + 1, iy) - node(ix, iy)) * u;
  const double b = node(ix, iy + 1) + (node(ix + 1, iy + 1) - node(ix, iy + 1)) * u;
  return a + (b - a) * v;
}

double softplus(double u) { return u > 30.0 ? u : std::log1p(std::exp(u)); }

}  // namespace

Terrain::Terrain(const TerrainParams& params, const TerrainExtent& extent, std::uint64_t seed)
    : params_(params), extent_(extent) {
  nx_ = static_cast<int>(std::ceil((extent.x_max - extent.x_min) / kCellM)) + 1;
  ny_ = static_cast<int>(std::ceil((extent.y_max - extent.y_min) / kCellM)) + 1;
  grid_.resize(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_));
  const std::uint64_t noise_seed = hash64(seed, 0x7e44a1);
  double max_amp = 0.0;
  for (int j = 0; j < ny_; ++j) {
    for (int i = 0; i < nx_; ++i) {
      const double x = extent.x_min + kCellM * i;
      const double y = extent.y_min + kCellM * j;
      const double amp =
          params.furrow_amplitude_m * std::max(0.0, 1.0 + params.furrow_variation * value_noise(noise_seed, x, y));
      grid_[static_cast<std::size_t>(j) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(i)] =
          Cell{analytic_base(x, y), amp};
      max_amp = std::max(max_amp, amp);
    }
  }
  // Furrow profile: rounded crests, a steeper flank on one side (a plough turns the soil one way).
  profile_.resize(kProfileSize + 1);
  double peak = 0.0;
  for (int k = 0; k <= kProfileSize; ++k) {
    const double phi = 2.0 * kPi * k / kProfileSize;
    const double v = std::cos(phi) + 0.3 * std::cos(2.0 * phi + 0.5);
    profile_[static_cast<std::size_t>(k)] = v;
    peak = std::max(peak, std::abs(v));
  }
  double max_dp = 0.0;
  for (int k = 0; k <= kProfileSize; ++k) profile_[static_cast<std::size_t>(k)] /= peak;
  for (int k = 0; k < kProfileSize; ++k) {
    const auto uk = static_cast<std::size_t>(k);
    max_dp = std::max(max_dp, std::abs(profile_[uk + 1] - profile_[uk]) * kProfileSize);
  }
  const double heading = params.furrow_heading_deg * kDegToRad;
  dir_x_ = -std::sin(heading);
  dir_y_ = std::cos(heading);

  // Slope bounds from the grid (bilinear interpolation never exceeds its edge differences).
  double max_base = 0.0;
  double max_amp_grad = 0.0;
  for (int j = 0; j + 1 < ny_; ++j) {
    for (int i = 0; i + 1 < nx_; ++i) {
      const auto at = [&](int a, int b) -> const Cell& {
        return grid_[static_cast<std::size_t>(b) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(a)];
      };
      const double gx =
          std::max(std::abs(at(i + 1, j).base - at(i, j).base), std::abs(at(i + 1, j + 1).base - at(i, j + 1).base));
      const double gy =
          std::max(std::abs(at(i, j + 1).base - at(i, j).base), std::abs(at(i + 1, j + 1).base - at(i + 1, j).base));
      max_base = std::max(max_base, std::hypot(gx, gy));
      const double ax =
          std::max(std::abs(at(i + 1, j).amp - at(i, j).amp), std::abs(at(i + 1, j + 1).amp - at(i, j + 1).amp));
      const double ay =
          std::max(std::abs(at(i, j + 1).amp - at(i, j).amp), std::abs(at(i + 1, j + 1).amp - at(i + 1, j).amp));
      max_amp_grad = std::max(max_amp_grad, std::hypot(ax, ay));
    }
  }
  base_slope_ = max_base / kCellM * 1.02 + 1e-3;
  envelope_ = max_amp * 1.001;
  surface_slope_ = base_slope_ + max_amp * max_dp / params.furrow_period_m + max_amp_grad / kCellM + 1e-3;
}

double Terrain::analytic_base(double x, double y) const {
  double z = params_.grade_x * x + params_.grade_y * y;
  if (params_.rise_grade != 0.0) {
    const double w = params_.rise_width_m;
    z += params_.rise_grade * w * softplus((x - params_.rise_start_x) / w);
  }
  for (const Undulation& u : params_.undulations) {
    const double h = u.heading_deg * kDegToRad;
    const double s = x * std::cos(h) + y * std::sin(h);
    z += u.amplitude_m * std::sin(2.0 * kPi * s / u.wavelength_m + u.phase_rad);
  }
  return z;
}

Terrain::Sample Terrain::sample(double x, double y) const {
  const double gx = std::clamp((x - extent_.x_min) / kCellM, 0.0, static_cast<double>(nx_ - 1) - 1e-9);
  const double gy = std::clamp((y - extent_.y_min) / kCellM, 0.0, static_cast<double>(ny_ - 1) - 1e-9);
  const double fx = std::floor(gx);
  const double fy = std::floor(gy);
  const auto i = static_cast<std::size_t>(fx);
  const auto j = static_cast<std::size_t>(fy);
  const double u = gx - fx;
  const double v = gy - fy;
  const auto row = static_cast<std::size_t>(nx_);
  const Cell& c00 = grid_[j * row + i];
  const Cell& c10 = grid_[j * row + i + 1];
  const Cell& c01 = grid_[(j + 1) * row + i];
  const Cell& c11 = grid_[(j + 1) * row + i + 1];
  const double w00 = (1.0 - u) * (1.0 - v);
  const double w10 = u * (1.0 - v);
  const double w01 = (1.0 - u) * v;
  const double w11 = u * v;
  const double base = c00.base * w00 + c10.base * w10 + c01.base * w01 + c11.base * w11;
  const double amp = c00.amp * w00 + c10.amp * w10 + c01.amp * w01 + c11.amp * w11;
  return {base, amp};
}

double Terrain::furrow(double x, double y) const {
  const double across = (x * dir_x_ + y * dir_y_) / params_.furrow_period_m;
  const double phase = (across - std::floor(across)) * kProfileSize;
  const double pf = std::floor(phase);
  const auto k = std::min(static_cast<std::size_t>(pf), static_cast<std::size_t>(kProfileSize - 1));
  return profile_[k] + (profile_[k + 1] - profile_[k]) * (phase - pf);
}

double Terrain::base(double x, double y) const { return sample(x, y).base; }
double Terrain::height(double x, double y) const {
  const Sample s = sample(x, y);
  return s.amp == 0.0 ? s.base : s.base + s.amp * furrow(x, y);
}

Vec3 Terrain::normal(double x, double y) const {
  constexpr double e = 0.04;
  const double h = height(x, y);
  const double dx = (height(x + e, y) - h) / e;
  const double dy = (height(x, y + e) - h) / e;
  return normalized({-dx, -dy, 1.0});
}

double Terrain::refine(const Ray& ray, double lo, double hi, double f_hi) const {
  // Regula falsi (Illinois) between a point above the surface (lo) and one below it (hi).
  const Vec3 q0 = ray.origin + ray.dir * lo;
  double f_lo = q0.z - height(q0.x, q0.y);
  int side = 0;
  for (int k = 0; k < 24 && hi - lo > 5e-3; ++k) {
    const double mid = f_lo > f_hi ? lo + (hi - lo) * f_lo / (f_lo - f_hi) : 0.5 * (lo + hi);
    const Vec3 q = ray.origin + ray.dir * mid;
    const double fm = q.z - height(q.x, q.y);
    if (std::abs(fm) < 1e-3) return mid;  // 1 mm off the surface: far below the range noise
    if (fm > 0.0) {
      lo = mid;
      f_lo = fm;
      if (side == 1) f_hi *= 0.5;
      side = 1;
    } else {
      hi = mid;
      f_hi = fm;
      if (side == -1) f_lo *= 0.5;
      side = -1;
    }
  }
  return hi;
}

bool Terrain::intersect(const Ray& ray, double tmax, double& t_hit) const {
  const Vec3 o = ray.origin;
  const Vec3 d = ray.dir;
  const double dxy = std::sqrt(d.x * d.x + d.y * d.y);
  const double climb_far = -d.z + base_slope_ * dxy;      // how fast the ray can close on the envelope
  const double climb_near = -d.z + surface_slope_ * dxy;  // ... on the surface
  if (climb_far <= 1e-9) return false;                    // the ray rises faster than the ground ever can
  auto min_step = [](double t) { return std::max(0.02, 0.003 * t); };
  // Inside the furrow envelope: at least ~10 cm of ground or 4 cm of height per sample (a crest narrower
  // than that can be clipped; the range noise is larger than what that changes).
  const double near_step = std::min(dxy > 1e-9 ? 0.10 / dxy : kInf, std::abs(d.z) > 1e-9 ? 0.04 / std::abs(d.z) : kInf);
  double t = 0.0;
  double t_prev = 0.0;
  double g_prev = -1.0;  // height over the envelope at t_prev while above it
  for (int iter = 0; iter < 4000 && t < tmax; ++iter) {
    const Vec3 p = o + d * t;
    const Sample s = sample(p.x, p.y);
    const double g = p.z - s.base - envelope_;
    if (g > 0.0) {
      // The safe step, or 90% of the way to where the last two samples say the envelope is (the base is
      // smooth, so that is close; landing inside the envelope is caught below and refined).
      double step = std::max(g / climb_far, min_step(t));
      if (g_prev > g) step = std::max(step, 0.9 * g * (t - t_prev) / (g_prev - g));
      g_prev = g;
      t_prev = t;
      t += step;
      continue;
    }
    g_prev = -1.0;
    const double f = s.amp == 0.0 ? p.z - s.base : p.z - s.base - s.amp * furrow(p.x, p.y);
    if (f <= 0.0) {
      t_hit = refine(ray, t_prev, t, f);
      return t_hit > 0.0 && t_hit < tmax;
    }
    t_prev = t;
    t += std::max({f / climb_near, near_step, min_step(t)});
  }
  return false;
}

}  // namespace fieldguard::sim
