// RoboSense RS-32 MSOP data packet decoder (protocols.md §2.2; rs_driver decoder_RS32.hpp, block_iterator.hpp,
// chan_angles.hpp; ros_rslidar rawdata.cc unpack_RS32 for the old 1 cm firmware; RS-LiDAR-32 manual appendix A).
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "fieldguard/drivers/robosense.hpp"

namespace fieldguard::robosense {

namespace {

constexpr std::array<std::uint8_t, 8> kMsopMagic = {0x55, 0xAA, 0x05, 0x0A, 0x5A, 0xA5, 0x50, 0xA0};
constexpr std::size_t kTimestampOffset = 20;
constexpr std::size_t kModelOffset = 30;
constexpr std::size_t kTemperatureOffset = 38;
constexpr std::uint8_t kBlockFlag0 = 0xFF;
constexpr std::uint8_t kBlockFlag1 = 0xEE;
constexpr int kFullTurnCdeg = 36000;
// A step between firing groups above this (0.01 degree) is the FOV blind zone or a corrupted azimuth, not
// rotation: rs_driver block_iterator.hpp uses the same threshold and falls back on the nominal step.
constexpr int kMaxGroupStepCdeg = 100;
constexpr double kHalfCmM = 0.005;
constexpr double kOneCmM = 0.01;
constexpr std::uint16_t kGroupFlag = 0x8000;

std::size_t block_offset(std::size_t b) { return kHeaderSize + b * kBlockSize; }
std::size_t slot_offset(std::size_t b, std::size_t slot) { return block_offset(b) + 4 + 3 * slot; }

std::uint16_t round_cdeg(double wrapped) {
  const long r = std::lround(wrapped);
  return static_cast<std::uint16_t>(r >= kFullTurnCdeg ? r - kFullTurnCdeg : r);
}

// Temperature bytes 38..39 (rs_driver parseTempInLe; ros_rslidar computeTemperature): byte 38 bits 3..7 are the
// low 5 bits, byte 39 bit 7 the sign and bits 0..6 the high bits; 0.0625 degC per LSB.
float temperature_c(ByteSpan p) {
  const int low = p[kTemperatureOffset] >> 3;
  const int high = p[kTemperatureOffset + 1] & 0x7F;
  const int magnitude = (high << 5) + low;
  const bool negative = (p[kTemperatureOffset + 1] & 0x80) != 0;
  return static_cast<float>(negative ? -magnitude : magnitude) * 0.0625F;
}

void check_calibration(const Calibration& c) {
  for (std::size_t i = 0; i < kChannels; ++i) {
    for (double a : {c.vert_deg[i], c.horiz_deg[i]}) {
      if (!std::isfinite(a) || std::abs(a) >= 90.0) {
        throw std::invalid_argument("RS-32 calibration: channel " + std::to_string(i) +
                                    " has an angle that is not a number between -90 and 90 degrees; check the "
                                    "configured angle table");
      }
    }
  }
}

// Tables differ when an angle differs by more than half the DIFOP's resolution (0.001 degree): a configured
// table written in degrees and the same table read from DIFOP are equal.
bool differs(const Calibration& a, const Calibration& b) {
  constexpr double kTolDeg = 0.0005;
  for (std::size_t i = 0; i < kChannels; ++i) {
    if (std::abs(a.vert_deg[i] - b.vert_deg[i]) > kTolDeg || std::abs(a.horiz_deg[i] - b.horiz_deg[i]) > kTolDeg) {
      return true;
    }
  }
  return false;
}

}  // namespace

Expected<MsopHeader, DecodeError> read_msop_header(ByteSpan p) {
  if (p.size() != kPacketSize) return Unexpected{DecodeError::BadLength};
  if (!std::equal(kMsopMagic.begin(), kMsopMagic.end(), p.begin())) return Unexpected{DecodeError::BadMagic};
  MsopHeader h;
  for (std::size_t b = 0; b < kBlocksPerPacket; ++b) {
    const std::size_t o = block_offset(b);
    if (p[o] != kBlockFlag0 || p[o + 1] != kBlockFlag1) return Unexpected{DecodeError::BadBlockFlag};
    h.azimuth_cdeg[b] = load_be16(p, o + 2);
    if (h.azimuth_cdeg[b] >= kFullTurnCdeg) return Unexpected{DecodeError::BadAzimuth};
  }
  const auto t = decode_ymd_time(p.subspan(kTimestampOffset, 10));
  if (!t) return Unexpected{DecodeError::BadTimestamp};
  h.sensor_time = *t;
  h.model_byte = p[kModelOffset];
  h.temperature_c = temperature_c(p);
  h.dual_layout = true;
  for (std::size_t b = 0; b < kBlocksPerPacket; b += 2) {
    if (h.azimuth_cdeg[b] != h.azimuth_cdeg[b + 1]) h.dual_layout = false;
  }
  return h;
}

const Calibration& nominal_calibration() {
  static const Calibration kNominal = [] {
    Calibration c;
    c.vert_deg = {-10.26, 0.30,  -6.41, -0.02, 2.28,  -0.33,  3.30,  -0.67,  4.61,  1.68,  7.02,
                  1.30,   10.30, 1.00,  15.02, 0.70,  -25.00, -2.28, -14.64, -2.67, -7.91, -3.02,
                  -5.41,  -3.30, -3.65, -1.02, -4.05, -1.33,  -4.39, -1.63,  -4.65, -1.98};
    return c;
  }();
  return kNominal;
}

Decoder::Decoder(DecoderOptions options) : options_(std::move(options)) {
  const auto& o = options_;
  if (!std::isfinite(o.min_range_m) || !std::isfinite(o.max_range_m) || o.min_range_m < 0.0 ||
      o.max_range_m <= o.min_range_m) {
    throw std::invalid_argument("RS-32 range limits: need 0 <= min_range_m < max_range_m");
  }
  if (!std::isfinite(o.optical_centre_offset_m) || std::abs(o.optical_centre_offset_m) > 1.0) {
    throw std::invalid_argument("RS-32 optical centre offset must be a few centimetres (rs_driver: 0.03997 m)");
  }
  if (o.calibration) set_calibration(*o.calibration);
  if (o.distance_unit == DistanceUnitOption::HalfCm) unit_ = DistanceUnit::HalfCm;
  if (o.distance_unit == DistanceUnitOption::OneCmGrouped) unit_ = DistanceUnit::OneCmGrouped;
  if (o.nominal_until_difop && !o.calibration) {
    set_calibration(nominal_calibration());
    nominal_ = true;
  }
  if (o.nominal_until_difop && !unit_) {
    unit_ = DistanceUnit::HalfCm;
    unit_assumed_ = true;
  }
  return_mode_ = o.return_mode;
}

void Decoder::set_calibration(const Calibration& c) {
  check_calibration(c);
  calibration_ = c;
  constexpr double kRadPerDeg = std::numbers::pi / 180.0;
  for (std::size_t i = 0; i < kChannels; ++i) {
    // Ring = rank by elevation, 0 = lowest (rs_driver genUserChan); equal angles ranked by channel.
    std::uint16_t ring = 0;
    for (std::size_t j = 0; j < kChannels; ++j) {
      if (c.vert_deg[j] < c.vert_deg[i] || (c.vert_deg[j] == c.vert_deg[i] && j < i)) ++ring;
    }
    table_[i] = Channel{.cos_vert = static_cast<float>(std::cos(c.vert_deg[i] * kRadPerDeg)),
                        .sin_vert = static_cast<float>(std::sin(c.vert_deg[i] * kRadPerDeg)),
                        .horiz_cdeg = static_cast<float>(c.horiz_deg[i] * 100.0),
                        .ring = ring};
  }
  turns_.resize(static_cast<std::size_t>(kMaxGroupStepCdeg) + 1);
  for (std::size_t step = 0; step < turns_.size(); ++step) fill_turns(static_cast<double>(step), turns_[step]);
}

void Decoder::fill_turns(double step_cdeg, std::array<ChannelTurn, kChannels>& out) const {
  constexpr double kRadPerCdeg = std::numbers::pi / 180.0 / 100.0;
  for (std::size_t c = 0; c < kChannels; ++c) {
    const double share = step_cdeg * (kFiringOffsetUs[c] / kBlockDurationUs);
    const double offset = share + static_cast<double>(table_[c].horiz_cdeg);
    out[c] = ChannelTurn{.cos_a = std::cos(offset * kRadPerCdeg),
                         .sin_a = std::sin(offset * kRadPerCdeg),
                         .cos_f = std::cos(share * kRadPerCdeg),
                         .sin_f = std::sin(share * kRadPerCdeg),
                         .offset_cdeg = offset};
  }
}

bool Decoder::apply(const DifopInfo& d) {
  rpm_ = d.rpm != 0 ? d.rpm : std::uint16_t{600};
  if (!options_.return_mode) return_mode_ = d.return_mode;
  if (options_.distance_unit == DistanceUnitOption::Auto && (!unit_ || unit_assumed_)) {
    unit_ = d.distance_unit;
    unit_assumed_ = false;
  }
  if (!d.calibration) return false;
  if (!calibration_ || nominal_) {
    nominal_ = false;
    set_calibration(*d.calibration);  // parse_difop checked the range, so this cannot throw
    return false;
  }
  return differs(*d.calibration, *calibration_);
}

Expected<MsopHeader, DecodeError> Decoder::decode(ByteSpan p, std::vector<LidarPoint>& out) const {
  const std::size_t before = out.size();
  out.resize(before + kMaxPointsPerPacket);
  std::size_t written = 0;
  auto header = decode(p, std::span<LidarPoint>(out).subspan(before), written);
  out.resize(before + written);
  return header;
}

Expected<MsopHeader, DecodeError> Decoder::decode(ByteSpan p, std::span<LidarPoint> room, std::size_t& written,
                                                  AzimuthRange* azimuths) const {
  written = 0;
  if (room.size() < kMaxPointsPerPacket) throw std::invalid_argument("RS-32 decode: room for fewer than 384 points");
  auto header = read_msop_header(p);
  if (!header) return header;
  if (!ready()) return Unexpected{DecodeError::NoCalibration};

  const ReturnMode mode =
      return_mode_ ? *return_mode_ : (header->dual_layout ? ReturnMode::Dual : ReturnMode::Strongest);
  const bool dual = mode == ReturnMode::Dual;
  const std::size_t step = dual ? 2 : 1;  // blocks per firing group
  const std::size_t groups = kBlocksPerPacket / step;

  // Azimuth of each firing group and its step to the next: the measured step when it is plausible, else the
  // previous plausible one, else the nominal step at the DIFOP's rpm (rs_driver's BLOCK_AZ_DURATION).
  const double nominal =
      static_cast<double>(kFullTurnCdeg) * (static_cast<double>(rpm_) / 60.0) * kBlockDurationUs * 1e-6;
  std::array<double, kBlocksPerPacket> az{};
  std::array<double, kBlocksPerPacket> delta{};
  double fallback = nominal;
  for (std::size_t g = 0; g < groups; ++g) {
    const int a = header->azimuth_cdeg[g * step];
    az[g] = a;
    double d = fallback;
    if (g + 1 < groups) {
      const int raw = (header->azimuth_cdeg[(g + 1) * step] - a + kFullTurnCdeg) % kFullTurnCdeg;
      if (raw <= kMaxGroupStepCdeg) d = raw;
    }
    fallback = d;
    delta[g] = d;
  }

  const bool grouped = *unit_ == DistanceUnit::OneCmGrouped;
  const double unit_m = grouped ? kOneCmM : kHalfCmM;
  const double min_r = options_.min_range_m;
  const double max_r = options_.max_range_m;
  const double offset_m = options_.optical_centre_offset_m;
  const ReturnType single_type = mode == ReturnMode::Last ? ReturnType::Last : ReturnType::Strongest;

  // Raw distance of channel c in block b (slot swap and flag of the old firmware's B blocks).
  auto raw_of = [&](std::size_t b, std::size_t c, std::uint8_t& intensity) {
    std::size_t slot = c;
    if (grouped && (load_be16(p, slot_offset(b, 0)) & kGroupFlag) != 0) slot = (c + kChannels / 2) % kChannels;
    intensity = p[slot_offset(b, slot) + 2];
    const std::uint16_t raw = load_be16(p, slot_offset(b, slot));
    return grouped ? static_cast<std::uint16_t>(raw & ~kGroupFlag) : raw;
  };

  const auto valid = [&](std::uint16_t raw) {
    const double d = static_cast<double>(raw) * unit_m;
    return raw != 0 && d >= min_r && d <= max_r;
  };

  constexpr double kRadPerCdeg = std::numbers::pi / 180.0 / 100.0;
  std::uint16_t min_cdeg = kFullTurnCdeg - 1;  // bounds on the firings' azimuths, for the rotation assembler
  std::uint16_t max_cdeg = 0;
  std::array<ChannelTurn, kChannels> odd_step{};  // a step with no table row (a fraction of 0.01 deg, or too big)
  for (std::size_t g = 0; g < groups; ++g) {
    // Each firing's azimuth is the group's turned by the channel's share of the step (and its correction): the
    // group's cosine and sine once, each channel's turn from the table of its step (no trigonometry per point).
    const double cos_g = std::cos(az[g] * kRadPerCdeg);
    const double sin_g = std::sin(az[g] * kRadPerCdeg);
    const double group_step = delta[g];
    const auto whole = static_cast<std::size_t>(group_step);
    const bool tabled = static_cast<double>(whole) == group_step && whole < turns_.size();
    if (!tabled) fill_turns(group_step, odd_step);
    const std::array<ChannelTurn, kChannels>& turns = tabled ? turns_[whole] : odd_step;
    for (std::size_t c = 0; c < kChannels; ++c) {
      // The returns first: a firing without one (a third of them in a field) costs no geometry.
      std::uint8_t i0 = 0;
      const std::uint16_t r0 = raw_of(g * step, c, i0);
      std::uint8_t i1 = 0;
      const std::uint16_t r1 = dual ? raw_of(g * step + 1, c, i1) : std::uint16_t{0};
      const bool v0 = valid(r0);
      const bool v1 = dual && valid(r1);
      if (!v0 && !v1) continue;

      const Channel& ch = table_[c];
      const ChannelTurn& t = turns[c];
      const double fire_us = static_cast<double>(g) * kBlockDurationUs + kFiringOffsetUs[c];
      double a = az[g] + t.offset_cdeg;  // within a turn and a half of 0: no fmod
      if (a >= kFullTurnCdeg) a -= kFullTurnCdeg;
      if (a < 0.0) a += kFullTurnCdeg;
      const double cos_a = cos_g * t.cos_a - sin_g * t.sin_a;
      const double sin_a = sin_g * t.cos_a + cos_g * t.sin_a;
      const double off_x = offset_m * (cos_g * t.cos_f - sin_g * t.sin_f);
      const double off_y = -offset_m * (sin_g * t.cos_f + cos_g * t.sin_f);
      const std::uint16_t a_cdeg = round_cdeg(a);
      min_cdeg = std::min(min_cdeg, a_cdeg);
      max_cdeg = std::max(max_cdeg, a_cdeg);
      const auto emit = [&](std::uint16_t raw, std::uint8_t intensity, ReturnType type) {
        const double d = static_cast<double>(raw) * unit_m;
        const double xy = d * static_cast<double>(ch.cos_vert);
        room[written++] = LidarPoint{.x = static_cast<float>(xy * cos_a + off_x),
                                     .y = static_cast<float>(-xy * sin_a + off_y),
                                     .z = static_cast<float>(d * static_cast<double>(ch.sin_vert)),
                                     .intensity = static_cast<float>(intensity),
                                     .time_s = static_cast<float>(fire_us * 1e-6),
                                     .range_m = static_cast<float>(d),
                                     .azimuth_cdeg = a_cdeg,
                                     .ring = ch.ring,
                                     .return_type = type,
                                     .source = 0,
                                     .reserved1 = 0};
      };
      if (!dual) {
        emit(r0, i0, single_type);
        continue;
      }
      // Dual: the first block of a pair holds the strongest return, the second the last one, or the second
      // strongest when the strongest is also the last (manual appendix A.2 and 7.1.3): nearer = second strongest.
      if (r0 == r1 && i0 == i1) {
        emit(r0, i0, ReturnType::StrongestAndLast);
        continue;
      }
      if (v0) emit(r0, i0, ReturnType::Strongest);
      if (v1) emit(r1, i1, v0 && r1 < r0 ? ReturnType::SecondStrongest : ReturnType::Last);
    }
  }
  if (azimuths != nullptr) *azimuths = min_cdeg <= max_cdeg ? AzimuthRange{min_cdeg, max_cdeg} : AzimuthRange{};
  return header;
}

}  // namespace fieldguard::robosense
