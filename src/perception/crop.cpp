#include "fieldguard/perception/crop.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "perception/simd.hpp"

namespace fieldguard::perception {
namespace {

// A box as four-wide bounds: lanes x, y, z; the fourth lane (a point's intensity) always passes.
struct BoxBounds {
  simd::f32x4 lo, hi;
  explicit BoxBounds(const Box3& b) {
    constexpr float inf = std::numeric_limits<float>::infinity();
    lo = simd::f32x4{static_cast<float>(b.min[0]), static_cast<float>(b.min[1]), static_cast<float>(b.min[2]), -inf};
    hi = simd::f32x4{static_cast<float>(b.max[0]), static_cast<float>(b.max[1]), static_cast<float>(b.max[2]), inf};
  }
  // All of x, y, z inside (closed); comparisons with NaN are false, so a NaN coordinate is never inside.
  [[nodiscard]] bool contains(simd::f32x4 p) const { return (simd::mask_bits((p >= lo) & (p <= hi)) & 7U) == 7U; }
};

[[nodiscard]] bool is_finite(const Box3& b) {
  for (std::size_t i = 0; i < 3; ++i) {
    if (!std::isfinite(b.min[i]) || !std::isfinite(b.max[i])) return false;
  }
  return true;
}

// A box's bounds, each splatted across four lanes: one axis of four points at a time.
struct BoxLanes {
  simd::f32x4 lo_x, lo_y, lo_z, hi_x, hi_y, hi_z;
  explicit BoxLanes(const Box3& b)
      : lo_x(simd::splat(static_cast<float>(b.min[0]))),
        lo_y(simd::splat(static_cast<float>(b.min[1]))),
        lo_z(simd::splat(static_cast<float>(b.min[2]))),
        hi_x(simd::splat(static_cast<float>(b.max[0]))),
        hi_y(simd::splat(static_cast<float>(b.max[1]))),
        hi_z(simd::splat(static_cast<float>(b.max[2]))) {}
  // Lane k all ones where point k is inside (closed): the same comparisons as BoxBounds::contains(), so the
  // same answer for every float, NaN included (never inside).
  [[nodiscard]] simd::i32x4 contains(simd::f32x4 x, simd::f32x4 y, simd::f32x4 z) const {
    return (x >= lo_x) & (x <= hi_x) & (y >= lo_y) & (y <= hi_y) & (z >= lo_z) & (z <= hi_z);
  }
};

// Copies the points of in[0, n) that are inside `keep` and outside `drop` to x, y, z, ring (each with room
// for n), in order, and returns how many. Branch-free: every point is written at the next free place, which
// moves on only when the point is kept, so the ROI's edge cutting through a rotation costs no mispredictions.
// `keep` must be finite (it then rejects NaN and infinity); with `check_finite` the points are also tested.
// With `split`, the 2D LiDAR's points are not kept but appended to `scan2d` (a rare, well-predicted branch).
// The box tests run on four points at a time (their x, y, z transposed into a vector each), which leaves the
// copy as most of the per-point work; the last n % 4 points, and any four that hold a 2D LiDAR point, one by one.
template <bool check_finite, bool split>
inline std::size_t crop_points(const LidarPoint* in, std::size_t n, const BoxBounds& keep, const BoxBounds& drop,
                               const BoxLanes& keep4, const BoxLanes& drop4, float* x, float* y, float* z,
                               std::uint16_t* ring, std::vector<LidarPoint>* scan2d) {
  static_assert(offsetof(LidarPoint, x) == 0 && offsetof(LidarPoint, y) == 4 && offsetof(LidarPoint, z) == 8 &&
                offsetof(LidarPoint, intensity) == 12);
  std::size_t k = 0;
  const auto one = [&](const LidarPoint& p) {
    const simd::f32x4 v = simd::load(&p.x);  // x, y, z, intensity
    bool kept = keep.contains(v) && !drop.contains(v);
    if constexpr (check_finite) kept = kept && std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
    if constexpr (split) {
      const bool is_2d = p.source == static_cast<std::uint8_t>(PointSource::Lidar2d);
      if (is_2d) [[unlikely]] {
        scan2d->push_back(p);
      }
      kept = kept && !is_2d;
    }
    x[k] = p.x;
    y[k] = p.y;
    z[k] = p.z;
    ring[k] = p.ring;
    k += kept ? 1U : 0U;
  };
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    const LidarPoint* const p = in + i;
    if constexpr (split) {
      constexpr auto k2d = static_cast<std::uint8_t>(PointSource::Lidar2d);
      if ((p[0].source == k2d) | (p[1].source == k2d) | (p[2].source == k2d) | (p[3].source == k2d)) [[unlikely]] {
        for (std::size_t j = 0; j < 4; ++j) one(p[j]);
        continue;
      }
    }
    simd::f32x4 px = simd::load(&p[0].x);
    simd::f32x4 py = simd::load(&p[1].x);
    simd::f32x4 pz = simd::load(&p[2].x);
    simd::f32x4 pi = simd::load(&p[3].x);
    simd::transpose4(px, py, pz, pi);
    simd::i32x4 in_box = keep4.contains(px, py, pz) & ~drop4.contains(px, py, pz);
    if constexpr (check_finite) {
      // |v| <= FLT_MAX: false for infinity and NaN, as !std::isfinite.
      const simd::f32x4 big = simd::splat(std::numeric_limits<float>::max());
      const simd::i32x4 abs_bits = simd::splat(0x7FFFFFFF);
      const auto abs = [&](simd::f32x4 v) {
        simd::i32x4 b;
        std::memcpy(&b, &v, sizeof b);
        b &= abs_bits;
        std::memcpy(&v, &b, sizeof v);
        return v;
      };
      in_box &= (abs(px) <= big) & (abs(py) <= big) & (abs(pz) <= big);
    }
    const unsigned bits = simd::mask_bits(in_box);
    if (bits == 0xFU) {
      // All four kept (most of a rotation near the tractor): their transposed coordinates are stored whole.
      // x + k has room for four: k <= i and i + 4 <= n.
      std::memcpy(x + k, &px, sizeof px);
      std::memcpy(y + k, &py, sizeof py);
      std::memcpy(z + k, &pz, sizeof pz);
      for (std::size_t j = 0; j < 4; ++j) ring[k + j] = p[j].ring;
      k += 4;
      continue;
    }
    if (bits == 0U) continue;  // none kept: nothing to write (what lies at k and after is overwritten or trimmed)
    for (std::size_t j = 0; j < 4; ++j) {
      x[k] = p[j].x;
      y[k] = p[j].y;
      z[k] = p[j].z;
      ring[k] = p[j].ring;
      k += (bits >> j) & 1U;
    }
  }
  for (; i < n; ++i) one(in[i]);
  return k;
}

}  // namespace

