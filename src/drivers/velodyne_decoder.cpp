// Velodyne HDL-32E / VLP-16 data packet decoder (protocols.md §1.2-§1.8, §1.10).
#include "fieldguard/drivers/velodyne_decoder.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "drivers/velodyne_decoder_kernels.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>  // baseline x86-64: two conversions and a sign mask the vector extension lowers badly
#endif

namespace fieldguard::velodyne {

namespace {

using kernels::azimuth_ring_word;
using kernels::azimuth_table;
using kernels::AzimuthEntry;
using kernels::load4;
using kernels::load_le16_unchecked;
using kernels::load_le32_unchecked;
using kernels::put_point_at;
using kernels::return_type_word;
using kernels::ring_word;
using kernels::round_cdeg_lround;
using kernels::transpose4;
using kernels::Vec4f;
using kernels::Vec4i;
using kernels::wrap_cdeg;

constexpr std::uint16_t kBlockFlag = 0xEEFF;  // FF EE on the wire, loaded little-endian
constexpr std::uint16_t kAzimuthUnits = 36000;
constexpr std::size_t kTimestampOffset = 1200;
constexpr std::size_t kReturnByteOffset = 1204;
constexpr std::size_t kProductByteOffset = 1205;

constexpr std::uint8_t kReturnStrongest = 0x37;
constexpr std::uint8_t kReturnLast = 0x38;
constexpr std::uint8_t kReturnDual = 0x39;
constexpr std::uint8_t kReturnUnset = 0x00;  // HDL-32E firmware before 2.2.20.0

// Largest plausible azimuth step between two firing groups (0.01 degree). At 1200 rpm a VLP-16 block
// advances about 80; anything beyond this is a corrupted azimuth and is not used for interpolation.
constexpr int kMaxGroupStepCdeg = 500;

// Firing layout of one model (protocols.md §1.7, §1.10).
struct Layout {
  std::size_t lasers;     // lasers per firing sequence
  std::size_t sequences;  // firing sequences per block
  float block_us;         // duration of one block = time between two firing groups
  float sequence_us;      // duration of one firing sequence
  float firing_us;        // time between two lasers of a sequence
};
constexpr Layout kHdl32Layout{32, 1, 46.08F, 46.08F, 1.152F};
constexpr Layout kVlp16Layout{16, 2, 110.592F, 55.296F, 2.304F};

const Layout& layout_of(Model m) { return m == Model::VLP16 ? kVlp16Layout : kHdl32Layout; }

// Product bytes (§1.4) that name a sensor other than `m`. 0x21 is accepted for both: early VLP-16 firmware
// reports the HDL-32E's byte. Unset or unknown bytes contradict nothing.
bool product_contradicts(Model m, std::uint8_t product) {
  switch (product) {
    case 0x22:
    case 0x24: return m != Model::VLP16;
    case 0x23:
    case 0x28:
    case 0xA1: return true;
    default: return false;
  }
}

}  // namespace

Expected<PacketHeader, DecodeError> read_packet_header(ByteSpan payload) {
  if (payload.size() != kDataPacketSize) return Unexpected{DecodeError::BadLength};
  // Every block at once, without a branch per block (the length is checked); only a packet that fails looks again,
  // block by block, for the first error.
  std::array<std::uint16_t, kBlocksPerPacket> azimuth{};
  unsigned bad = 0;
  for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
    const std::uint8_t* const block = payload.data() + b * kBlockSize;
    azimuth[b] = load_le16_unchecked(block + 2);
    bad |= static_cast<unsigned>(load_le16_unchecked(block) != kBlockFlag) |
           static_cast<unsigned>(azimuth[b] >= kAzimuthUnits);
  }
  if (bad != 0) {
    for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
      if (load_le16(payload, b * kBlockSize) != kBlockFlag) return Unexpected{DecodeError::BadBlockFlag};
      if (azimuth[b] >= kAzimuthUnits) return Unexpected{DecodeError::BadAzimuth};
    }
  }
  PacketHeader h;
  h.timestamp_us = load_le32(payload, kTimestampOffset);
  h.return_byte = payload[kReturnByteOffset];
  h.product_byte = payload[kProductByteOffset];
  h.dual_layout = azimuth[0] == azimuth[1];
  h.first_azimuth_cdeg = azimuth.front();
  h.last_azimuth_cdeg = azimuth.back();
  switch (h.return_byte) {
    case kReturnStrongest: h.return_mode = ReturnMode::Strongest; break;
    case kReturnLast: h.return_mode = ReturnMode::Last; break;
    case kReturnDual: h.return_mode = ReturnMode::Dual; break;
    default:
      if (h.dual_layout) {
        h.return_mode = ReturnMode::Dual;
      } else if (h.return_byte == kReturnUnset) {
        h.return_mode = ReturnMode::Strongest;  // old firmware: single return, the default mode
      } else {
        return Unexpected{DecodeError::BadReturnMode};
      }
  }
  return h;
}

