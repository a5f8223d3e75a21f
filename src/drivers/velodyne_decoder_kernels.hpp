#pragma once
// Private to velodyne_decoder.cpp: the azimuth cos/sin table and the 4-wide vector helpers its per-slot loops use.

#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <type_traits>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/core/vec4.hpp"

namespace fieldguard::velodyne::kernels {

inline constexpr std::int32_t kTurnCdeg = 36000;  // one turn in 0.01 degree

// Wraps an azimuth into [0, 36000] exactly as fmod: the reference for every input.
inline float wrap_cdeg(float a) {
  a = std::fmod(a, static_cast<float>(kTurnCdeg));
  if (a < 0.F) a += static_cast<float>(kTurnCdeg);
  return a;
}

inline std::uint16_t round_cdeg_lround(float wrapped) {
  const long r = std::lround(wrapped);
  return static_cast<std::uint16_t>(r >= kTurnCdeg ? r - kTurnCdeg : r);
}

// lround() of a wrapped azimuth w in [0, 36000], folded into 0..35999, given i = trunc(w) and f = w - i. For w >= 0,
// w - trunc(w) is exact, so adding (f >= 0.5) rounds halves away from zero exactly as lround does.
inline std::uint16_t round_cdeg(std::int32_t i, float f) {
  const std::int32_t r = i + static_cast<std::int32_t>(f >= 0.5F);
  return static_cast<std::uint16_t>(r - kTurnCdeg * static_cast<std::int32_t>(r >= kTurnCdeg));
}

// cos and sin of every whole 0.01 degree, with the step to the next entry, for linear interpolation: 36001 entries
// of 16 bytes (563 KiB, of which a packet touches a few KiB), shared by every decoder, built once.
//
// Error of entry + fraction * step against the exact cos/sin of the same float azimuth: linear interpolation over
// h = 0.01 deg = 1.745e-4 rad errs by at most h^2/8 = 3.8e-9; rounding the entries to float adds up to 3.0e-8 and
// the multiply-add up to 3.0e-8 more, so under 7e-8 per component: 0.013 mm at 130 m. Measured with the float
// products that make x and y (VelodyneDecoderFast.AzimuthTableErrorAt130m): 0.019 mm at 130 m, against 0.082 mm
// for the libm path it replaced (std::cos/std::sin of azimuth * float(pi / 18000), an angle rounded to float
// twice). The two paths differ by at most 0.061 mm on the real captures, 0.087 mm on random packets.
struct alignas(16) AzimuthEntry {
  float cos;
  float sin;
  float dcos;  // cos of the next entry - cos of this one
  float dsin;
};
static_assert(sizeof(AzimuthEntry) == 16);

inline const std::vector<AzimuthEntry>& azimuth_table() {
  static const std::vector<AzimuthEntry> table = [] {
    constexpr auto kTurn = static_cast<std::size_t>(kTurnCdeg);
    std::vector<AzimuthEntry> t(kTurn + 1);  // entry 36000 for a wrapped azimuth of exactly 36000
    constexpr double kRadPerCdeg = std::numbers::pi / 18000.0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      // Angles reduced to [0, 36000) before cos/sin, so that entry 36000 equals entry 0 exactly.
      const double c0 = std::cos(static_cast<double>(i % kTurn) * kRadPerCdeg);
      const double s0 = std::sin(static_cast<double>(i % kTurn) * kRadPerCdeg);
      const double c1 = std::cos(static_cast<double>((i + 1) % kTurn) * kRadPerCdeg);
      const double s1 = std::sin(static_cast<double>((i + 1) % kTurn) * kRadPerCdeg);
      const auto c0f = static_cast<float>(c0);
      const auto s0f = static_cast<float>(s0);
      t[i] = AzimuthEntry{c0f, s0f, static_cast<float>(c1 - static_cast<double>(c0f)),
                          static_cast<float>(s1 - static_cast<double>(s0f))};
    }
    return t;
  }();
  return table;
}

// A little-endian u16 at p (the caller checked the length): one load on a little-endian host.
inline std::uint16_t load_le16_unchecked(const std::uint8_t* p) {
  if constexpr (std::endian::native == std::endian::little) {
    std::uint16_t v = 0;
    std::memcpy(&v, p, sizeof v);
    return v;
  } else {
    return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
  }
}

// A little-endian u32 at p (the caller checked that 4 bytes are there), as a signed 32-bit value: the decoder
// keeps only its low 24 bits.
inline std::int32_t load_le32_unchecked(const std::uint8_t* p) {
  std::uint32_t v = 0;
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(&v, p, sizeof v);
  } else {
    v = static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8U) |
        (static_cast<std::uint32_t>(p[2]) << 16U) | (static_cast<std::uint32_t>(p[3]) << 24U);
  }
  return static_cast<std::int32_t>(v);
}

// Four floats in one vector register: the vector extension of GCC and Clang, lowered to SSE2 on x86-64, NEON on
// ARM, scalar code elsewhere; no -march needed. __builtin_shufflevector: GCC 12 and later, Clang.
using Vec4f = vec4::f32x4;
using Vec4i = vec4::i32x4;

inline Vec4f load4(const void* p) {
  Vec4f v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

using vec4::transpose4;

// A LidarPoint is written as two 16-byte halves: (x, y, z, intensity) and (time_s, range_m, w2, w3), where w2 and
// w3 are the 32-bit words holding (azimuth_cdeg, ring) and (return_type, source, reserved1).
static_assert(offsetof(LidarPoint, x) == 0 && offsetof(LidarPoint, y) == 4 && offsetof(LidarPoint, z) == 8 &&
              offsetof(LidarPoint, intensity) == 12 && offsetof(LidarPoint, time_s) == 16 &&
              offsetof(LidarPoint, range_m) == 20 && offsetof(LidarPoint, azimuth_cdeg) == 24 &&
              offsetof(LidarPoint, ring) == 26 && offsetof(LidarPoint, return_type) == 28 &&
              offsetof(LidarPoint, source) == 29 && offsetof(LidarPoint, reserved1) == 30 && sizeof(LidarPoint) == 32 &&
              std::is_trivially_copyable_v<LidarPoint>);

constexpr std::uint32_t azimuth_ring_word(std::uint16_t azimuth_cdeg, std::uint16_t ring) {
  if constexpr (std::endian::native == std::endian::little) return azimuth_cdeg | (std::uint32_t{ring} << 16);
  return (std::uint32_t{azimuth_cdeg} << 16) | ring;
}
// azimuth_ring_word(a, r) == (a's word | ring_word(r)) for every a, r, a's word being a on little-endian and a << 16
// on big-endian: the two halves apart, so that the ring's half is made once per slot and the azimuth's per firing
// in 32-bit lanes (VelodyneDecoder's angles4).
constexpr std::uint32_t ring_word(std::uint16_t ring) {
  if constexpr (std::endian::native == std::endian::little) return std::uint32_t{ring} << 16;
  return ring;
}
constexpr std::uint32_t return_type_word(ReturnType type) {  // source = reserved1 = 0
  const auto t = static_cast<std::uint32_t>(type);
  if constexpr (std::endian::native == std::endian::little) return t;
  return t << 24;
}

// A point's two halves written at `bytes`: the object representation of a LidarPoint of the room a decoder writes
// to (trivially copyable, so its bytes may be written directly).
inline void put_point_at(unsigned char* bytes, const Vec4f& first, const Vec4f& second) {
  std::memcpy(bytes, &first, sizeof first);
  std::memcpy(bytes + sizeof first, &second, sizeof second);
}

}  // namespace fieldguard::velodyne::kernels