namespace {

template <bool split>
void crop(std::span<const LidarPoint> in, const Box3& roi, const Box3& body, Cloud& out,
          std::vector<LidarPoint>* scan2d) {
  const std::size_t n = in.size();
  out.x.resize(n);
  out.y.resize(n);
  out.z.resize(n);
  out.ring.resize(n);
  const BoxBounds keep(roi), drop(body);
  const BoxLanes keep4(roi), drop4(body);
  // A finite ROI already rejects NaN and infinity; only an unbounded one needs the explicit test.
  const std::size_t k = is_finite(roi) ? crop_points<false, split>(in.data(), n, keep, drop, keep4, drop4, out.x.data(),
                                                                   out.y.data(), out.z.data(), out.ring.data(), scan2d)
                                       : crop_points<true, split>(in.data(), n, keep, drop, keep4, drop4, out.x.data(),
                                                                  out.y.data(), out.z.data(), out.ring.data(), scan2d);
  out.x.resize(k);
  out.y.resize(k);
  out.z.resize(k);
  out.ring.resize(k);
}

}  // namespace

void crop_box(std::span<const LidarPoint> in, const Box3& roi, const Box3& body, Cloud& out) {
  crop<false>(in, roi, body, out, nullptr);
}

void crop_box(std::span<const LidarPoint> in, const Box3& roi, const Box3& body, Cloud& out,
              std::vector<LidarPoint>& scan2d) {
  scan2d.clear();
  crop<true>(in, roi, body, out, &scan2d);
}

}  // namespace fieldguard::perception
