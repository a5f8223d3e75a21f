#include "fieldguard/perception/zone_ground.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "perception/hypot.hpp"
#include "perception/nth_element.hpp"
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

// Least squares z = a x + b y + c over the points pts_ whose residual to `sel` lies in [lo, hi),
// with the slope pulled towards `prior`'s by prior_per_point for each point used. Four points at a time,
// branch-free, in float about the first point (a bin spans metres: no cancellation to fear); pts_ is padded to
// a multiple of four with points that are never selected.
ZoneGround::Fit ZoneGround::least_squares(const GroundPlane& sel, float lo, float hi, const GroundPlane& prior,
                                          double prior_per_point) const {
  using simd::f32x4;
  using simd::i32x4;
  Fit f;
  if (pts_.n == 0) return f;
  const float ox = pts_.x[0], oy = pts_.y[0], oz = pts_.z[0];
  const f32x4 vox = simd::splat(ox), voy = simd::splat(oy), voz = simd::splat(oz);
  const f32x4 sa = simd::splat(sel.a), sb = simd::splat(sel.b), sc = simd::splat(sel.c);
  const f32x4 vlo = simd::splat(lo), vhi = simd::splat(hi);
  const f32x4 zero = simd::splat(0.F);
  f32x4 n = zero, sx = zero, sy = zero, sz = zero, sxx = zero, sxy = zero, syy = zero, sxz = zero, syz = zero;
  for (std::size_t i = 0; i < pts_.padded; i += 4) {
    const f32x4 x = simd::load(pts_.x + i), y = simd::load(pts_.y + i), z = simd::load(pts_.z + i);
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
  f.sel = sel;
  f.lo = lo;
  f.hi = hi;
  return f;
}

// The diagonal of the x-y box of the points `f` was fitted to (the same selection again). Apart from
// least_squares: of a bin's several fits only the last one's is looked at, and only for a bin that passed the
// slope tests. In the same pass, whether any point of pts_ lies more than `deepest` below f.plane (into `below`;
// -inf: none ever does), the last test fit_bin makes, on the points already loaded.
float ZoneGround::spread(const Fit& f, float deepest, bool& below) const {
  using simd::f32x4;
  using simd::i32x4;
  const f32x4 sa = simd::splat(f.sel.a), sb = simd::splat(f.sel.b), sc = simd::splat(f.sel.c);
  const f32x4 vlo = simd::splat(f.lo), vhi = simd::splat(f.hi);
  const f32x4 pa = simd::splat(f.plane.a), pb = simd::splat(f.plane.b), pc = simd::splat(f.plane.c);
  const f32x4 vdeep = simd::splat(deepest);
  const f32x4 big = simd::splat(std::numeric_limits<float>::max());
  f32x4 x0 = big, x1 = -big, y0 = big, y1 = -big;
  i32x4 deep = simd::splat(0);
  for (std::size_t i = 0; i < pts_.padded; i += 4) {
    const f32x4 x = simd::load(pts_.x + i), y = simd::load(pts_.y + i), z = simd::load(pts_.z + i);
    const f32x4 r = z - (sa * x + sb * y + sc);
    const i32x4 in = (r >= vlo) & (r < vhi);
    x0 = in ? (x < x0 ? x : x0) : x0;
    x1 = in ? (x > x1 ? x : x1) : x1;
    y0 = in ? (y < y0 ? y : y0) : y0;
    y1 = in ? (y > y1 ? y : y1) : y1;
    deep |= z - (pa * x + pb * y + pc) < vdeep;
  }
  below = simd::mask_bits(deep) != 0U;
  const float ex = std::max({x1[0], x1[1], x1[2], x1[3]}) - std::min({x0[0], x0[1], x0[2], x0[3]});
  const float ey = std::max({y1[0], y1[1], y1[2], y1[3]}) - std::min({y0[0], y0[1], y0[2], y0[3]});
  return std::sqrt(ex * ex + ey * ey);
}

// z - plane.z_at(x, y) for every point of pts_, padding included, into out (pts_.padded floats): four at a
// time, lane by lane the scalar expression's operations in its order, so its bits.
void ZoneGround::residuals(const GroundPlane& plane, float* out) const {
  using simd::f32x4;
  const f32x4 pa = simd::splat(plane.a), pb = simd::splat(plane.b), pc = simd::splat(plane.c);
  for (std::size_t i = 0; i < pts_.padded; i += 4) {
    const f32x4 r = simd::load(pts_.z + i) - (pa * simd::load(pts_.x + i) + pb * simd::load(pts_.y + i) + pc);
    std::memcpy(out + i, &r, sizeof r);
  }
}

// The points into sx_ .. sz_ by bin (input order within one, as a stable counting sort leaves them), each bin's
// run padded to a multiple of four with copies of its first point a million metres up.
void ZoneGround::sort_into_bins(const Cloud& in) {
  const std::size_t n = in.size(), nbins = bins_.size();
  bins_of(in, bin_of_point_);
  bin_count_.assign(nbins, 0U);
  for (std::size_t i = 0; i < n; ++i) ++bin_count_[bin_of_point_[i]];
  bin_start_.resize(nbins + 1);
  bin_start_[0] = 0;
  for (std::size_t b = 0; b < nbins; ++b) bin_start_[b + 1] = bin_start_[b] + ((bin_count_[b] + 3U) & ~3U);
  const std::size_t total = bin_start_[nbins];
  sx_.resize(total);
  sy_.resize(total);
  sz_.resize(total);
  sidx_.resize(total);
  cursor_.assign(bin_start_.begin(), bin_start_.end() - 1);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t k = cursor_[bin_of_point_[i]]++;
    sx_[k] = in.x[i];
    sy_[k] = in.y[i];
    sz_[k] = in.z[i];
    sidx_[k] = static_cast<std::uint32_t>(i);
  }
  for (std::size_t b = 0; b < nbins; ++b) {
    const std::uint32_t first = bin_start_[b];
    for (std::uint32_t k = first + bin_count_[b]; k < bin_start_[b + 1]; ++k) {
      sx_[k] = sx_[first];
      sy_[k] = sy_[first];
      sz_[k] = sz_[first] + 1e6F;
    }
  }
}

