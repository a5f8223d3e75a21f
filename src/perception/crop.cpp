#include "fieldguard/perception/crop.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "perception/simd.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

// The rings of four points into ring[0, 4).
inline void copy_rings(const LidarPoint* p, std::uint16_t* ring) {
#if defined(__SSE2__)
  // Four word inserts from memory and one eight-byte store, not four loads and four stores. Without optimisation
  // (Debug) GCC's _mm_insert_epi16 is a macro that narrows an int to short inside: -Wsign-conversion, not ours.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wsign-conversion"
  __m128i r = _mm_cvtsi32_si128(p[0].ring);
  r = _mm_insert_epi16(r, p[1].ring, 1);
  r = _mm_insert_epi16(r, p[2].ring, 2);
  r = _mm_insert_epi16(r, p[3].ring, 3);
#pragma GCC diagnostic pop
  std::memcpy(ring, &r, 4 * sizeof(std::uint16_t));
#else
  for (std::size_t j = 0; j < 4; ++j) ring[j] = p[j].ring;
#endif
}

// Copies the points of in[0, n) that are inside `keep` and outside `drop` to x, y, z, ring (each with room
// for n), in order, and returns how many. `keep` must be finite (it then rejects NaN and infinity); with
// `check_finite` the points are also tested. With `split`, the 2D LiDAR's points are not kept but appended to
// `scan2d` (a rare, well-predicted branch). `ahead` is a float above the body's front face and the ROI's back
// face (see crop()).
// The box tests run on four points at a time (their x, y, z transposed into a vector each). The fours that
// lie in the ROI ahead of the body (four in ten of a rotation of the shed scene) are proven outside the body by
// that alone: six comparisons decide them, and only the others pay for the full twelve (or seven, when none of
// the four is in the ROI: the rotation's sides). A four kept whole is stored as vectors; one kept in part is
// written point by point, each at the next free place, which moves on only when the point is kept (no branch
// per point). The last n % 4 points, and any eight (or last four) that hold a point not from the 3D LiDAR, go
// one by one.
// With `count`, also counts the kept points with x <= near (NaN never is) into *near_count: here, where the
// kept fours' x are already in a register, not in a second pass over the kept points.
template <bool check_finite, bool split, bool count>
inline std::size_t crop_points(const LidarPoint* in, std::size_t n, const BoxBounds& keep, const BoxBounds& drop,
                               const BoxLanes& keep4, const BoxLanes& drop4, simd::f32x4 ahead, float* x, float* y,
                               float* z, std::uint16_t* ring, std::vector<LidarPoint>* scan2d, float near,
                               std::uint32_t* near_count) {
  static_assert(offsetof(LidarPoint, x) == 0 && offsetof(LidarPoint, y) == 4 && offsetof(LidarPoint, z) == 8 &&
                offsetof(LidarPoint, intensity) == 12);
  std::size_t k = 0;
  const simd::f32x4 near4 = simd::splat(near);
  simd::i32x4 minus_near = simd::splat(std::int32_t{0});  // a true comparison is -1
  std::uint32_t near_one = 0;
  // Every point is written at the next free place, which moves on only when it is kept (no branch per point).
  // Written out four times below, not looped: g++ -O2 leaves a four-step loop rolled, at twice the instructions.
  const auto put = [&](const LidarPoint& p, unsigned kept) {
    x[k] = p.x;
    y[k] = p.y;
    z[k] = p.z;
    ring[k] = p.ring;
    k += kept;
  };
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
    if constexpr (count) near_one += kept && p.x <= near ? 1U : 0U;
    put(p, kept ? 1U : 0U);
  };
  // Four points from p on, all from the 3D LiDAR. Forced inline: it is called twice per loop step, and a call
  // per four would cost more than the loop step it saves.
  const auto four = [&](const LidarPoint* p) __attribute__((always_inline)) {
    simd::f32x4 px = simd::load(&p[0].x);
    simd::f32x4 py = simd::load(&p[1].x);
    simd::f32x4 pz = simd::load(&p[2].x);
    simd::f32x4 pi = simd::load(&p[3].x);
    simd::transpose4(px, py, pz, pi);
    // The ROI on all but its back face: both tests below need it. False for NaN, as every comparison here.
    simd::i32x4 in_roi =
        (px <= keep4.hi_x) & (py >= keep4.lo_y) & (py <= keep4.hi_y) & (pz >= keep4.lo_z) & (pz <= keep4.hi_z);
    // x > ahead: beyond the body's front face, so outside the body, and beyond the ROI's back face.
    if (check_finite || simd::mask_bits(in_roi & (px > ahead)) != 0xFU) {
      in_roi &= px >= keep4.lo_x;
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
        in_roi &= (abs(px) <= big) & (abs(py) <= big) & (abs(pz) <= big);
      }
      // None in the ROI (a run of them where the rotation sweeps past its sides): no body test, nothing to
      // write (what lies at k and after is overwritten or trimmed).
      if (simd::mask_bits(in_roi) == 0U) return;
      const simd::i32x4 kept = in_roi & ~drop4.contains(px, py, pz);
      const unsigned bits = simd::mask_bits(kept);
      if (bits != 0xFU) {
        if (bits != 0U) {
          if constexpr (count) minus_near += kept & (px <= near4);
          put(p[0], bits & 1U);
          put(p[1], (bits >> 1U) & 1U);
          put(p[2], (bits >> 2U) & 1U);
          put(p[3], bits >> 3U);
        }
        return;
      }
    }
    // All four kept: their transposed coordinates are stored whole. x + k has room for four: k <= i and
    // i + 4 <= n.
    std::memcpy(x + k, &px, sizeof px);
    std::memcpy(y + k, &py, sizeof py);
    std::memcpy(z + k, &pz, sizeof pz);
    copy_rings(p, ring + k);
    k += 4;
    if constexpr (count) minus_near += px <= near4;
  };
  // Eight at a time: one source test and one loop step for two fours.
  static_assert(static_cast<std::uint8_t>(PointSource::Lidar3d) == 0);
  std::size_t i = 0;
  constexpr std::size_t kAhead = 512;  // points: 16 kB
  for (; i + 8 <= n; i += 8) {
    const LidarPoint* const p = in + i;
    // The eight's four cache lines kAhead points ahead (the last point's line near the end), fetched now. In
    // the daemon's path the frame comes from the decoder, out of the near caches, and the hardware prefetcher
    // did not run far enough ahead of this loop: BM_PacketsToObstacles' crop took 0.24-0.31 ms without and
    // 0.17-0.19 ms with (a distance of 128 to 4,096 points measured alike; none helps the crop's own, warm,
    // benchmark).
    const char* const later = reinterpret_cast<const char*>(in + std::min(i + kAhead, n - 8));
    __builtin_prefetch(later);
    __builtin_prefetch(later + 64);
    __builtin_prefetch(later + 128);
    __builtin_prefetch(later + 192);
    if constexpr (split) {
      // One OR of the sources instead of a comparison each: any source but the 3D LiDAR's (0) sends the eight
      // to the point-by-point path, which tells the 2D LiDAR's exactly.
      if ((p[0].source | p[1].source | p[2].source | p[3].source | p[4].source | p[5].source | p[6].source |
           p[7].source) != 0) [[unlikely]] {
        for (std::size_t j = 0; j < 8; ++j) one(p[j]);
        continue;
      }
    }
    four(p);
    four(p + 4);
  }
  if (i + 4 <= n) {
    const LidarPoint* const p = in + i;
    bool only_3d = true;
    if constexpr (split) only_3d = (p[0].source | p[1].source | p[2].source | p[3].source) == 0;
    if (only_3d) {
      four(p);
      i += 4;
    }
  }
  for (; i < n; ++i) one(in[i]);
  if constexpr (count) {
    for (int j = 0; j < 4; ++j) near_one += static_cast<std::uint32_t>(-minus_near[j]);
    *near_count = near_one;
  }
  return k;
}

}  // namespace

