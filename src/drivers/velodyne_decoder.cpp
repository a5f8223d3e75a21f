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

namespace fieldguard::velodyne {

namespace {

using kernels::AzimuthEntry;
using kernels::azimuth_ring_word;
using kernels::azimuth_word;
using kernels::azimuth_table;
using kernels::load4;
using kernels::load_le16_unchecked;
using kernels::load_le32_unchecked;
using kernels::put_point;
using kernels::round_cdeg32;
using kernels::round_cdeg_lround;
using kernels::return_type_word;
using kernels::ring_word;
using kernels::transpose4;
using kernels::Vec4f;
using kernels::Vec4i;
using kernels::wrap_cdeg;
using kernels::wrap_cdeg_fast;

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
  std::size_t lasers;      // lasers per firing sequence
  std::size_t sequences;   // firing sequences per block
  float block_us;          // duration of one block = time between two firing groups
  float sequence_us;       // duration of one firing sequence
  float firing_us;         // time between two lasers of a sequence
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
  std::array<std::uint16_t, kBlocksPerPacket> azimuth{};
  for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
    const std::size_t base = b * kBlockSize;
    if (load_le16(payload, base) != kBlockFlag) return Unexpected{DecodeError::BadBlockFlag};
    azimuth[b] = load_le16(payload, base + 2);
    if (azimuth[b] >= kAzimuthUnits) return Unexpected{DecodeError::BadAzimuth};
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
  (void)azimuth_table();  // built once per process, here rather than on the first packet
  if (options_.model == Model::Unknown) return;  // decode() refuses every packet: NoModel

  const Layout& lay = layout_of(options_.model);
  block_us_ = lay.block_us;
  // Summed in the same order as the point times (group_time_s_, below), so that the marked firing is exactly 0.
  const float in_block_last = static_cast<float>(lay.sequences - 1) * lay.sequence_us +
                              static_cast<float>(lay.lasers - 1) * lay.firing_us;
  last_firing_single_us_ = static_cast<float>(kBlocksPerPacket - 1) * lay.block_us + in_block_last;
  last_firing_dual_us_ = static_cast<float>(kBlocksPerPacket / 2 - 1) * lay.block_us + in_block_last;

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
    if (!(std::abs(slots_.rot_cdeg[slot]) < 35000.F)) fast_wrap_ = false;
  }
  min_rot_cdeg_ = *std::min_element(slots_.rot_cdeg.begin(), slots_.rot_cdeg.end());
  max_rot_cdeg_ = *std::max_element(slots_.rot_cdeg.begin(), slots_.rot_cdeg.end());
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

// The returns of one block, slot by slot, and the points they make (structure of arrays: the loops over them
// are plain arithmetic with a constant trip count, which the compiler vectorises at -O2 with baseline SSE2).
struct BlockPoints {
  alignas(16) std::array<std::int32_t, kSlotsPerBlock> raw;
  alignas(16) std::array<std::int32_t, kSlotsPerBlock> intensity;
  alignas(16) std::array<std::int32_t, kSlotsPerBlock> ok;  // 1: a return inside the range limits
  alignas(16) std::array<float, kSlotsPerBlock> intensity_f;
  alignas(16) std::array<float, kSlotsPerBlock> range;
  alignas(16) std::array<float, kSlotsPerBlock> x;
  alignas(16) std::array<float, kSlotsPerBlock> y;
  alignas(16) std::array<float, kSlotsPerBlock> z;
};

// Azimuth, its cos/sin and the firing time of each slot of a firing group.
struct GroupAngles {
  alignas(16) std::array<float, kSlotsPerBlock> cos_a;
  alignas(16) std::array<float, kSlotsPerBlock> sin_a;
  // The firing time of each slot: the group's row of Decoder::group_time_s_.
  const float* time_s;
  alignas(16) std::array<std::uint32_t, kSlotsPerBlock> azimuth_ring;  // azimuth_ring_word() of each slot
};

}  // namespace

