// The zone ground's layout: concentric zones cut into rings and sectors, which bin a point falls in, and each
// bin's neighbours inwards and outwards. The fitting is in zone_ground.cpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "fieldguard/perception/zone_ground.hpp"
#include "perception/fast_math.hpp"
#include "perception/simd.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace fieldguard::perception {
namespace {

constexpr std::size_t kMaxBins = std::size_t{1} << 20U;

float tan_deg(double deg) { return static_cast<float>(std::tan(deg * std::numbers::pi / 180.0)); }

}  // namespace

ZoneGround::ZoneGround(const ZoneParams& params)
    : params_(params), sensor_height_m_(static_cast<float>(params.sensor_height_m)) {
  const auto& e = params_.edges_m;
  if (e.size() < 2 || params_.rings.size() != e.size() - 1 || params_.sectors.size() != e.size() - 1) {
    throw std::invalid_argument("ZoneGround: need n+1 zone edges for n zones, and rings and sectors for each");
  }
  if (!(e[0] >= 0.0)) throw std::invalid_argument("ZoneGround: zone edges must not be negative");
  std::size_t bins = 0;
  std::vector<std::array<float, 2>> centers;
  for (std::size_t z = 0; z + 1 < e.size(); ++z) {
    if (!(e[z + 1] > e[z])) throw std::invalid_argument("ZoneGround: zone edges must increase");
    if (params_.rings[z] < 1 || params_.sectors[z] < 1) {
      throw std::invalid_argument("ZoneGround: every zone needs at least one ring and one sector");
    }
    Zone zone{};
    zone.r0 = static_cast<float>(e[z]);
    zone.r1 = static_cast<float>(e[z + 1]);
    zone.rings = static_cast<std::uint32_t>(params_.rings[z]);
    zone.sectors = static_cast<std::uint32_t>(params_.sectors[z]);
    zone.inv_ring_width = static_cast<float>(static_cast<double>(zone.rings) / (e[z + 1] - e[z]));
    zone.first_bin = static_cast<std::uint32_t>(bins);
    zone.sector_scale = static_cast<float>(static_cast<double>(zone.sectors) / (2.0 * std::numbers::pi));
    // The largest value below the count, so that truncation gives the last ring or sector.
    zone.max_ring = std::nextafter(static_cast<float>(zone.rings), 0.F);
    zone.max_sector = std::nextafter(static_cast<float>(zone.sectors), 0.F);
    bins += static_cast<std::size_t>(zone.rings) * zone.sectors;
    // Bin centres, for blending the planes of bins without their own.
    for (std::uint32_t ring = 0; ring < zone.rings; ++ring) {
      for (std::uint32_t sector = 0; sector < zone.sectors; ++sector) {
        const double r = e[z] + (ring + 0.5) * (e[z + 1] - e[z]) / zone.rings;
        const double theta = (sector + 0.5) * 2.0 * std::numbers::pi / zone.sectors - std::numbers::pi;
        centers.push_back({static_cast<float>(r * std::cos(theta)), static_cast<float>(r * std::sin(theta))});
      }
    }
    if (bins > kMaxBins) throw std::invalid_argument("ZoneGround: more than 2^20 bins");
    zones_.push_back(zone);
  }
  bins_.resize(bins);
  for (std::size_t b = 0; b < bins; ++b) {
    bins_[b].plane = GroundPlane{0.F, 0.F, -sensor_height_m_};
    bins_[b].center_x = centers[b][0];
    bins_[b].center_y = centers[b][1];
  }
  // Each bin's neighbours along its direction: the bin just inside it (ring inside, or the inner zone's last
  // ring under its middle) and the bin just outside it. kNoBin at the ends.
  inner_.assign(bins, kNoBin);
  outer_.assign(bins, kNoBin);
  for (std::uint32_t zi = 0; zi < zones_.size(); ++zi) {
    const Zone& z = zones_[zi];
    for (std::uint32_t ring = 0; ring < z.rings; ++ring) {
      for (std::uint32_t sector = 0; sector < z.sectors; ++sector) {
        const std::uint32_t b = z.first_bin + ring * z.sectors + sector;
        std::uint32_t in = kNoBin;
        if (ring > 0) {
          in = b - z.sectors;
        } else if (zi > 0) {
          const Zone& iz = zones_[zi - 1];
          const double mid = (static_cast<double>(sector) + 0.5) / static_cast<double>(z.sectors);
          const auto s = std::min(static_cast<std::uint32_t>(mid * static_cast<double>(iz.sectors)), iz.sectors - 1);
          in = iz.first_bin + (iz.rings - 1) * iz.sectors + s;
        }
        inner_[b] = in;
        if (ring + 1 < z.rings) {
          outer_[b] = b + z.sectors;
        } else if (zi + 1 < zones_.size()) {
          const Zone& oz = zones_[zi + 1];
          const double mid = (static_cast<double>(sector) + 0.5) / static_cast<double>(z.sectors);
          const auto s = std::min(static_cast<std::uint32_t>(mid * static_cast<double>(oz.sectors)), oz.sectors - 1);
          outer_[b] = oz.first_bin + s;
        }
      }
    }
  }
  tan_max_slope_ = tan_deg(params_.max_slope_deg);
  tan_max_tilt_ = tan_deg(params_.max_tilt_deg);
  tan_max_change_ = tan_deg(params_.max_slope_change_deg);
}

