#include "fieldguard/output/can_speed.hpp"

#include "fieldguard/output/can_frame.hpp"

namespace fieldguard::output {
namespace {

// J1939 ranges of a 2-byte parameter: 0x0000-0xFAFF valid, 0xFB00-0xFDFF reserved, 0xFExx error, 0xFFxx n/a.
constexpr std::uint16_t kMaxValid16 = 0xFAFF;

}  // namespace

std::string_view to_string(SpeedError e) {
  switch (e) {
    case SpeedError::OtherPgn: return "other_pgn";
    case SpeedError::TooShort: return "too_short";
    case SpeedError::NotAvailable: return "not_available";
    case SpeedError::SenderError: return "sender_error";
    case SpeedError::Reserved: return "reserved";
  }
  return "unknown";
}

Expected<BusSpeed, SpeedError> decode_speed(std::uint32_t can_id, std::span<const std::uint8_t> data) {
  const J1939Fields f = j1939_fields(can_id & kEffMask);
  std::size_t at = 0;
  double scale_mps = 0.0;
  BusSpeed out;
  out.source_address = f.source;
  if (f.pgn == kPgnCcvs1) {
    at = 1;
    scale_mps = 1.0 / 256.0 / 3.6;  // 1/256 km/h per bit
    out.source = SpeedSource::Ccvs1;
  } else if (f.pgn == kPgnIsoWheelBasedSpeed) {
    at = 0;
    scale_mps = 0.001;
    out.source = SpeedSource::IsoWheelBased;
  } else {
    return Unexpected{SpeedError::OtherPgn};
  }
  if (data.size() < at + 2) return Unexpected{SpeedError::TooShort};
  const auto raw = static_cast<std::uint16_t>(data[at] | data[at + 1] << 8U);  // J1939: little-endian
  if (raw > kMaxValid16) {
    if (raw >= 0xFF00) return Unexpected{SpeedError::NotAvailable};
    if (raw >= 0xFE00) return Unexpected{SpeedError::SenderError};
    return Unexpected{SpeedError::Reserved};
  }
  out.speed_mps = raw * scale_mps;
  return out;
}

}  // namespace fieldguard::output