// The per-point arithmetic is the same as the straightforward per-return loop this replaces (and gives the same
// floats: no reassociation, no fused multiply-add at -O2 without -march), except that azimuth cos/sin come from
// the table (see azimuth_table()). Each firing group goes through loops over its 32 slots that the compiler
// vectorises (azimuths, ranges, coordinates), one that looks the azimuths up in the table, and one that writes the
// points out.
template <bool kDual, bool kFastWrap>
std::size_t Decoder::decode_points(const std::uint8_t* bytes, const PacketHeader& header, LidarPoint* dst,
                                   AzimuthRange* azimuths) const {
  constexpr std::size_t kStep = kDual ? 2 : 1;               // blocks per firing group
  constexpr std::size_t kGroups = kBlocksPerPacket / kStep;  // firing groups per packet
  constexpr std::size_t kSlots = kSlotsPerBlock;

  const float* const group_times = kDual ? group_time_s_[1].data() : group_time_s_[0].data();

  // Azimuth of each group and its step to the next group (the last group reuses the previous step).
  std::array<int, kGroups> az_int{};
  for (std::size_t g = 0; g < kGroups; ++g) az_int[g] = load_le16_unchecked(bytes + g * kStep * kBlockSize + 2);
  std::array<float, kGroups> az{};
  std::array<float, kGroups> delta{};
  int fallback = 0;
  for (std::size_t g = 0; g < kGroups; ++g) {
    int d = fallback;
    if (g + 1 < kGroups) {
      const int raw_step = (az_int[g + 1] - az_int[g] + kAzimuthUnits) % kAzimuthUnits;
      if (raw_step <= kMaxGroupStepCdeg) d = raw_step;
    }
    fallback = d;
    az[g] = static_cast<float>(az_int[g]);
    delta[g] = static_cast<float>(d);
  }
  if (azimuths != nullptr) {
    *azimuths = AzimuthRange{};
    if constexpr (kFastWrap) {
      // Before wrapping, a firing's azimuth is az[g] + delta[g] * block_fraction - rot_cdeg with the fraction in
      // [0, 1) and delta[g] >= 0: inside [az[g] - max_rot, az[g] + delta[g] - min_rot], give or take the float
      // rounding (under 0.02 here). One unit of margin either side covers that and the rounding to 0.01 degree;
      // a range inside [0, 35999] then holds every rounded azimuth, none of them wrapped.
      float lo = az[0];
      float hi = az[0] + delta[0];
      for (std::size_t g = 1; g < kGroups; ++g) {
        lo = std::min(lo, az[g]);
        hi = std::max(hi, az[g] + delta[g]);
      }
      const float lo_cdeg = std::floor(lo - max_rot_cdeg_) - 1.F;
      const float hi_cdeg = std::ceil(hi - min_rot_cdeg_) + 1.F;
      if (lo_cdeg >= 0.F && hi_cdeg <= static_cast<float>(kAzimuthUnits - 1)) {
        *azimuths = AzimuthRange{static_cast<std::uint16_t>(lo_cdeg), static_cast<std::uint16_t>(hi_cdeg)};
      }
    }
  }

  const ReturnType single_type = header.return_mode == ReturnMode::Last ? ReturnType::Last : ReturnType::Strongest;
  const float res = resolution_m_;
  const auto min_r = static_cast<float>(options_.min_range_m);
  const auto max_r = static_cast<float>(options_.max_range_m);
  const AzimuthEntry* const table = azimuth_table().data();
  const SlotTables& t = slots_;

  // Azimuth of every firing of group g, its cos/sin and the firing time.
  auto group_angles = [&](std::size_t g, GroupAngles& out) {
    out.time_s = group_times + g * kSlots;
    const float az_g = az[g];
    const float delta_g = delta[g];
    if constexpr (kFastWrap) {
      alignas(16) std::array<std::int32_t, kSlots> index;
      alignas(16) std::array<float, kSlots> frac;
      for (std::size_t s = 0; s < kSlots; ++s) {
        const float w = wrap_cdeg_fast(az_g + delta_g * t.block_fraction[s] - t.rot_cdeg[s]);
        const auto i = static_cast<std::int32_t>(w);  // w >= 0: truncation is floor
        const float f = w - static_cast<float>(i);     // exact
        index[s] = i;
        frac[s] = f;
        out.azimuth_ring[s] = azimuth_word(round_cdeg32(i, f)) | t.ring_word[s];
      }
      // The table look-up, four slots at a time: four entries (cos, sin, dcos, dsin) transposed into a vector of
      // each, then entry + fraction * step (the same float operations as one slot at a time).
      for (std::size_t s = 0; s < kSlots; s += 4) {
        Vec4f c = load4(&table[index[s]]);
        Vec4f sn = load4(&table[index[s + 1]]);
        Vec4f dc = load4(&table[index[s + 2]]);
        Vec4f ds = load4(&table[index[s + 3]]);
        transpose4(c, sn, dc, ds);
        const Vec4f f = load4(&frac[s]);
        const Vec4f cos4 = c + f * dc;
        const Vec4f sin4 = sn + f * ds;
        std::memcpy(&out.cos_a[s], &cos4, sizeof cos4);
        std::memcpy(&out.sin_a[s], &sin4, sizeof sin4);
      }
    } else {
      // Azimuth corrections of more than 350 degrees (or not finite): the general path, as it always was.
      for (std::size_t s = 0; s < kSlots; ++s) {
        const float w = wrap_cdeg(az_g + delta_g * t.block_fraction[s] - t.rot_cdeg[s]);
        const float angle = w * (std::numbers::pi_v<float> / 18000.F);
        out.cos_a[s] = std::cos(angle);
        out.sin_a[s] = std::sin(angle);
        out.azimuth_ring[s] = azimuth_ring_word(round_cdeg_lround(w), t.ring[s]);
      }
    }
  };

  // The returns of one block (kSlots of them at `b`) into points, all slots, in range or not.
  auto block_points = [&](const std::uint8_t* b, const GroupAngles& ga, BlockPoints& out) {
    // Four slots at a time: each slot's 3 bytes and the next one as a little-endian u32 (distance in the low 16
    // bits, reflectivity in the next 8), split by masks. The last slot's 4th byte is the next block's flag, or
    // the timestamp after the last block: inside the checked 1206 bytes.
    for (std::size_t s = 0; s < kSlots; s += 4) {
      const Vec4i v = {load_le32_unchecked(b + 3 * s), load_le32_unchecked(b + 3 * s + 3),
                       load_le32_unchecked(b + 3 * s + 6), load_le32_unchecked(b + 3 * s + 9)};
      const Vec4i raw = v & 0xFFFF;
      const Vec4i intensity = (v >> 16) & 0xFF;
      std::memcpy(&out.raw[s], &raw, sizeof raw);
      std::memcpy(&out.intensity[s], &intensity, sizeof intensity);
    }
    for (std::size_t s = 0; s < kSlots; ++s) {
      const float d = static_cast<float>(out.raw[s]) * res + t.dist_m[s];
      out.ok[s] = static_cast<std::int32_t>(out.raw[s] != 0) & static_cast<std::int32_t>(d >= min_r) &
                  static_cast<std::int32_t>(d <= max_r);
      const float xy = d * t.cos_vert[s] - t.vert_offset_m[s] * t.sin_vert[s];
      out.range[s] = d;
      out.intensity_f[s] = static_cast<float>(out.intensity[s]);
      out.x[s] = xy * ga.cos_a[s] + t.horiz_offset_m[s] * ga.sin_a[s];
      out.y[s] = -xy * ga.sin_a[s] + t.horiz_offset_m[s] * ga.cos_a[s];
      out.z[s] = d * t.sin_vert[s] + t.vert_offset_m[s] * t.cos_vert[s];
    }
  };

  // The points of four slots [s, s + 4) of block `bp` as the two 16-byte halves of each (put_point()), by two
  // 4 x 4 transposes of the structure of arrays. `type` holds the four slots' return_type_word()s.
  struct Four {
    Vec4f a0, a1, a2, a3;  // first halves of the four points
    Vec4f b0, b1, b2, b3;  // second halves
  };
  auto write4 = [&](const BlockPoints& bp, const GroupAngles& ga, std::size_t s, const Vec4f& type) {
    Four f{load4(&bp.x[s]), load4(&bp.y[s]), load4(&bp.z[s]), load4(&bp.intensity_f[s]),
           load4(ga.time_s + s), load4(&bp.range[s]), load4(&ga.azimuth_ring[s]), type};
    transpose4(f.a0, f.a1, f.a2, f.a3);
    transpose4(f.b0, f.b1, f.b2, f.b3);
    return f;
  };

  std::size_t n = 0;
  for (std::size_t g = 0; g < kGroups; ++g) {
    const std::uint8_t* const block0 = bytes + g * kStep * kBlockSize + 4;
    GroupAngles ga;
    group_angles(g, ga);
    BlockPoints p0;
    block_points(block0, ga, p0);
    // Every slot's point is written, in range or not, and kept (n advanced) only if in range: no branch on the data.
    // The room holds kMaxPointsPerPacket points, and n never runs ahead of the slots written.
    if constexpr (!kDual) {
      const auto w = std::bit_cast<float>(return_type_word(single_type));
      const Vec4f type = {w, w, w, w};
      // Written out four times rather than as a loop over k: the eight halves stay in registers.
      for (std::size_t s = 0; s < kSlots; s += 4) {
        const Four f = write4(p0, ga, s, type);
        put_point(dst + n, f.a0, f.b0);
        n += static_cast<std::size_t>(p0.ok[s]);
        put_point(dst + n, f.a1, f.b1);
        n += static_cast<std::size_t>(p0.ok[s + 1]);
        put_point(dst + n, f.a2, f.b2);
        n += static_cast<std::size_t>(p0.ok[s + 2]);
        put_point(dst + n, f.a3, f.b3);
        n += static_cast<std::size_t>(p0.ok[s + 3]);
      }
    } else {
      // Dual: the last return (block 0) and the strongest (block 1); one echo (both blocks equal) is emitted
      // once, as StrongestAndLast.
      BlockPoints p1;
      block_points(block0 + kBlockSize, ga, p1);
      alignas(16) std::array<std::uint32_t, kSlots> type0;
      alignas(16) std::array<std::int32_t, kSlots> keep1;
      for (std::size_t s = 0; s < kSlots; ++s) {
        const bool same = p0.raw[s] == p1.raw[s] && p0.intensity[s] == p1.intensity[s];
        type0[s] = return_type_word(same ? ReturnType::StrongestAndLast : ReturnType::Last);
        keep1[s] = static_cast<std::int32_t>(p1.ok[s] != 0 && !same);
      }
      const auto w1 = std::bit_cast<float>(return_type_word(ReturnType::Strongest));
      const Vec4f type1 = {w1, w1, w1, w1};
      for (std::size_t s = 0; s < kSlots; s += 4) {
        const Four f0 = write4(p0, ga, s, load4(&type0[s]));
        const Four f1 = write4(p1, ga, s, type1);
        put_point(dst + n, f0.a0, f0.b0);
        n += static_cast<std::size_t>(p0.ok[s]);
        put_point(dst + n, f1.a0, f1.b0);
        n += static_cast<std::size_t>(keep1[s]);
        put_point(dst + n, f0.a1, f0.b1);
        n += static_cast<std::size_t>(p0.ok[s + 1]);
        put_point(dst + n, f1.a1, f1.b1);
        n += static_cast<std::size_t>(keep1[s + 1]);
        put_point(dst + n, f0.a2, f0.b2);
        n += static_cast<std::size_t>(p0.ok[s + 2]);
        put_point(dst + n, f1.a2, f1.b2);
        n += static_cast<std::size_t>(keep1[s + 2]);
        put_point(dst + n, f0.a3, f0.b3);
        n += static_cast<std::size_t>(p0.ok[s + 3]);
        put_point(dst + n, f1.a3, f1.b3);
        n += static_cast<std::size_t>(keep1[s + 3]);
      }
    }
  }
  return n;
}

