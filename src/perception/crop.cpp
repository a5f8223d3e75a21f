#include "fieldguard/perception/crop.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
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

// Copies the points of in[0, n) that are inside `keep` and outside `drop` to x, y, z, ring (each with room
// for n), in order, and returns how many. Branch-free: every point is written at the next free place, which
// moves on only when the point is kept, so the ROI's edge cutting through a rotation costs no mispredictions.
// `keep` must be finite (it then rejects NaN and infinity); with `check_finite` the points are also tested.
// With `split`, the 2D LiDAR's points are not kept but appended to `scan2d` (a rare, well-predicted branch).
template <bool check_finite, bool split>
inline std::size_t crop_points(const LidarPoint* in, std::size_t n, const BoxBounds& keep, const BoxBounds& drop,
                               float* x, float* y, float* z, std::uint16_t* ring, std::vector<LidarPoint>* scan2d) {
  static_assert(offsetof(LidarPoint, x) == 0 && offsetof(LidarPoint, y) == 4 && offsetof(LidarPoint, z) == 8 &&
                offsetof(LidarPoint, intensity) == 12);
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const LidarPoint& p = in[i];
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
  }
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
  // A finite ROI already rejects NaN and infinity; only an unbounded one needs the explicit test.
  const std::size_t k = is_finite(roi) ? crop_points<false, split>(in.data(), n, keep, drop, out.x.data(), out.y.data(),
                                                                   out.z.data(), out.ring.data(), scan2d)
                                       : crop_points<true, split>(in.data(), n, keep, drop, out.x.data(), out.y.data(),
                                                                  out.z.data(), out.ring.data(), scan2d);
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
