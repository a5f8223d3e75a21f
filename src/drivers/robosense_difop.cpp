// RoboSense RS-32 DIFOP (device information) packet (protocols.md §2.3; rs_driver RS32DifopPkt).
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>

#include "fieldguard/drivers/robosense.hpp"

namespace fieldguard::robosense {

namespace {

constexpr std::array<std::uint8_t, 8> kDifopMagic = {0xA5, 0xFF, 0x00, 0x5A, 0x11, 0x11, 0x55, 0x55};
constexpr std::size_t kRpmOffset = 8;
constexpr std::size_t kFovOffset = 32;
constexpr std::size_t kTopFirmwareOffset = 40;
constexpr std::size_t kBottomFirmwareOffset = 45;
constexpr std::size_t kSerialOffset = 292;
constexpr std::size_t kReturnModeOffset = 300;
constexpr std::size_t kUtcTimeOffset = 303;
constexpr std::size_t kVertTableOffset = 468;
constexpr std::size_t kHorizTableOffset = 564;
constexpr std::int32_t kMaxAbsMillideg = 90'000;  // rs_driver angleCheck: -90 <= angle < 90 degrees

// A vertical table that was never written: every record 00 00 00 or FF FF FF (ros_rslidar checks the first
// bytes for 00/FF; rs_driver refuses a sign byte FF).
bool table_unwritten(ByteSpan p, std::size_t offset) {
  for (std::size_t c = 0; c < kChannels; ++c) {
    const std::size_t o = offset + 3 * c;
    const bool zero = p[o] == 0x00 && p[o + 1] == 0x00 && p[o + 2] == 0x00;
    const bool ff = p[o] == 0xFF && p[o + 1] == 0xFF && p[o + 2] == 0xFF;
    if (!zero && !ff) return false;
  }
  return true;
}

// Decodes one table into degrees; false if a record is undecodable or out of range.
bool read_table(ByteSpan p, std::size_t offset, std::array<double, kChannels>& deg) {
  for (std::size_t c = 0; c < kChannels; ++c) {
    const auto v = decode_angle_millideg(p.subspan(offset + 3 * c, 3));
    if (!v || std::abs(*v) >= kMaxAbsMillideg) return false;
    deg[c] = static_cast<double>(*v) * 0.001;
  }
  return true;
}

}  // namespace

Expected<DifopInfo, DecodeError> parse_difop(ByteSpan p) {
  if (p.size() != kPacketSize) return Unexpected{DecodeError::BadLength};
  if (!std::equal(kDifopMagic.begin(), kDifopMagic.end(), p.begin())) return Unexpected{DecodeError::BadMagic};

  DifopInfo d;
  d.rpm = load_be16(p, kRpmOffset);
  d.fov_start_cdeg = load_be16(p, kFovOffset);
  d.fov_end_cdeg = load_be16(p, kFovOffset + 2);
  std::copy_n(p.begin() + kTopFirmwareOffset, d.top_firmware.size(), d.top_firmware.begin());
  std::copy_n(p.begin() + kBottomFirmwareOffset, d.bottom_firmware.size(), d.bottom_firmware.begin());
  std::copy_n(p.begin() + kSerialOffset, d.serial.size(), d.serial.begin());
  d.return_mode_byte = p[kReturnModeOffset];
  switch (d.return_mode_byte) {
    case 0x00: d.return_mode = ReturnMode::Dual; break;
    case 0x02: d.return_mode = ReturnMode::Last; break;
    default: d.return_mode = ReturnMode::Strongest; break;  // 0x01, and rs_driver's default for the rest
  }
  d.utc_time = decode_ymd_time(p.subspan(kUtcTimeOffset, 10));
  d.distance_unit = distance_unit_from_firmware(p[41], p[42], p[43]);

  if (table_unwritten(p, kVertTableOffset)) return d;
  Calibration cal;
  if (!read_table(p, kVertTableOffset, cal.vert_deg) || !read_table(p, kHorizTableOffset, cal.horiz_deg)) {
    return Unexpected{DecodeError::BadAngleTable};
  }
  d.calibration = cal;
  return d;
}

}  // namespace fieldguard::robosense