std::uint32_t ZoneGround::bin_of(float x, float y) const {
  return bin_of_polar(std::sqrt(x * x + y * y), fast_atan2(y, x));
}

// Without branches on the data: points come in scan order, which mixes near and far, and a branch on the
// zone would be a guess. (NaN ends in the first bin: every comparison with it is false.)
std::uint32_t ZoneGround::bin_of_polar(float r, float theta) const {
  std::size_t zi = 0;
  for (std::size_t z = 0; z + 1 < zones_.size(); ++z) zi += (r >= zones_[z].r1) ? 1U : 0U;
  const Zone& z = zones_[zi];
  float rf = (r - z.r0) * z.inv_ring_width;
  rf = rf > 0.F ? rf : 0.F;
  rf = rf < z.max_ring ? rf : z.max_ring;
  float sf = (theta + std::numbers::pi_v<float>)*z.sector_scale;
  sf = sf > 0.F ? sf : 0.F;
  sf = sf < z.max_sector ? sf : z.max_sector;
  return z.first_bin + static_cast<std::uint32_t>(rf) * z.sectors + static_cast<std::uint32_t>(sf);
}

void ZoneGround::bins_of(const Cloud& in, Buffer<std::uint32_t>& out) const {
  using simd::f32x4;
  using simd::i32x4;
  const std::size_t n = in.size();
  out.resize(n);
  // Each zone's constants in two rows of four, to be picked per lane by how many zone ends the range has passed (the
  // ends increase, so passing one passes all before it: bin_of_polar's count; NaN passes none, the first zone, as
  // there). The points come in scan order, one firing's lasers near and far, so the four lanes are mostly in
  // different zones: each lane's two rows are loaded and transposed into one vector per constant.
  struct Rows {
    f32x4 lo;  // r0, inv_ring_width, max_ring, sector_scale
    f32x4 hi;  // max_sector, first_bin and sectors (their bits), unused
  };
  // On the stack for up to kFixedZones zones (a frame allocates nothing), on the heap beyond.
  constexpr std::size_t kFixedZones = 16;
  std::array<Rows, kFixedZones> fixed_rows{};
  std::vector<Rows> more_rows;
  if (zones_.size() > kFixedZones) more_rows.resize(zones_.size());
  Rows* const rows = zones_.size() <= kFixedZones ? fixed_rows.data() : more_rows.data();
  for (std::size_t k = 0; k < zones_.size(); ++k) {
    const Zone& z = zones_[k];
    const i32x4 ints = {0, static_cast<std::int32_t>(z.first_bin), static_cast<std::int32_t>(z.sectors), 0};
    Rows r{{z.r0, z.inv_ring_width, z.max_ring, z.sector_scale}, {}};
    std::memcpy(&r.hi, &ints, sizeof ints);
    r.hi[0] = z.max_sector;
    rows[k] = r;
  }
  const Rows* const row = rows;
  // Up to kFixedEnds ends (five zones) in a fixed array, the rest NaN, which no range passes (every comparison with
  // NaN is false): a loop of known length, unrolled, its ends kept in registers. More ends: all of them in a vector.
  constexpr std::size_t kFixedEnds = 4;
  const std::size_t n_ends = zones_.empty() ? 0 : zones_.size() - 1;  // end k: where zone k + 1 begins
  std::array<f32x4, kFixedEnds> fixed_ends{};
  fixed_ends.fill(simd::splat(std::numeric_limits<float>::quiet_NaN()));
  std::vector<f32x4> ends;
  for (std::size_t k = 0; k < n_ends; ++k) {
    const f32x4 end = simd::splat(zones_[k].r1);
    if (n_ends <= kFixedEnds) {
      fixed_ends[k] = end;
    } else {
      ends.push_back(end);
    }
  }
  const f32x4 zero = simd::splat(0.F), pi = simd::splat(std::numbers::pi_v<float>);
  std::size_t p = 0;
  const auto run = [&](const auto& zone_ends) {
    for (; p + 4 <= n; p += 4) {
      const f32x4 x = simd::load(in.x.data() + p), y = simd::load(in.y.data() + p);
      const f32x4 r2 = x * x + y * y;
#if defined(__SSE2__)
      const f32x4 r = _mm_sqrt_ps(r2);  // correctly rounded, as std::sqrt
#else
      const f32x4 r = {std::sqrt(r2[0]), std::sqrt(r2[1]), std::sqrt(r2[2]), std::sqrt(r2[3])};
#endif
      const f32x4 theta = fast_atan2(y, x);
      i32x4 passed = simd::splat(0);
      for (const f32x4& end : zone_ends) passed -= r >= end;
      const Rows &z0 = row[passed[0]], &z1 = row[passed[1]], &z2 = row[passed[2]], &z3 = row[passed[3]];
      f32x4 r0 = z0.lo, inv_ring_width = z1.lo, max_ring = z2.lo, sector_scale = z3.lo;
      simd::transpose4(r0, inv_ring_width, max_ring, sector_scale);
      f32x4 max_sector = z0.hi, first_bits = z1.hi, sectors_bits = z2.hi, unused = z3.hi;
      simd::transpose4(max_sector, first_bits, sectors_bits, unused);
      i32x4 first_bin, sectors;
      std::memcpy(&first_bin, &first_bits, sizeof first_bin);
      std::memcpy(&sectors, &sectors_bits, sizeof sectors);
      f32x4 rf = (r - r0) * inv_ring_width;
      rf = rf > zero ? rf : zero;
      rf = rf < max_ring ? rf : max_ring;
      f32x4 sf = (theta + pi) * sector_scale;
      sf = sf > zero ? sf : zero;
      sf = sf < max_sector ? sf : max_sector;
      const i32x4 b = first_bin + __builtin_convertvector(rf, i32x4) * sectors + __builtin_convertvector(sf, i32x4);
      std::memcpy(out.data() + p, &b, sizeof b);
    }
  };
  if (n_ends <= kFixedEnds) {
    run(fixed_ends);
  } else {
    run(ends);
  }
  for (; p < n; ++p) out[p] = bin_of(in.x[p], in.y[p]);
}

GroundPlane ZoneGround::plane_at(float x, float y) const { return bins_[bin_of(x, y)].plane; }

bool ZoneGround::fitted_at(float x, float y) const { return bins_[bin_of(x, y)].fitted; }

float ZoneGround::support_at(float x, float y) const { return bins_[bin_of(x, y)].support_m; }

}  // namespace fieldguard::perception