Expected<PacketHeader, DecodeError> Decoder::check(ByteSpan payload) const {
  auto header = read_packet_header(payload);
  if (!header) return header;
  if (options_.model == Model::Unknown) return Unexpected{DecodeError::NoModel};
  if (product_contradicts(options_.model, header->product_byte)) return Unexpected{DecodeError::ModelMismatch};
  return header;
}

std::size_t Decoder::decode_checked(ByteSpan payload, const PacketHeader& header, LidarPoint* room,
                                   AzimuthRange* azimuths) const {
  const bool dual = header.return_mode == ReturnMode::Dual || header.dual_layout;
  const std::uint8_t* const bytes = payload.data();  // length checked by read_packet_header()
  if (dual) {
    return fast_wrap_ ? decode_points<true, true>(bytes, header, room, azimuths)
                      : decode_points<true, false>(bytes, header, room, azimuths);
  }
  return fast_wrap_ ? decode_points<false, true>(bytes, header, room, azimuths)
                    : decode_points<false, false>(bytes, header, room, azimuths);
}

Expected<PacketHeader, DecodeError> Decoder::decode(ByteSpan payload, std::vector<LidarPoint>& out) const {
  auto header = check(payload);
  if (!header) return header;
  // Room for every return of the packet, trimmed to what was kept. resize() grows geometrically, so appending
  // packet after packet to one vector does not reallocate per packet.
  const std::size_t base = out.size();
  out.resize(base + kMaxPointsPerPacket);
  out.resize(base + decode_checked(payload, *header, out.data() + base, nullptr));
  return header;
}

Expected<PacketHeader, DecodeError> Decoder::decode(ByteSpan payload, std::span<LidarPoint, kMaxPointsPerPacket> room,
                                                    std::size_t& count) const {
  count = 0;
  auto header = check(payload);
  if (!header) return header;
  count = decode_checked(payload, *header, room.data(), nullptr);
  return header;
}

Expected<PacketHeader, DecodeError> Decoder::decode(ByteSpan payload, std::span<LidarPoint, kMaxPointsPerPacket> room,
                                                    std::size_t& count, AzimuthRange& azimuths) const {
  count = 0;
  azimuths = AzimuthRange{};
  auto header = check(payload);
  if (!header) return header;
  count = decode_checked(payload, *header, room.data(), &azimuths);
  return header;
}

}  // namespace fieldguard::velodyne
