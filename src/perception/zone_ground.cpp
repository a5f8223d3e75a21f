#include "fieldguard/perception/zone_ground.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "perception/fast_math.hpp"
#include "perception/simd.hpp"

namespace fieldguard::perception {
namespace {

// Weight of the prior slope in a bin's least-squares fit, per point (m^2, the units of (x - mean_x)^2): the
// data's slope counts as much as the prior's where the points spread 1 m (standard deviation) in that direction.
// A slope from a short baseline (one scan ring's arc across furrows) is not worth extrapolating 20 m.
constexpr double kBinPriorPerPoint = 1.0;
// The innermost ring's plane sees the ground all round the vehicle: its data rules.
constexpr double kInnermostPriorPerPoint = 0.01;
// Below this distance between a bin's points and where its prior was fitted, no secant slope is taken (m).
constexpr float kSecantMin_m = 2.0F;
// Refit band above the plane, as a fraction of fit_distance_m (below it: the whole distance).
constexpr float kUpperBand = 0.5F;
// The innermost ring's plane: fitted to the points within these bands of the plane so far, in turn.
constexpr float kInnermostBands[] = {0.5F, 0.3F, 0.15F};
constexpr std::uint32_t kInnermostMinPoints = 10;

}  // namespace

// Least squares z = a x + b y + c over the gathered bin points whose residual to `sel` lies in [lo, hi),
// with the slope pulled towards `prior`'s by prior_per_point for each point used. Four points at a time,
// branch-free, in float about the bin's first point (a bin spans metres: no cancellation to fear); the
// gathered arrays are padded to a multiple of four with points that are never selected.
ZoneGround::Fit ZoneGround::least_squares(const GroundPlane& sel, float lo, float hi, const GroundPlane& prior,
                                          double prior_per_point) const {
  using simd::f32x4;
  using simd::i32x4;
  Fit f;
  if (bin_n_ == 0) return f;
  const float ox = bx_[0], oy = by_[0], oz = bz_[0];
  const f32x4 vox = simd::splat(ox), voy = simd::splat(oy), voz = simd::splat(oz);
  const f32x4 sa = simd::splat(sel.a), sb = simd::splat(sel.b), sc = simd::splat(sel.c);
  const f32x4 vlo = simd::splat(lo), vhi = simd::splat(hi);
  const f32x4 zero = simd::splat(0.F);
  f32x4 n = zero, sx = zero, sy = zero, sz = zero, sxx = zero, sxy = zero, syy = zero, sxz = zero, syz = zero;
  const f32x4 big = simd::splat(std::numeric_limits<float>::max());
  f32x4 x0 = big, x1 = -big, y0 = big, y1 = -big;
  for (std::size_t i = 0; i < bx_.size(); i += 4) {
    const f32x4 x = simd::load(bx_.data() + i), y = simd::load(by_.data() + i), z = simd::load(bz_.data() + i);
    const f32x4 r = z - (sa * x + sb * y + sc);
    const i32x4 in = (r >= vlo) & (r < vhi);
    const f32x4 w = __builtin_convertvector(-in, f32x4);  // 1 where selected, 0 elsewhere
    const f32x4 dx = (x - vox) * w, dy = (y - voy) * w, dz = (z - voz) * w;
    n += w;
    sx += dx;
    sy += dy;
    sz += dz;
    sxx += dx * dx;
    sxy += dx * dy;
    syy += dy * dy;
    sxz += dx * dz;
    syz += dy * dz;
    x0 = in ? (x < x0 ? x : x0) : x0;
    x1 = in ? (x > x1 ? x : x1) : x1;
    y0 = in ? (y < y0 ? y : y0) : y0;
    y1 = in ? (y > y1 ? y : y1) : y1;
  }
  const auto sum = [](f32x4 v) {
    return static_cast<double>(v[0]) + static_cast<double>(v[1]) + static_cast<double>(v[2]) +
           static_cast<double>(v[3]);
  };
  const double cnt = sum(n);
  if (cnt < 1.0) return f;
  const double mx = sum(sx) / cnt, my = sum(sy) / cnt, mz = sum(sz) / cnt;
  const double w = prior_per_point * cnt;
  const double cxx = sum(sxx) - sum(sx) * mx + w;
  const double cyy = sum(syy) - sum(sy) * my + w;
  const double cxy = sum(sxy) - sum(sx) * my;
  const double rx = sum(sxz) - sum(sx) * mz + w * static_cast<double>(prior.a);
  const double ry = sum(syz) - sum(sy) * mz + w * static_cast<double>(prior.b);
  const double det = cxx * cyy - cxy * cxy;
  const double a = (rx * cyy - cxy * ry) / det;
  const double b = (cxx * ry - cxy * rx) / det;
  const double gx = mx + static_cast<double>(ox), gy = my + static_cast<double>(oy);
  const double c = (mz + static_cast<double>(oz)) - a * gx - b * gy;
  f.plane = GroundPlane{static_cast<float>(a), static_cast<float>(b), static_cast<float>(c)};
  f.mean_x = static_cast<float>(gx);
  f.mean_y = static_cast<float>(gy);
  f.count = static_cast<std::uint32_t>(cnt);
  const float ex = std::max({x1[0], x1[1], x1[2], x1[3]}) - std::min({x0[0], x0[1], x0[2], x0[3]});
  const float ey = std::max({y1[0], y1[1], y1[2], y1[3]}) - std::min({y0[0], y0[1], y0[2], y0[3]});
  f.spread = std::sqrt(ex * ex + ey * ey);
  return f;
}

// Gathers the points order_[k0, k1) into bx_, by_, bz_, padded to a multiple of four with points that no
// selection takes (a million metres above the first).
void ZoneGround::gather(const Cloud& in, std::uint32_t k0, std::uint32_t k1) {
  const std::size_t m = k1 - k0;
  const std::size_t padded = (m + 3) & ~std::size_t{3};
  bin_n_ = m;
  bx_.resize(padded);
  by_.resize(padded);
  bz_.resize(padded);
  for (std::size_t j = 0; j < m; ++j) {
    const std::uint32_t i = order_[k0 + j];
    bx_[j] = in.x[i];
    by_[j] = in.y[i];
    bz_[j] = in.z[i];
  }
  for (std::size_t j = m; j < padded; ++j) {
    bx_[j] = bx_[0];
    by_[j] = by_[0];
    bz_[j] = bz_[0] + 1e6F;
  }
}

GroundPlane ZoneGround::fit_innermost(const Cloud& in) {
  const GroundPlane level{0.F, 0.F, -sensor_height_m_};
  const Zone& z = zones_[0];
  const std::uint32_t b0 = z.first_bin, b1 = z.first_bin + z.sectors;
  GroundPlane plane = level;
  if (bin_start_[b1] == bin_start_[b0]) return level;
  gather(in, bin_start_[b0], bin_start_[b1]);
  for (const float band : kInnermostBands) {
    const Fit f = least_squares(plane, -band, band, level, kInnermostPriorPerPoint);
    if (f.count < kInnermostMinPoints) break;
    plane = f.plane;
  }
  const float max_tilt = tan_max_tilt_;
  if (plane.a * plane.a + plane.b * plane.b > max_tilt * max_tilt) return level;
  // The sensor height it implies must be plausible too.
  if (std::fabs(plane.c + sensor_height_m_) > static_cast<float>(params_.max_step_m) + 2.F * max_tilt) return level;
  return plane;
}

void ZoneGround::fit_bin(std::uint32_t bin, const Bin& prior) {
  Bin& out = bins_[bin];
  out.plane = prior.plane;
  out.ref_x = prior.ref_x;
  out.ref_y = prior.ref_y;
  out.fitted = false;
  const std::size_t m = bin_n_;
  if (m < static_cast<std::size_t>(std::max(params_.min_bin_points, 3))) return;

  // Seeds: the lowest points along the prior's slope.
  const GroundPlane slope{prior.plane.a, prior.plane.b, 0.F};
  resid_.resize(m);
  for (std::size_t i = 0; i < m; ++i) resid_[i] = bz_[i] - slope.z_at(bx_[i], by_[i]);
  tmp_.assign(resid_.begin(), resid_.end());
  const std::size_t lowest = std::clamp<std::size_t>(static_cast<std::size_t>(std::max(params_.seed_lowest, 1)), 1, m);
  std::nth_element(tmp_.begin(), tmp_.begin() + static_cast<std::ptrdiff_t>(lowest - 1), tmp_.end());
  float sum = 0.F;
  for (std::size_t i = 0; i < lowest; ++i) sum += tmp_[i];
  const float seed_hi = sum / static_cast<float>(lowest) + static_cast<float>(params_.seed_margin_m);

  Fit f = least_squares(slope, -std::numeric_limits<float>::max(), seed_hi, prior.plane, kBinPriorPerPoint);
  if (f.count < 3) return;
  // The slope the refits lean on: the prior's, but along the line from where the prior was fitted to these
  // points, the rise between the two (the secant). A bin seen by one scan ring cannot tell its own slope across
  // the ring, and far out the rings are metres apart: their heights are what tells how the ground bends.
  GroundPlane guide = prior.plane;
  {
    const float dx = f.mean_x - prior.ref_x, dy = f.mean_y - prior.ref_y;
    const float dist = std::sqrt(dx * dx + dy * dy);
    if (dist > kSecantMin_m) {
      const float ux = dx / dist, uy = dy / dist;
      const float secant = (f.plane.z_at(f.mean_x, f.mean_y) - prior.plane.z_at(prior.ref_x, prior.ref_y)) / dist;
      const float along = prior.plane.a * ux + prior.plane.b * uy;
      guide.a += (secant - along) * ux;
      guide.b += (secant - along) * uy;
    }
  }
  // The ground is the lower envelope: refits take points up to fit_distance below the plane but only half as
  // far above it, so that a ridge's flank or an object's foot does not draw the plane up step by step.
  const auto band = static_cast<float>(params_.fit_distance_m);
  for (int it = 0; it < params_.fit_iterations; ++it) {
    const Fit g = least_squares(f.plane, -band, kUpperBand * band, guide, kBinPriorPerPoint);
    if (g.count < 3) break;
    const bool settled = g.count == f.count;
    f = g;
    if (settled) break;  // the same points again: the same plane
  }

  const float max_slope = tan_max_slope_;
  if (f.plane.a * f.plane.a + f.plane.b * f.plane.b > max_slope * max_slope) return;
  // The slope may bend only so much from the bin inside: a ridge's flank or an object's base is not a slope.
  const float max_change = tan_max_change_;
  const float da = f.plane.a - prior.plane.a, db = f.plane.b - prior.plane.b;
  if (da * da + db * db > max_change * max_change) return;
  if (f.spread < static_cast<float>(params_.min_spread_m)) return;
  const float step = f.plane.z_at(f.mean_x, f.mean_y) - prior.plane.z_at(f.mean_x, f.mean_y);
  const float ddx = f.mean_x - prior.ref_x, ddy = f.mean_y - prior.ref_y;
  const float dist = std::sqrt(ddx * ddx + ddy * ddy);
  const float allowed = static_cast<float>(params_.max_step_m) + dist * max_change;
  if (std::fabs(step) > allowed) return;
  // A ground plane is the lower envelope of its bin's returns. One with a return of its own bin far below it
  // was fitted to something standing there: behind a tree row only the near-horizontal lasers reach the next
  // row's crowns, and their returns make a flat, wide "ground" a metre up, with a lower laser's return under it.
  if (params_.max_below_m > 0.0) {
    const float deepest = -static_cast<float>(params_.max_below_m);
    for (std::size_t i = 0; i < m; ++i) {
      if (bz_[i] - f.plane.z_at(bx_[i], by_[i]) < deepest) return;
    }
  }
  out.plane = f.plane;
  out.ref_x = f.mean_x;
  out.ref_y = f.mean_y;
  out.fitted = true;
}

// A bin without its own plane lies between fitted bins (HDL-32E rings reach flat ground 7 m apart at 20 m,
// and 20 m apart beyond): it gets the planes around it blended by inverse distance from its centre to where
// each was fitted: the plane continued from inside (pass one), the first fitted bin outside it, and the
// nearest fitted bin within kLateral sectors on either side in its ring. Extrapolating the inner plane alone
// carries that plane's slope error out to the edge of the region (a climb that starts at 20 m is a metre
// off at 50 m).
void ZoneGround::interpolate_gaps() {
  constexpr std::uint32_t kLateral = 2;
  constexpr float kMinDistance = 0.5F;  // m: no neighbour weighs more than one this near
  filled_.resize(bins_.size());
  for (auto& b : bins_) b.support_m = 0.F;
  for (std::uint32_t zi = 0; zi < zones_.size(); ++zi) {
    const Zone& z = zones_[zi];
    for (std::uint32_t ring = 0; ring < z.rings; ++ring) {
      const std::uint32_t ring_first = z.first_bin + ring * z.sectors;
      for (std::uint32_t s = 0; s < z.sectors; ++s) {
        const std::uint32_t b = ring_first + s;
        filled_[b] = bins_[b].plane;
        if (bins_[b].fitted) continue;
        const float cx = bins_[b].center_x, cy = bins_[b].center_y;
        float wa = 0.F, wb = 0.F, wc = 0.F, wsum = 0.F;
        float nearest = std::numeric_limits<float>::max();
        const auto blend = [&](const Bin& n) {
          const float dx = cx - n.ref_x, dy = cy - n.ref_y;
          const float d = std::sqrt(dx * dx + dy * dy);
          nearest = std::min(nearest, d);
          const float w = 1.F / std::max(kMinDistance, d);
          wa += w * n.plane.a;
          wb += w * n.plane.b;
          wc += w * n.plane.c;
          wsum += w;
        };
        blend(bins_[b]);  // continued from inside
        std::uint32_t outer = outer_[b];
        while (outer != kNoBin && !bins_[outer].fitted) outer = outer_[outer];
        if (outer != kNoBin) blend(bins_[outer]);
        for (const std::uint32_t step : {1U, z.sectors - 1U}) {  // one way round, then the other
          if (z.sectors < 2) break;
          std::uint32_t t = s;
          for (std::uint32_t k = 0; k < kLateral; ++k) {
            t = (t + step) % z.sectors;
            if (t == s) break;
            if (bins_[ring_first + t].fitted) {
              blend(bins_[ring_first + t]);
              break;
            }
          }
        }
        filled_[b] = GroundPlane{wa / wsum, wb / wsum, wc / wsum};
        bins_[b].support_m = nearest;
      }
    }
  }
  for (std::size_t b = 0; b < bins_.size(); ++b) bins_[b].plane = filled_[b];
}

// The ground under (x, y) in `bin`: between where its plane was fitted and where the plane of the bin beyond
// it on the point's side (outside it when the point lies farther out than that, else inside) was fitted, the
// two planes interpolated by distance, as a ring's measured ground gives way to the next ring's. A neighbour
// without a plane of its own does not count (its plane is a blend already).
float ZoneGround::blended_z(std::uint32_t bin, float x, float y) const {
  const Bin& own = bins_[bin];
  const float z_own = own.plane.z_at(x, y);
  const float r2 = x * x + y * y, ref_r2 = own.ref_x * own.ref_x + own.ref_y * own.ref_y;
  const std::uint32_t nb = r2 >= ref_r2 ? outer_[bin] : inner_[bin];
  if (nb == kNoBin || !bins_[nb].fitted) return z_own;
  const Bin& other = bins_[nb];
  const float d_own = std::hypot(x - own.ref_x, y - own.ref_y);
  const float d_other = std::hypot(x - other.ref_x, y - other.ref_y);
  const float sum = d_own + d_other;
  if (!(sum > 0.F)) return z_own;
  return (d_other * z_own + d_own * other.plane.z_at(x, y)) / sum;
}

void ZoneGround::segment(const Cloud& in, GroundLabels& out) {
  const std::size_t n = in.size();
  const std::size_t nbins = bins_.size();
  out.resize(n);
  bin_of_point_.resize(n);
  bin_start_.assign(nbins + 1, 0U);
  // Range and angle four points at a time (the same arithmetic as bin_of, lane by lane).
  std::size_t p = 0;
  for (; p + 4 <= n; p += 4) {
    const simd::f32x4 x = simd::load(in.x.data() + p), y = simd::load(in.y.data() + p);
    const simd::f32x4 r2 = x * x + y * y;
    const simd::f32x4 r = {std::sqrt(r2[0]), std::sqrt(r2[1]), std::sqrt(r2[2]), std::sqrt(r2[3])};
    const simd::f32x4 theta = fast_atan2(y, x);
    for (int k = 0; k < 4; ++k) {
      const std::uint32_t b = bin_of_polar(r[k], theta[k]);
      bin_of_point_[p + static_cast<std::size_t>(k)] = b;
      ++bin_start_[b + 1];
    }
  }
  for (; p < n; ++p) {
    const std::uint32_t b = bin_of(in.x[p], in.y[p]);
    bin_of_point_[p] = b;
    ++bin_start_[b + 1];
  }
  for (std::size_t b = 0; b < nbins; ++b) bin_start_[b + 1] += bin_start_[b];
  order_.resize(n);
  tmp_.clear();
  {
    // Counting sort of the point indices by bin (stable: input order within a bin).
    Buffer<std::uint32_t>& cursor = cursor_;
    cursor.assign(bin_start_.begin(), bin_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order_[cursor[bin_of_point_[i]]++] = static_cast<std::uint32_t>(i);
  }

  Bin innermost;
  innermost.plane = fit_innermost(in);
  innermost.fitted = true;

  for (std::uint32_t zi = 0; zi < zones_.size(); ++zi) {
    const Zone& z = zones_[zi];
    for (std::uint32_t ring = 0; ring < z.rings; ++ring) {
      for (std::uint32_t s = 0; s < z.sectors; ++s) {
        const std::uint32_t b = z.first_bin + ring * z.sectors + s;
        gather(in, bin_start_[b], bin_start_[b + 1]);
        const Bin prior = (zi == 0 && ring == 0) ? innermost : bins_[inner_[b]];
        fit_bin(b, prior);
      }
    }
  }

  interpolate_gaps();

  const auto threshold = static_cast<float>(params_.ground_threshold_m);
  const auto guess = static_cast<float>(params_.max_extrapolation_m);
  const bool blend = params_.blend_radial;
  for (std::size_t i = 0; i < n; ++i) {
    const Bin& bin = bins_[bin_of_point_[i]];
    const float g = blend ? blended_z(bin_of_point_[i], in.x[i], in.y[i]) : bin.plane.z_at(in.x[i], in.y[i]);
    const float h = in.z[i] - g;
    out.height_m[i] = h;
    out.ground[i] = h < threshold ? 1U : 0U;
    out.guessed[i] = bin.support_m > guess ? 1U : 0U;
  }
}

}  // namespace fieldguard::perception
