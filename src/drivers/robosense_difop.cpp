// RoboSense RS-32 DIFOP (device information) packet (protocols.md §2.3; rs_driver RS32DifopPkt).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

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

// angle.csv: one channel a line; blank lines and a trailing newline are allowed, nothing else.
Expected<Calibration, std::string> parse_angle_csv(std::string_view text) {
  Calibration c;
  std::size_t channel = 0;
  std::size_t line_no = 0;
  while (!text.empty()) {
    const std::size_t end = std::min(text.find('\n'), text.size());
    std::string line(text.substr(0, end));
    text.remove_prefix(std::min(end + 1, text.size()));
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    const auto bad = [&](const std::string& why) {
      return Unexpected{"angle.csv line " + std::to_string(line_no) + ": " + why};
    };
    if (channel == kChannels) return bad("more than 32 channels");
    const std::size_t comma = line.find(',');
    std::array<double, 2> v{0.0, 0.0};
    const std::array<std::string, 2> fields = {line.substr(0, comma),
                                               comma == std::string::npos ? "0" : line.substr(comma + 1)};
    for (std::size_t i = 0; i < 2; ++i) {
      char* stop = nullptr;
      v[i] = std::strtod(fields[i].c_str(), &stop);
      if (stop == fields[i].c_str() || std::string_view(stop).find_first_not_of(" \t") != std::string_view::npos ||
          !std::isfinite(v[i]) || std::abs(v[i]) >= 90.0) {
        return bad("'" + fields[i] + "' is not an angle in degrees between -90 and 90");
      }
    }
    c.vert_deg[channel] = v[0];
    c.horiz_deg[channel] = v[1];
    ++channel;
  }
  if (channel != kChannels) {
    return Unexpected{"angle.csv has " + std::to_string(channel) + " channels; an RS-32's has 32 lines"};
  }
  return c;
}

}  // namespace fieldguard::robosense