// The points of bins [b0, b1) into bx_ .. bz_, one run padded as a bin's is, for pts_.
void ZoneGround::gather_innermost(std::uint32_t b0, std::uint32_t b1) {
  std::size_t m = 0;
  for (std::uint32_t b = b0; b < b1; ++b) m += bin_count_[b];
  const std::size_t padded = (m + 3) & ~std::size_t{3};
  bx_.resize(padded);
  by_.resize(padded);
  bz_.resize(padded);
  std::size_t j = 0;
  for (std::uint32_t b = b0; b < b1; ++b) {
    for (std::uint32_t k = bin_start_[b]; k < bin_start_[b] + bin_count_[b]; ++k, ++j) {
      bx_[j] = sx_[k];
      by_[j] = sy_[k];
      bz_[j] = sz_[k];
    }
  }
  for (; j < padded; ++j) {
    bx_[j] = bx_[0];
    by_[j] = by_[0];
    bz_[j] = bz_[0] + 1e6F;
  }
  pts_ = Points{bx_.data(), by_.data(), bz_.data(), m, padded};
}

GroundPlane ZoneGround::fit_innermost() {
  const GroundPlane level{0.F, 0.F, -sensor_height_m_};
  const Zone& z = zones_[0];
  const std::uint32_t b0 = z.first_bin, b1 = z.first_bin + z.sectors;
  GroundPlane plane = level;
  gather_innermost(b0, b1);
  if (pts_.n == 0) return level;
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
  const std::size_t m = pts_.n;
  if (m < static_cast<std::size_t>(std::max(params_.min_bin_points, 3))) return;

  // Seeds: the lowest points along the prior's slope.
  const GroundPlane slope{prior.plane.a, prior.plane.b, 0.F};
  tmp_.resize(pts_.padded);
  residuals(slope, tmp_.data());  // the padding's too, past m: never looked at
  const std::size_t lowest = std::clamp<std::size_t>(static_cast<std::size_t>(std::max(params_.seed_lowest, 1)), 1, m);
  const auto padded = static_cast<std::uint32_t>(pts_.padded);
  select_scratch_.resize(2 * std::size_t{padded} + 2);
  if (!nth_element_branchfree(tmp_.data(), padded, static_cast<std::uint32_t>(lowest - 1), select_scratch_.data())) {
    residuals(slope, tmp_.data());  // libstdc++ heap-selects here: its own call, on the residuals again
    std::nth_element(tmp_.begin(), tmp_.begin() + static_cast<std::ptrdiff_t>(lowest - 1), tmp_.end());
  }
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
  // The lower-envelope test below, on the points spread() loads anyway.
  const float deepest =
      params_.max_below_m > 0.0 ? -static_cast<float>(params_.max_below_m) : -std::numeric_limits<float>::infinity();
  bool below = false;
  if (spread(f, deepest, below) < static_cast<float>(params_.min_spread_m)) return;
  const float step = f.plane.z_at(f.mean_x, f.mean_y) - prior.plane.z_at(f.mean_x, f.mean_y);
  const float ddx = f.mean_x - prior.ref_x, ddy = f.mean_y - prior.ref_y;
  const float dist = std::sqrt(ddx * ddx + ddy * ddy);
  const float allowed = static_cast<float>(params_.max_step_m) + dist * max_change;
  if (std::fabs(step) > allowed) return;
  // A ground plane is the lower envelope of its bin's returns. One with a return of its own bin far below it
  // was fitted to something standing there: behind a tree row only the near-horizontal lasers reach the next
  // row's crowns, and their returns make a flat, wide "ground" a metre up, with a lower laser's return under it.
  // Four at a time over the padding too: a padding point is its run's first point a million metres up, so its
  // residual is never below that point's (rounding is monotonic), and the answer is the same.
  if (below) return;
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

namespace {

// hypot_f lane by lane: the squares summed and rooted in double, two lanes at a time, rounded to float (its
// operations in its order, so its bits where it does not fall back; where it would, a lane is NaN here).
inline simd::f32x4 hypot_f4(simd::f32x4 x, simd::f32x4 y) {
#if defined(__SSE2__)
  __m128 xv, yv;
  std::memcpy(&xv, &x, sizeof xv);
  std::memcpy(&yv, &y, sizeof yv);
  const __m128d xl = _mm_cvtps_pd(xv), yl = _mm_cvtps_pd(yv);
  const __m128d xh = _mm_cvtps_pd(_mm_movehl_ps(xv, xv)), yh = _mm_cvtps_pd(_mm_movehl_ps(yv, yv));
  const __m128d rl = _mm_sqrt_pd(_mm_add_pd(_mm_mul_pd(xl, xl), _mm_mul_pd(yl, yl)));
  const __m128d rh = _mm_sqrt_pd(_mm_add_pd(_mm_mul_pd(xh, xh), _mm_mul_pd(yh, yh)));
  const __m128 r = _mm_movelh_ps(_mm_cvtpd_ps(rl), _mm_cvtpd_ps(rh));
  simd::f32x4 out;
  std::memcpy(&out, &r, sizeof out);
  return out;
#else
  return simd::f32x4{hypot_f(x[0], y[0]), hypot_f(x[1], y[1]), hypot_f(x[2], y[2]), hypot_f(x[3], y[3])};
#endif
}

}  // namespace

// Heights and labels. A point's ground, with blend_radial: between where its bin's plane was fitted and where the
// plane of the bin beyond it on the point's side (outside it when the point lies farther out than that, else inside)
// was fitted, the two planes interpolated by distance, as a ring's measured ground gives way to the next ring's. A
// neighbour without a plane of its own does not count (its plane is a blend already).
// Bin by bin over the sorted runs, four points at a time: a bin's own plane and its two neighbours' are the same
// for all its points, and the results go back to each point's place in the cloud. Lane by lane the operations of
// label_point, in its order (no contraction into fused multiply-adds on this target): the same bits.
void ZoneGround::label(const Cloud& in, GroundLabels& out) {
  const auto guess = static_cast<float>(params_.max_extrapolation_m);
  label_.resize(bins_.size());
  const auto fitted_or_none = [this](std::uint32_t b) { return b != kNoBin && bins_[b].fitted ? b : kNoBin; };
  for (std::uint32_t b = 0; b < bins_.size(); ++b) {
    const Bin& bin = bins_[b];
    label_[b] = Label{bin.plane,
                      bin.ref_x,
                      bin.ref_y,
                      bin.ref_x * bin.ref_x + bin.ref_y * bin.ref_y,
                      fitted_or_none(outer_[b]),
                      fitted_or_none(inner_[b]),
                      bin.support_m > guess ? std::uint8_t{1} : std::uint8_t{0}};
  }
  using simd::f32x4;
  using simd::i32x4;
  const auto threshold = static_cast<float>(params_.ground_threshold_m);
  const bool blend = params_.blend_radial;
  const f32x4 zero = simd::splat(0.F);
  const auto nbins = static_cast<std::uint32_t>(bins_.size());
  float* const height = out.height_m.data();
  std::uint8_t* const is_ground = out.ground.data();
  std::uint8_t* const guessed = out.guessed.data();
  for (std::uint32_t b = 0; b < nbins; ++b) {
    const std::uint32_t first = bin_start_[b], count = bin_count_[b];
    if (count == 0) continue;
    const Label& own = label_[b];
    const f32x4 pa = simd::splat(own.plane.a), pb = simd::splat(own.plane.b), pc = simd::splat(own.plane.c);
    const f32x4 rx = simd::splat(own.ref_x), ry = simd::splat(own.ref_y), rr2 = simd::splat(own.ref_r2);
    // The neighbour a point blends with: outer where it lies at least as far out as own.ref, else inner. A missing
    // one stands in as own's plane and place, never taken (its lanes are masked off).
    const bool has_outer = blend && own.outer != kNoBin, has_inner = blend && own.inner != kNoBin;
    const Label& lo = has_outer ? label_[own.outer] : own;
    const Label& li = has_inner ? label_[own.inner] : own;
    const i32x4 outer_ok = simd::splat(has_outer ? std::int32_t{-1} : 0);
    const i32x4 inner_ok = simd::splat(has_inner ? std::int32_t{-1} : 0);
    const float* const xs = sx_.data() + first;
    const float* const ys = sy_.data() + first;
    const float* const zs = sz_.data() + first;
    const std::uint32_t* const idx = sidx_.data() + first;
    for (std::uint32_t k = 0; k < count; k += 4) {
      const f32x4 x = simd::load(xs + k), y = simd::load(ys + k), z = simd::load(zs + k);
      f32x4 g = pa * x + pb * y + pc;
      if (has_outer || has_inner) {
        const i32x4 outside = x * x + y * y >= rr2;
        const i32x4 take_nb = outside ? outer_ok : inner_ok;
        const f32x4 oa = outside ? simd::splat(lo.plane.a) : simd::splat(li.plane.a);
        const f32x4 ob = outside ? simd::splat(lo.plane.b) : simd::splat(li.plane.b);
        const f32x4 oc = outside ? simd::splat(lo.plane.c) : simd::splat(li.plane.c);
        const f32x4 ox = outside ? simd::splat(lo.ref_x) : simd::splat(li.ref_x);
        const f32x4 oy = outside ? simd::splat(lo.ref_y) : simd::splat(li.ref_y);
        const f32x4 d_own = hypot_f4(x - rx, y - ry);
        const f32x4 d_other = hypot_f4(x - ox, y - oy);
        const f32x4 sum = d_own + d_other;
        if (simd::mask_bits(sum != sum) != 0U) {  // NaN in either distance (neither is negative: no inf - inf)
          // NaN somewhere (a non-finite point or plane): hypot_f's own fallback decides, point by point.
          for (std::uint32_t l = 0; l < 4 && k + l < count; ++l) label_point(in, idx[k + l], out);
          continue;
        }
        const f32x4 blended = (d_other * g + d_own * (oa * x + ob * y + oc)) / (sum > zero ? sum : simd::splat(1.F));
        g = (take_nb & (sum > zero)) ? blended : g;
      }
      const f32x4 h = z - g;
      const i32x4 ground = -(h < simd::splat(threshold));  // 1 or 0
      const auto put = [&](std::uint32_t l) {
        const std::uint32_t i = idx[k + l];
        height[i] = h[l];
        is_ground[i] = static_cast<std::uint8_t>(ground[l]);
        guessed[i] = own.guessed;
      };
      if (count - k >= 4) {
        put(0);
        put(1);
        put(2);
        put(3);
      } else {
        for (std::uint32_t l = 0; l < count - k; ++l) put(l);
      }
    }
  }
}

// One point's height and labels, as label() gives them four at a time.
void ZoneGround::label_point(const Cloud& in, std::uint32_t i, GroundLabels& out) const {
  const Label& own = label_[bin_of_point_[i]];
  const float x = in.x[i], y = in.y[i];
  float g = own.plane.z_at(x, y);
  if (params_.blend_radial) {
    const std::uint32_t nb = x * x + y * y >= own.ref_r2 ? own.outer : own.inner;
    if (nb != kNoBin) {
      const Label& other = label_[nb];
      const float d_own = hypot_f(x - own.ref_x, y - own.ref_y);
      const float d_other = hypot_f(x - other.ref_x, y - other.ref_y);
      const float sum = d_own + d_other;
      if (sum > 0.F) g = (d_other * g + d_own * other.plane.z_at(x, y)) / sum;
    }
  }
  const float h = in.z[i] - g;
  out.height_m[i] = h;
  out.ground[i] = h < static_cast<float>(params_.ground_threshold_m) ? 1U : 0U;
  out.guessed[i] = own.guessed;
}

void ZoneGround::label_one_at_a_time(const Cloud& in, GroundLabels& out) const {
  out.resize(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) label_point(in, static_cast<std::uint32_t>(i), out);
}

void ZoneGround::segment(const Cloud& in, GroundLabels& out) {
  out.resize(in.size());
  sort_into_bins(in);

  Bin innermost;
  innermost.plane = fit_innermost();
  innermost.fitted = true;

  for (std::uint32_t zi = 0; zi < zones_.size(); ++zi) {
    const Zone& z = zones_[zi];
    for (std::uint32_t ring = 0; ring < z.rings; ++ring) {
      for (std::uint32_t s = 0; s < z.sectors; ++s) {
        const std::uint32_t b = z.first_bin + ring * z.sectors + s;
        const std::uint32_t first = bin_start_[b];
        pts_ = Points{sx_.data() + first, sy_.data() + first, sz_.data() + first, bin_count_[b],
                      bin_start_[b + 1] - first};
        const Bin prior = (zi == 0 && ring == 0) ? innermost : bins_[inner_[b]];
        fit_bin(b, prior);
      }
    }
  }

  interpolate_gaps();

  label(in, out);
}

}  // namespace fieldguard::perception