namespace {

template <bool split, bool count>
void crop(std::span<const LidarPoint> in, const Box3& roi, const Box3& body, Cloud& out,
          std::vector<LidarPoint>* scan2d, float near = 0.0F, std::uint32_t* near_count = nullptr) {
  const std::size_t n = in.size();
  out.x.resize(n);
  out.y.resize(n);
  out.z.resize(n);
  out.ring.resize(n);
  const BoxBounds keep(roi), drop(body);
  const BoxLanes keep4(roi), drop4(body);
  // The fast test's threshold: x above it is above both the body's max x and the ROI's min x. A NaN bound
  // makes it infinite (no x is above it; every point takes the full test).
  const float body_front = static_cast<float>(body.max[0]), roi_back = static_cast<float>(roi.min[0]);
  const float front = std::isnan(body_front) || std::isnan(roi_back) ? std::numeric_limits<float>::infinity()
                                                                     : std::max(body_front, roi_back);
  const simd::f32x4 ahead = simd::splat(front);
  // A finite ROI already rejects NaN and infinity; only an unbounded one needs the explicit test.
  const std::size_t k =
      is_finite(roi)
          ? crop_points<false, split, count>(in.data(), n, keep, drop, keep4, drop4, ahead, out.x.data(), out.y.data(),
                                             out.z.data(), out.ring.data(), scan2d, near, near_count)
          : crop_points<true, split, count>(in.data(), n, keep, drop, keep4, drop4, ahead, out.x.data(), out.y.data(),
                                            out.z.data(), out.ring.data(), scan2d, near, near_count);
  out.x.resize(k);
  out.y.resize(k);
  out.z.resize(k);
  out.ring.resize(k);
}

}  // namespace

void crop_box(std::span<const LidarPoint> in, const Box3& roi, const Box3& body, Cloud& out) {
  crop<false, false>(in, roi, body, out, nullptr);
}

void crop_box(std::span<const LidarPoint> in, const Box3& roi, const Box3& body, Cloud& out,
              std::vector<LidarPoint>& scan2d) {
  scan2d.clear();
  crop<true, false>(in, roi, body, out, &scan2d);
}

std::uint32_t crop_box(std::span<const LidarPoint> in, const Box3& roi, const Box3& body, Cloud& out,
                       std::vector<LidarPoint>& scan2d, float count_x_max) {
  scan2d.clear();
  std::uint32_t near = 0;
  crop<true, true>(in, roi, body, out, &scan2d, count_x_max, &near);
  return near;
}

}  // namespace fieldguard::perception
