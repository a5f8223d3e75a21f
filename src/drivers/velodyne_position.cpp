// Velodyne position packet, protocols.md §1.9.

#include "fieldguard/drivers/velodyne_position.hpp"

#include <algorithm>
#include <string_view>

namespace fieldguard::velodyne {
namespace {

constexpr std::size_t kImuOffset = 14;  // gyro k at 14 + 8k, temperature 16 + 8k, accel X 18 + 8k, Y 20 + 8k
constexpr std::size_t kImuStride = 8;
constexpr std::size_t kTimestampOffset = 198;
constexpr std::size_t kPpsOffset = 202;
constexpr std::size_t kNmeaOffset = 206;

// Scales: VeloView only [single-source].
constexpr double kGyroDpsPerLsb = 0.09766;
constexpr double kTempCPerLsb = 0.1453;
constexpr double kTempOffsetC = 25.0;
constexpr double kAccelGPerLsb = 0.001221;

// The low 12 bits of a 16-bit LE word as a two's-complement number (the top 4 bits are not part of it).
[[nodiscard]] int s12(ByteSpan b, std::size_t off) {
  const int raw = load_le16(b, off) & 0x0FFF;
  return raw >= 0x800 ? raw - 0x1000 : raw;
}

[[nodiscard]] PpsStatus pps_of(std::uint8_t b) {
  switch (b) {
    case 0: return PpsStatus::Absent;
    case 1: return PpsStatus::Synchronizing;
    case 2: return PpsStatus::Locked;
    case 3: return PpsStatus::Error;
    default: return PpsStatus::Unknown;
  }
}

}  // namespace

std::string_view to_string(PpsStatus s) {
  switch (s) {
    case PpsStatus::Absent: return "absent";
    case PpsStatus::Synchronizing: return "synchronizing";
    case PpsStatus::Locked: return "locked";
    case PpsStatus::Error: return "error";
    case PpsStatus::Unknown: break;
  }
  return "unknown";
}

Expected<PositionPacket, DecodeError> decode_position_packet(ByteSpan payload) {
  if (payload.size() != kPositionPacketSize) return Unexpected{DecodeError::BadLength};
  PositionPacket p;
  for (std::size_t k = 0; k < 3; ++k) {
    const std::size_t base = kImuOffset + kImuStride * k;
    p.gyro_dps[k] = s12(payload, base) * kGyroDpsPerLsb;
    p.temperature_c[k] = s12(payload, base + 2) * kTempCPerLsb + kTempOffsetC;
    p.accel_x_g[k] = s12(payload, base + 4) * kAccelGPerLsb;
    p.accel_y_g[k] = s12(payload, base + 6) * kAccelGPerLsb;
  }
  p.timestamp_us = load_le32(payload, kTimestampOffset);
  p.pps = pps_of(payload[kPpsOffset]);

  // The sentence runs to the first NUL (or the end of the packet); its line terminator is dropped too.
  const auto text = payload.subspan(kNmeaOffset);
  const auto end = std::find(text.begin(), text.end(), std::uint8_t{0});
  p.nmea.assign(text.begin(), end);
  while (!p.nmea.empty() && (p.nmea.back() == '\r' || p.nmea.back() == '\n')) p.nmea.pop_back();
  if (!p.nmea.empty()) {
    auto rmc = nmea::parse_rmc(p.nmea);
    if (rmc) {
      p.rmc = std::move(rmc).value();
    } else {
      p.nmea_error = rmc.error();
    }
  }
  return p;
}

}  // namespace fieldguard::velodyne