namespace {

inline Vec4f splat(float v) { return Vec4f{v, v, v, v}; }
inline Vec4i splat_i(std::int32_t v) { return Vec4i{v, v, v, v}; }
inline Vec4i load4i(const void* p) {
  Vec4i v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
using Vec4u = std::uint32_t __attribute__((vector_size(16)));
inline Vec4f bits_as_float(const Vec4i& v) {
  Vec4f f;
  std::memcpy(&f, &v, sizeof f);
  return f;
}

// The range of four returns from their raw distances: the one formula of the per-slot loop and of the integer
// range test worked out from it (Decoder::SlotTables::raw_above), so that both round alike.
inline Vec4f range_of(const Vec4i& raw, const Vec4f& resolution, const Vec4f& dist) {
  return __builtin_convertvector(raw, Vec4f) * resolution + dist;
}

constexpr std::int32_t kMaxRaw = 0xFFFF;

// The smallest raw distance in [1, kMaxRaw] for which `rises` holds, kMaxRaw + 1 if none; `rises` must be false up
// to some raw and true from there on.
template <typename Pred>
std::int32_t first_raw_where(Pred rises) {
  std::int32_t lo = 1;
  std::int32_t hi = kMaxRaw + 1;
  while (lo < hi) {
    const std::int32_t mid = lo + (hi - lo) / 2;
    if (rises(mid)) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  return lo;
}

}  // namespace

Decoder::Decoder(const Calibration& calibration, const DecoderOptions& options)
    : options_(options), calibration_(calibration) {
  if (options_.model != Model::Unknown) {
    const std::size_t want = layout_of(options_.model).lasers;
    if (calibration_.lasers.size() != want) {
      throw std::invalid_argument("a " + std::string(to_string(options_.model)) + " needs a calibration of " +
                                  std::to_string(want) + " lasers, this one has " +
                                  std::to_string(calibration_.lasers.size()));
    }
  }
  if (!(calibration_.distance_resolution_m > 0.0) || !std::isfinite(calibration_.distance_resolution_m)) {
    throw std::invalid_argument("the calibration's distance resolution must be a positive number of metres");
  }
  if (calibration_.ring_of_laser.size() != calibration_.lasers.size()) assign_rings(calibration_);
  resolution_m_ = static_cast<float>(calibration_.distance_resolution_m);
  (void)azimuth_table();                         // built once per process, here rather than on the first packet
  if (options_.model == Model::Unknown) return;  // decode() refuses every packet: NoModel

  const Layout& lay = layout_of(options_.model);
  block_us_ = lay.block_us;
  // Summed in the same order as the point times (group_time_s_, below), so that the marked firing is exactly 0.
  const float in_block_last =
      static_cast<float>(lay.sequences - 1) * lay.sequence_us + static_cast<float>(lay.lasers - 1) * lay.firing_us;
  last_firing_single_us_ = static_cast<float>(kBlocksPerPacket - 1) * lay.block_us + in_block_last;
  // Dual return: the packet holds half as many firings (block pairs); the division is exact (12 blocks).
  last_firing_dual_us_ =
      static_cast<float>(kBlocksPerPacket / 2 - 1) * lay.block_us + in_block_last;  // NOLINT(bugprone-integer-division)

  constexpr double kRadPerDeg = std::numbers::pi / 180.0;
  for (std::size_t slot = 0; slot < kSlotsPerBlock; ++slot) {
    const std::size_t s = slot / lay.lasers;  // firing sequence in the block
    const std::size_t j = slot % lay.lasers;  // laser
    const LaserCorrection& c = calibration_.lasers[j];
    const int ring = calibration_.ring_of_laser[j];
    const float in_block_us = static_cast<float>(s) * lay.sequence_us + static_cast<float>(j) * lay.firing_us;
    slots_.cos_vert[slot] = static_cast<float>(std::cos(c.vert_deg * kRadPerDeg));
    slots_.sin_vert[slot] = static_cast<float>(std::sin(c.vert_deg * kRadPerDeg));
    slots_.rot_cdeg[slot] = static_cast<float>(c.rot_deg * 100.0);
    slots_.dist_m[slot] = static_cast<float>(c.dist_m);
    slots_.vert_offset_m[slot] = static_cast<float>(c.vert_offset_m);
    slots_.horiz_offset_m[slot] = static_cast<float>(c.horiz_offset_m);
    slots_.in_block_us[slot] = in_block_us;
    slots_.block_fraction[slot] = in_block_us / lay.block_us;
    slots_.ring[slot] = static_cast<std::uint16_t>(ring < 0 ? 0 : ring);
    slots_.ring_word[slot] = ring_word(slots_.ring[slot]);
    slots_.vert_offset_sin[slot] = slots_.vert_offset_m[slot] * slots_.sin_vert[slot];
    slots_.vert_offset_cos[slot] = slots_.vert_offset_m[slot] * slots_.cos_vert[slot];
    if (!(std::abs(slots_.rot_cdeg[slot]) < 35000.F)) fast_wrap_ = false;
  }
  min_rot_cdeg_ = *std::min_element(slots_.rot_cdeg.begin(), slots_.rot_cdeg.end());
  max_rot_cdeg_ = *std::max_element(slots_.rot_cdeg.begin(), slots_.rot_cdeg.end());
  // The kept raw distances of each slot, from the float test itself: range_of() does not fall as raw rises (float
  // conversion, multiply by a positive resolution and add are monotonic), so `range >= min` turns true once and
  // `range <= max` false once, also for a non-finite dist_m or limit (never true, or true throughout).
  const Vec4f res = splat(resolution_m_);
  const auto min_r = static_cast<float>(options_.min_range_m);
  const auto max_r = static_cast<float>(options_.max_range_m);
  for (std::size_t slot = 0; slot < kSlotsPerBlock; ++slot) {
    const Vec4f dist = splat(slots_.dist_m[slot]);
    const auto range = [&](std::int32_t raw) { return range_of(splat_i(raw), res, dist)[0]; };
    const std::int32_t first_near = first_raw_where([&](std::int32_t raw) { return range(raw) >= min_r; });
    const std::int32_t first_far = first_raw_where([&](std::int32_t raw) { return !(range(raw) <= max_r); });
    slots_.raw_above[slot] = first_near - 1;  // >= 0: raw 0 ("no return") is never kept
    slots_.raw_below[slot] = first_far;
  }
  // Point times relative to the firing the packet timestamp marks, per firing group and slot.
  for (std::size_t dual = 0; dual < 2; ++dual) {
    const float ref_us = options_.timestamp_reference == TimestampReference::LastFiring
                             ? (dual != 0 ? last_firing_dual_us_ : last_firing_single_us_)
                             : 0.F;
    const std::size_t groups = dual != 0 ? kBlocksPerPacket / 2 : kBlocksPerPacket;
    for (std::size_t g = 0; g < groups; ++g) {
      const float group_us = static_cast<float>(g) * block_us_;
      for (std::size_t slot = 0; slot < kSlotsPerBlock; ++slot) {
        group_time_s_[dual][g * kSlotsPerBlock + slot] = ((group_us + slots_.in_block_us[slot]) - ref_us) * 1e-6F;
      }
    }
  }
}

namespace {

// The angles of four slots of a firing group: azimuth cos/sin and the (azimuth, ring) words of the points.
struct Angles4 {
  Vec4f cos_a;
  Vec4f sin_a;
  Vec4i azimuth_ring;
};

// The returns of four slots of one block and their points (before the time, azimuth and type are added).
struct Returns4 {
  Vec4f x, y, z, intensity, range;
  Vec4i ok;    // -1 (all bits): a return inside the range limits; 0: none
  Vec4i echo;  // distance and reflectivity bytes as they came: two blocks carry the same echo where these are equal
};

// Four points as LidarPoints: the two 16-byte halves of each (kernels::put_point_at()), by two 4 x 4 transposes of
// the rows (x, y, z, intensity) and (time, range, (azimuth, ring) word, return_type_word()).
struct Rows {
  Vec4f a0, a1, a2, a3;  // first halves of the four points after the transpose
  Vec4f b0, b1, b2, b3;  // second halves
};
inline Rows rows_of(const Returns4& r, const Vec4f& time, const Vec4i& azimuth_ring, const Vec4i& type) {
  Rows w{r.x, r.y, r.z, r.intensity, time, r.range, bits_as_float(azimuth_ring), bits_as_float(type)};
  transpose4(w.a0, w.a1, w.a2, w.a3);
  transpose4(w.b0, w.b1, w.b2, w.b3);
  return w;
}

}  // namespace

Expected<PacketHeader, DecodeError> Decoder::check(ByteSpan payload) const {
  auto header = read_packet_header(payload);
  if (!header) return header;
  if (const auto e = accept(*header)) return Unexpected{*e};
  return header;
}

std::optional<DecodeError> Decoder::accept(const PacketHeader& header) const {
  if (options_.model == Model::Unknown) return DecodeError::NoModel;
  if (product_contradicts(options_.model, header.product_byte)) return DecodeError::ModelMismatch;
  return std::nullopt;
}

namespace {

bool is_dual(const PacketHeader& header) { return header.return_mode == ReturnMode::Dual || header.dual_layout; }

// The lanes of `ok` (each 0 or all ones) as four bits.
inline unsigned keep_mask(const Vec4i& ok) {
#if defined(__SSE2__)
  return static_cast<unsigned>(_mm_movemask_ps(bits_as_float(ok)));  // one instruction
#else
  return static_cast<unsigned>((ok[0] & 1) | (ok[1] & 2) | (ok[2] & 4) | (ok[3] & 8));
#endif
}

}  // namespace

// Azimuth of each firing group and its step to the next group (the last group reuses the previous step), and the
// bounds they give.
template <bool kDual>
Decoder::PacketAzimuths Decoder::read_azimuths(const std::uint8_t* bytes) const {
  constexpr std::size_t kStep = kDual ? 2 : 1;
  constexpr std::size_t kGroups = kBlocksPerPacket / kStep;
  PacketAzimuths out;
  out.dual_ = kDual;
  out.min_rot_bits_ = std::bit_cast<std::uint32_t>(min_rot_cdeg_);
  out.max_rot_bits_ = std::bit_cast<std::uint32_t>(max_rot_cdeg_);
  // Four groups at a time: kChunks vectors of azimuths, the lanes past the last group holding copies of it (and of
  // its step), which change neither the minimum nor the maximum below.
  constexpr std::size_t kChunks = (kGroups + 3) / 4;
  constexpr std::size_t kLanes = 4 * kChunks;
  alignas(16) std::array<std::int32_t, kLanes + 1> az_int{};
  for (std::size_t g = 0; g < kGroups; ++g) az_int[g] = load_le16_unchecked(bytes + g * kStep * kBlockSize + 2);
  for (std::size_t g = kGroups; g <= kLanes; ++g) az_int[g] = az_int[kGroups - 1];
  // Each group's step to the next: (next - this) mod 36000 for azimuths in [0, 36000) (checked below), without a
  // division; a step beyond kMaxGroupStepCdeg is a corrupted azimuth, replaced by the step before it.
  alignas(16) std::array<std::int32_t, kLanes> step{};
  unsigned too_far = 0;
  unsigned out_of_turn = 0;
  for (std::size_t c = 0; c < kLanes; c += 4) {
    const Vec4i here = load4i(&az_int[c]);
    Vec4i d = load4i(&az_int[c + 1]) - here;
    d += splat_i(kAzimuthUnits) & (d < splat_i(0));
    too_far |= keep_mask(d > splat_i(kMaxGroupStepCdeg));
    out_of_turn |= keep_mask(here >= splat_i(kAzimuthUnits));
    std::memcpy(&step[c], &d, sizeof d);
  }
  if (too_far != 0) {  // rare: the sequential rule, group by group
    std::int32_t fallback = 0;
    for (std::size_t g = 0; g + 1 < kGroups; ++g) {
      if (step[g] > kMaxGroupStepCdeg) step[g] = fallback;
      fallback = step[g];
    }
  }
  for (std::size_t g = kGroups - 1; g < kLanes; ++g) step[g] = step[kGroups - 2];  // the last group: the step before
  // Floats (exact below 2^24) for the per-slot loop, and from them the smallest azimuth and the largest azimuth plus
  // step, as the bounds below need them.
  Vec4f lo4 = splat(static_cast<float>(az_int[0]));
  Vec4f hi4 = splat(0.F);
  alignas(16) std::array<float, kLanes> az_f{};
  alignas(16) std::array<float, kLanes> step_f{};
  for (std::size_t c = 0; c < kLanes; c += 4) {
    const Vec4f az = __builtin_convertvector(load4i(&az_int[c]), Vec4f);
    const Vec4f d = __builtin_convertvector(load4i(&step[c]), Vec4f);
    lo4 = az < lo4 ? az : lo4;
    hi4 = az + d > hi4 ? az + d : hi4;
    std::memcpy(&az_f[c], &az, sizeof az);
    std::memcpy(&step_f[c], &d, sizeof d);
  }
  std::memcpy(out.az_.data(), az_f.data(), kGroups * sizeof(float));
  std::memcpy(out.delta_.data(), step_f.data(), kGroups * sizeof(float));
  const float lo = std::min(std::min(lo4[0], lo4[1]), std::min(lo4[2], lo4[3]));
  const float hi = std::max(std::max(hi4[0], hi4[1]), std::max(hi4[2], hi4[3]));
  const bool bad = out_of_turn != 0;  // read_packet_header() refuses these; a caller of azimuths() may not have
  out.valid_ = !bad;
  if (bad || !fast_wrap_) return out;
  // Before wrapping, a firing's azimuth is az[g] + delta[g] * block_fraction - rot_cdeg with the fraction in
  // [0, 1) and delta[g] >= 0: inside [az[g] - max_rot, az[g] + delta[g] - min_rot], give or take the float
  // rounding (under 0.02 here). One unit of margin either side covers that and the rounding to 0.01 degree;
  // a range inside [0, 35999] then holds every rounded azimuth, none of them wrapped.
  const float lo_cdeg = std::floor(lo - max_rot_cdeg_) - 1.F;
  const float hi_cdeg = std::ceil(hi - min_rot_cdeg_) + 1.F;
  if (lo_cdeg >= 0.F && hi_cdeg <= static_cast<float>(kAzimuthUnits - 1)) {
    out.bounds_ = AzimuthRange{static_cast<std::uint16_t>(lo_cdeg), static_cast<std::uint16_t>(hi_cdeg)};
  }
  return out;
}

Decoder::PacketAzimuths Decoder::azimuths(ByteSpan payload, const PacketHeader& header) const {
  if (payload.size() != kDataPacketSize) return PacketAzimuths{};  // not valid: decodes to nothing
  return is_dual(header) ? read_azimuths<true>(payload.data()) : read_azimuths<false>(payload.data());
}

namespace {

// Where each of four points goes when only some are kept: for every mask of kept lanes (bit k: lane k), the byte
// offset of lane k's point from the first free one (the number of kept lanes before it, times the point size) and
// the bytes the kept points take. A dropped lane gets the offset of the next kept one, which overwrites it (or of
// the first point after them, which is free room): every lane is written, with no branch on the data.
struct KeepTable {
  std::array<std::array<std::uint8_t, 4>, 16> offset{};
  std::array<std::uint8_t, 16> bytes{};  // kept lanes times the point size
};
constexpr KeepTable kKeep = [] {
  KeepTable k;
  for (unsigned mask = 0; mask < 16; ++mask) {
    unsigned kept = 0;
    for (unsigned lane = 0; lane < 4; ++lane) {
      k.offset[mask][lane] = static_cast<std::uint8_t>(kept * sizeof(LidarPoint));
      kept += (mask >> lane) & 1U;
    }
    k.bytes[mask] = static_cast<std::uint8_t>(kept * sizeof(LidarPoint));
  }
  return k;
}();

// float(offset + double(t)) of each lane: RotationAssembler::commit()'s conversion of a packet-relative time to a
// frame-relative one, two lanes at a time in double. SSE2's conversions where there is SSE2 (GCC lowers the
// generic vector code for 2-lane halves through memory), the same conversions lane by lane elsewhere.
using Vec2d = double __attribute__((vector_size(16)));
inline Vec4f add_offset(const Vec4f& t, const Vec2d& offset) {
#if defined(__SSE2__)
  const __m128d lo = _mm_add_pd(_mm_cvtps_pd(t), offset);
  const __m128d hi = _mm_add_pd(_mm_cvtps_pd(_mm_movehl_ps(t, t)), offset);
  return _mm_movelh_ps(_mm_cvtpd_ps(lo), _mm_cvtpd_ps(hi));
#else
  return Vec4f{static_cast<float>(offset[0] + static_cast<double>(t[0])),
               static_cast<float>(offset[0] + static_cast<double>(t[1])),
               static_cast<float>(offset[0] + static_cast<double>(t[2])),
               static_cast<float>(offset[0] + static_cast<double>(t[3]))};
#endif
}

}  // namespace

// One pass over each firing group, four slots at a time, everything in registers: azimuth and its table cos/sin,
// the returns, the points, and their transposition into LidarPoints. The arithmetic of every point is the same
// as the straightforward per-return loop's (and gives the same floats: no reassociation, no fused multiply-add
// at -O2 without -march), except that azimuth cos/sin come from the table (see azimuth_table()).
template <bool kDual, Decoder::Wrap kWrap, bool kFrameTimes>
std::size_t Decoder::decode_points(const std::uint8_t* bytes, const PacketHeader& header, const PacketAzimuths& groups,
                                   const float* times, double time_offset_s, LidarPoint* dst) const {
  constexpr std::size_t kStep = kDual ? 2 : 1;               // blocks per firing group
  constexpr std::size_t kGroups = kBlocksPerPacket / kStep;  // firing groups per packet
  constexpr std::size_t kSlots = kSlotsPerBlock;

  const SlotTables& t = slots_;
  const Vec4f res = splat(resolution_m_);
  const auto* const table = reinterpret_cast<const unsigned char*>(azimuth_table().data());
  const ReturnType single_type = header.return_mode == ReturnMode::Last ? ReturnType::Last : ReturnType::Strongest;
  const Vec4i type_single = splat_i(static_cast<std::int32_t>(return_type_word(single_type)));
  const Vec2d offset = {time_offset_s, time_offset_s};

  // Four slots' angles, from the group's azimuth and step (splat).
  auto angles4 = [&](const Vec4f& az_g, const Vec4f& delta_g, std::size_t s) {
    Angles4 an;
    constexpr auto kTurn = static_cast<float>(kAzimuthUnits);
    Vec4f w = az_g + delta_g * load4(&t.block_fraction[s]) - load4(&t.rot_cdeg[s]);
    if constexpr (kWrap == Wrap::Fast) {
      // wrap_cdeg() for w in (-36000, 72000), four lanes at a time: fmod's result there is w, w - 36000 (exact by
      // Sterbenz' lemma for w <= 72000) or w + 36000 (w < 0). Written as w - 36000 * {-1, 0, 1}, which gives the
      // same floats without a select (a comparison is -1 where true).
      const Vec4i turns = (w < splat(0.F)) - (w >= splat(kTurn));
      w = w - splat(kTurn) * __builtin_convertvector(turns, Vec4f);
    }
    // Wrap::None: the packet's azimuth bounds (bounds_of()) lie inside [0, 35999], so every w is already in
    // [0, 36000) and rounds to at most 35999: the wraps above and below would subtract 0.
    const Vec4i i = __builtin_convertvector(w, Vec4i);      // w >= 0: truncation is floor
    const Vec4f f = w - __builtin_convertvector(i, Vec4f);  // exact
    // kernels::round_cdeg() in 32-bit lanes, then the azimuth's half of azimuth_ring_word().
    Vec4i r = i - (f >= splat(0.5F));
    if constexpr (kWrap == Wrap::Fast) r -= splat_i(kAzimuthUnits) & (r >= splat_i(kAzimuthUnits));
    if constexpr (std::endian::native != std::endian::little) r <<= 16;
    an.azimuth_ring = r | load4i(&t.ring_word[s]);
    // The table look-up: four entries (cos, sin, dcos, dsin) transposed into a vector of each, then
    // entry + fraction * step (the same float operations as one slot at a time). Byte offsets in unsigned lanes:
    // no sign extension per lane.
    const Vec4u at = __builtin_convertvector(i, Vec4u) * static_cast<std::uint32_t>(sizeof(AzimuthEntry));
    Vec4f c = load4(table + at[0]);
    Vec4f sn = load4(table + at[1]);
    Vec4f dc = load4(table + at[2]);
    Vec4f ds = load4(table + at[3]);
    transpose4(c, sn, dc, ds);
    an.cos_a = c + f * dc;
    an.sin_a = sn + f * ds;
    return an;
  };

  // Four slots' returns of the block whose first slot is at `b` (after its flag and azimuth).
  auto returns4 = [&](const std::uint8_t* b, std::size_t s, const Angles4& an) {
    Returns4 r;
    // Each slot's 3 bytes and the next one as a little-endian u32 (distance in the low 16 bits, reflectivity in
    // the next 8), split by masks. The last slot's 4th byte is the next block's flag, or the timestamp after the
    // last block: inside the checked 1206 bytes.
    const Vec4i v = {load_le32_unchecked(b + 3 * s), load_le32_unchecked(b + 3 * s + 3),
                     load_le32_unchecked(b + 3 * s + 6), load_le32_unchecked(b + 3 * s + 9)};
    r.echo = v & 0xFFFFFF;  // only the dual path compares echoes (dead code elsewhere)
    const Vec4i raw = v & 0xFFFF;
    const Vec4f d = range_of(raw, res, load4(&t.dist_m[s]));
    // min_range_m <= d <= max_range_m and raw != 0, in integers (SlotTables::raw_above).
    r.ok = (raw > load4i(&t.raw_above[s])) & (raw < load4i(&t.raw_below[s]));
    const Vec4f cos_vert = load4(&t.cos_vert[s]);
    const Vec4f sin_vert = load4(&t.sin_vert[s]);
    const Vec4f horiz = load4(&t.horiz_offset_m[s]);
    const Vec4f xy = d * cos_vert - load4(&t.vert_offset_sin[s]);
    r.range = d;
    r.intensity = __builtin_convertvector((v >> 16) & 0xFF, Vec4f);
    r.x = xy * an.cos_a + horiz * an.sin_a;
    r.y = -xy * an.sin_a + horiz * an.cos_a;
    r.z = d * sin_vert + load4(&t.vert_offset_cos[s]);
    return r;
  };

  // Azimuth corrections of more than 350 degrees (or not finite): the general path, as it always was, a group's
  // angles at a time into these arrays.
  struct SlowAngles {
    alignas(16) std::array<float, kSlots> cos_a;
    alignas(16) std::array<float, kSlots> sin_a;
    alignas(16) std::array<std::uint32_t, kSlots> azimuth_ring;
  };
  auto slow_angles = [&](float az_g, float delta_g, SlowAngles& out) {
    for (std::size_t s = 0; s < kSlots; ++s) {
      const float w = wrap_cdeg(az_g + delta_g * t.block_fraction[s] - t.rot_cdeg[s]);
      const float angle = w * (std::numbers::pi_v<float> / 18000.F);
      out.cos_a[s] = std::cos(angle);
      out.sin_a[s] = std::sin(angle);
      out.azimuth_ring[s] = azimuth_ring_word(round_cdeg_lround(w), t.ring[s]);
    }
  };

  // Every slot's point is written, in range or not, and kept (`out` advanced) only if in range: no branch on the
  // data. The room holds kMaxPointsPerPacket points, and `out` never runs ahead of the slots written. A byte
  // pointer into the room's object representation (put_point_at()), so that a kept point costs one add.
  auto* const first_free = reinterpret_cast<unsigned char*>(dst);
  unsigned char* out = first_free;
  auto put = [&](const Vec4f& first, const Vec4f& second, std::int32_t keep) {
    put_point_at(out, first, second);
    out += sizeof(LidarPoint) * static_cast<std::size_t>(keep & 1);
  };
  for (std::size_t g = 0; g < kGroups; ++g) {
    const std::uint8_t* const block0 = bytes + g * kStep * kBlockSize + 4;
    const float* const time_g = times + g * kSlots;
    const Vec4f az_g = splat(groups.az_[g]);
    const Vec4f delta_g = splat(groups.delta_[g]);
    [[maybe_unused]] SlowAngles slow;
    if constexpr (kWrap == Wrap::General) slow_angles(groups.az_[g], groups.delta_[g], slow);
    for (std::size_t s = 0; s < kSlots; s += 4) {
      Angles4 an;
      if constexpr (kWrap == Wrap::General) {
        an = Angles4{load4(&slow.cos_a[s]), load4(&slow.sin_a[s]), load4i(&slow.azimuth_ring[s])};
      } else {
        an = angles4(az_g, delta_g, s);
      }
      Vec4f time = load4(time_g + s);
      if constexpr (kFrameTimes) time = add_offset(time, offset);
      const Returns4 r0 = returns4(block0, s, an);
      if constexpr (!kDual) {
        const Rows w = rows_of(r0, time, an.azimuth_ring, type_single);
        const unsigned mask = keep_mask(r0.ok);
        const std::array<std::uint8_t, 4>& at = kKeep.offset[mask];
        put_point_at(out + at[0], w.a0, w.b0);
        put_point_at(out + at[1], w.a1, w.b1);
        put_point_at(out + at[2], w.a2, w.b2);
        put_point_at(out + at[3], w.a3, w.b3);
        out += kKeep.bytes[mask];
      } else {
        // Dual: the last return (block 0) and the strongest (block 1), slot by slot; one echo (both blocks
        // equal) is emitted once, as StrongestAndLast.
        const Returns4 r1 = returns4(block0 + kBlockSize, s, an);
        const Vec4i same = r0.echo == r1.echo;
        const Vec4i type0 = (same & static_cast<std::int32_t>(return_type_word(ReturnType::StrongestAndLast))) |
                            (~same & static_cast<std::int32_t>(return_type_word(ReturnType::Last)));
        const Vec4i keep1 = r1.ok & ~same;
        const Rows w0 = rows_of(r0, time, an.azimuth_ring, type0);
        const Rows w1 = rows_of(r1, time, an.azimuth_ring,
                                splat_i(static_cast<std::int32_t>(return_type_word(ReturnType::Strongest))));
        put(w0.a0, w0.b0, r0.ok[0]);
        put(w1.a0, w1.b0, keep1[0]);
        put(w0.a1, w0.b1, r0.ok[1]);
        put(w1.a1, w1.b1, keep1[1]);
        put(w0.a2, w0.b2, r0.ok[2]);
        put(w1.a2, w1.b2, keep1[2]);
        put(w0.a3, w0.b3, r0.ok[3]);
        put(w1.a3, w1.b3, keep1[3]);
      }
    }
  }
  return static_cast<std::size_t>(out - first_free) / sizeof(LidarPoint);
}

std::size_t Decoder::decode_checked(const std::uint8_t* bytes, const PacketHeader& header, const PacketAzimuths& groups,
                                    LidarPoint* room, std::optional<double> time_offset_s) const {
  const float* const times = groups.dual_ ? group_time_s_[1].data() : group_time_s_[0].data();
  const auto run = [&]<bool kDual, Wrap kWrap>() {
    if (time_offset_s) return decode_points<kDual, kWrap, true>(bytes, header, groups, times, *time_offset_s, room);
    return decode_points<kDual, kWrap, false>(bytes, header, groups, times, 0.0, room);
  };
  // Bounds inside the turn (read_azimuths() gives them only on the fast path) leave nothing to wrap; trusted only
  // where they were worked out with this decoder's azimuth corrections.
  const bool inside = groups.bounds_.max_cdeg < kAzimuthUnits &&
                      groups.min_rot_bits_ == std::bit_cast<std::uint32_t>(min_rot_cdeg_) &&
                      groups.max_rot_bits_ == std::bit_cast<std::uint32_t>(max_rot_cdeg_);
  if (groups.dual_) {
    if (!fast_wrap_) return run.template operator()<true, Wrap::General>();
    return inside ? run.template operator()<true, Wrap::None>() : run.template operator()<true, Wrap::Fast>();
  }
  if (!fast_wrap_) return run.template operator()<false, Wrap::General>();
  return inside ? run.template operator()<false, Wrap::None>() : run.template operator()<false, Wrap::Fast>();
}

Expected<PacketHeader, DecodeError> Decoder::decode(ByteSpan payload, std::vector<LidarPoint>& out) const {
  auto header = check(payload);
  if (!header) return header;
  // Room for every return of the packet, trimmed to what was kept. resize() grows geometrically, so appending
  // packet after packet to one vector does not reallocate per packet.
  const std::size_t base = out.size();
  out.resize(base + kMaxPointsPerPacket);
  out.resize(base +
             decode_checked(payload.data(), *header, azimuths(payload, *header), out.data() + base, std::nullopt));
  return header;
}

Expected<PacketHeader, DecodeError> Decoder::decode(ByteSpan payload, std::span<LidarPoint, kMaxPointsPerPacket> room,
                                                    std::size_t& count) const {
  count = 0;
  auto header = check(payload);
  if (!header) return header;
  count = decode_checked(payload.data(), *header, azimuths(payload, *header), room.data(), std::nullopt);
  return header;
}

Expected<PacketHeader, DecodeError> Decoder::decode(ByteSpan payload, std::span<LidarPoint, kMaxPointsPerPacket> room,
                                                    std::size_t& count, AzimuthRange& azimuths_out) const {
  count = 0;
  azimuths_out = AzimuthRange{};
  auto header = check(payload);
  if (!header) return header;
  const PacketAzimuths az = azimuths(payload, *header);
  azimuths_out = az.bounds_;
  count = decode_checked(payload.data(), *header, az, room.data(), std::nullopt);
  return header;
}

std::size_t Decoder::decode_accepted(ByteSpan payload, const PacketHeader& header, const PacketAzimuths& groups,
                                     std::span<LidarPoint, kMaxPointsPerPacket> room,
                                     std::optional<double> time_offset_s) const {
  // Misuse (another payload's or layout's azimuths, a payload read_packet_header() would refuse): nothing decoded.
  if (payload.size() != kDataPacketSize || !groups.valid_ || groups.dual_ != is_dual(header) || accept(header)) {
    return 0;
  }
  return decode_checked(payload.data(), header, groups, room.data(), time_offset_s);
}

}  // namespace fieldguard::velodyne
