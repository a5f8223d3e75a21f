// Velodyne HDL-32E / VLP-16 data packet decoder (protocols.md §1.2-§1.8, §1.10).
#include "fieldguard/drivers/velodyne_decoder.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace fieldguard::velodyne {

namespace {

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

float wrap_cdeg(float a) {
  a = std::fmod(a, static_cast<float>(kAzimuthUnits));
  if (a < 0.F) a += static_cast<float>(kAzimuthUnits);
  return a;
}

std::uint16_t round_cdeg(float wrapped) {
  const long r = std::lround(wrapped);
  return static_cast<std::uint16_t>(r >= kAzimuthUnits ? r - kAzimuthUnits : r);
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

  table_.reserve(calibration_.lasers.size());
  constexpr double kRadPerDeg = std::numbers::pi / 180.0;
  for (std::size_t i = 0; i < calibration_.lasers.size(); ++i) {
    const LaserCorrection& c = calibration_.lasers[i];
    const int ring = calibration_.ring_of_laser[i];
    table_.push_back(LaserTable{
        .cos_vert = static_cast<float>(std::cos(c.vert_deg * kRadPerDeg)),
        .sin_vert = static_cast<float>(std::sin(c.vert_deg * kRadPerDeg)),
        .rot_cdeg = static_cast<float>(c.rot_deg * 100.0),
        .dist_m = static_cast<float>(c.dist_m),
        .vert_offset_m = static_cast<float>(c.vert_offset_m),
        .horiz_offset_m = static_cast<float>(c.horiz_offset_m),
        .ring = static_cast<std::uint16_t>(ring < 0 ? 0 : ring),
    });
  }
}

Expected<PacketHeader, DecodeError> Decoder::decode(ByteSpan payload, std::vector<LidarPoint>& out) const {
  auto header = read_packet_header(payload);
  if (!header) return header;
  if (options_.model == Model::Unknown) return Unexpected{DecodeError::NoModel};
  if (product_contradicts(options_.model, header->product_byte)) return Unexpected{DecodeError::ModelMismatch};

  const Layout& lay = layout_of(options_.model);
  const bool dual = header->return_mode == ReturnMode::Dual || header->dual_layout;
  const std::size_t step = dual ? 2 : 1;                  // blocks per firing group
  const std::size_t groups = kBlocksPerPacket / step;     // firing groups per packet

  // Time of the firing the packet timestamp marks, relative to block 0 slot 0.
  // Summed in the same order as the point times below, so that the marked firing is exactly 0.
  const float last_firing_us = static_cast<float>(groups - 1) * lay.block_us +
                               (static_cast<float>(lay.sequences - 1) * lay.sequence_us +
                                static_cast<float>(lay.lasers - 1) * lay.firing_us);
  const float ref_us = options_.timestamp_reference == TimestampReference::LastFiring ? last_firing_us : 0.F;

  // Azimuth of each group and its step to the next group (the last group reuses the previous step).
  std::array<float, kBlocksPerPacket> az{};
  std::array<float, kBlocksPerPacket> delta{};
  int fallback = 0;
  for (std::size_t g = 0; g < groups; ++g) {
    const int a = load_le16(payload, g * step * kBlockSize + 2);
    az[g] = static_cast<float>(a);
    int d = fallback;
    if (g + 1 < groups) {
      const int next = load_le16(payload, (g + 1) * step * kBlockSize + 2);
      const int raw_step = (next - a + kAzimuthUnits) % kAzimuthUnits;
      if (raw_step <= kMaxGroupStepCdeg) d = raw_step;
    }
    fallback = d;
    delta[g] = static_cast<float>(d);
  }

  const ReturnType single_type =
      header->return_mode == ReturnMode::Last ? ReturnType::Last : ReturnType::Strongest;
  const auto res = static_cast<float>(calibration_.distance_resolution_m);
  const auto min_r = static_cast<float>(options_.min_range_m);
  const auto max_r = static_cast<float>(options_.max_range_m);
  constexpr float kRadPerCdeg = std::numbers::pi_v<float> / 18000.F;

  for (std::size_t g = 0; g < groups; ++g) {
    const std::size_t block0 = g * step;
    const float group_us = static_cast<float>(g) * lay.block_us;
    for (std::size_t s = 0; s < lay.sequences; ++s) {
      for (std::size_t j = 0; j < lay.lasers; ++j) {
        const std::size_t slot = s * lay.lasers + j;
        const LaserTable& laser = table_[j];
        const float in_block_us = static_cast<float>(s) * lay.sequence_us + static_cast<float>(j) * lay.firing_us;
        const float azimuth = wrap_cdeg(az[g] + delta[g] * (in_block_us / lay.block_us) - laser.rot_cdeg);
        const float time_s = ((group_us + in_block_us) - ref_us) * 1e-6F;
        const float angle = azimuth * kRadPerCdeg;
        const float cos_a = std::cos(angle);
        const float sin_a = std::sin(angle);

        // Reads one return of this firing from block b; false if there is none or it is out of range.
        auto read = [&](std::size_t b, std::uint16_t& raw, std::uint8_t& intensity) {
          const std::size_t off = b * kBlockSize + 4 + 3 * slot;
          raw = load_le16(payload, off);
          intensity = payload[off + 2];
          if (raw == 0) return false;
          const float d = static_cast<float>(raw) * res + laser.dist_m;
          return d >= min_r && d <= max_r;
        };
        auto emit = [&](std::uint16_t raw, std::uint8_t intensity, ReturnType type) {
          const float d = static_cast<float>(raw) * res + laser.dist_m;
          const float xy = d * laser.cos_vert - laser.vert_offset_m * laser.sin_vert;
          LidarPoint p;
          p.x = xy * cos_a + laser.horiz_offset_m * sin_a;
          p.y = -xy * sin_a + laser.horiz_offset_m * cos_a;
          p.z = d * laser.sin_vert + laser.vert_offset_m * laser.cos_vert;
          p.intensity = static_cast<float>(intensity);
          p.time_s = time_s;
          p.range_m = d;
          p.azimuth_cdeg = round_cdeg(azimuth);
          p.ring = laser.ring;
          p.return_type = type;
          out.push_back(p);
        };

        std::uint16_t raw0 = 0;
        std::uint8_t int0 = 0;
        const bool ok0 = read(block0, raw0, int0);
        if (!dual) {
          if (ok0) emit(raw0, int0, single_type);
          continue;
        }
        std::uint16_t raw1 = 0;
        std::uint8_t int1 = 0;
        const bool ok1 = read(block0 + 1, raw1, int1);
        if (raw0 == raw1 && int0 == int1) {
          if (ok0) emit(raw0, int0, ReturnType::StrongestAndLast);
          continue;
        }
        if (ok0) emit(raw0, int0, ReturnType::Last);
        if (ok1) emit(raw1, int1, ReturnType::Strongest);
      }
    }
  }
  return header;
}

}  // namespace fieldguard::velodyne
