// Xbus framing (protocols.md §5.1).

#include <array>
#include <utility>

#include "fieldguard/drivers/xsens.hpp"

namespace fieldguard::xsens {
namespace {

constexpr std::size_t kHeader = 4;          // preamble, bus id, mid, length
constexpr std::size_t kExtendedHeader = 6;  // + 2-byte length

constexpr std::array<std::pair<std::uint8_t, std::string_view>, 24> kNames = {{
    {mid::kReqDeviceId, "ReqDID"},
    {mid::kDeviceId, "DeviceID"},
    {mid::kInitMt, "InitMT"},
    {mid::kInitMtResults, "InitMTResults"},
    {mid::kReqConfiguration, "ReqConfiguration"},
    {mid::kConfiguration, "Configuration"},
    {mid::kGoToMeasurement, "GoToMeasurement"},
    {mid::kGoToMeasurementAck, "GoToMeasurementAck"},
    {mid::kReqFirmwareRevision, "ReqFWRev"},
    {mid::kFirmwareRevision, "FirmwareRev"},
    {mid::kReqProductCode, "ReqProductCode"},
    {mid::kProductCode, "ProductCode"},
    {mid::kGoToConfig, "GoToConfig"},
    {mid::kGoToConfigAck, "GoToConfigAck"},
    {mid::kMtData, "MTData"},
    {mid::kMtData2, "MTData2"},
    {mid::kWakeUp, "WakeUp"},
    {mid::kWakeUpAck, "WakeUpAck"},
    {mid::kReset, "Reset"},
    {mid::kError, "Error"},
    {mid::kReqFilterProfile, "ReqFilterProfile"},
    {mid::kFilterProfile, "FilterProfile"},
    {mid::kSetOutputConfiguration, "SetOutputConfiguration"},
    {mid::kOutputConfiguration, "OutputConfiguration"},
}};

}  // namespace

std::string_view message_name(std::uint8_t id) {
  for (const auto& [m, name] : kNames) {
    if (m == id) return name;
  }
  return {};
}

std::string_view to_string(Error e) {
  switch (e) {
    case Error::TooShort: return "too_short";
    case Error::BadPreamble: return "bad_preamble";
    case Error::TooLong: return "too_long";
    case Error::BadChecksum: return "bad_checksum";
    case Error::NotMtData2: return "not_mtdata2";
    case Error::TruncatedPacket: return "truncated_packet";
    case Error::BadPacketSize: return "bad_packet_size";
  }
  return "unknown";
}

std::uint8_t byte_sum(ByteSpan bytes) {
  unsigned sum = 0;
  for (const std::uint8_t b : bytes) sum += b;
  return static_cast<std::uint8_t>(sum & 0xFFU);
}

Expected<Message, Error> decode_frame(ByteSpan bytes) {
  if (bytes.size() < 2) return Unexpected{Error::TooShort};
  if (bytes[0] != kPreamble || bytes[1] != kBusMaster) return Unexpected{Error::BadPreamble};
  if (bytes.size() < kHeader) return Unexpected{Error::TooShort};
  std::size_t header = kHeader;
  std::size_t length = bytes[3];
  if (length == kExtendedLength) {
    if (bytes.size() < kExtendedHeader) return Unexpected{Error::TooShort};
    header = kExtendedHeader;
    length = load_be16(bytes, 4);
  }
  if (length > kMaxPayload) return Unexpected{Error::TooLong};
  const std::size_t total = header + length + 1;
  if (bytes.size() < total) return Unexpected{Error::TooShort};
  if (byte_sum(bytes.subspan(1, total - 1)) != 0) return Unexpected{Error::BadChecksum};
  Message m;
  m.bus_id = bytes[1];
  m.mid = bytes[2];
  m.payload = bytes.subspan(header, length);
  m.frame_size = total;
  return m;
}

std::vector<std::uint8_t> encode_frame(std::uint8_t id, ByteSpan payload) {
  std::vector<std::uint8_t> f;
  f.reserve(payload.size() + kExtendedHeader + 1);
  f.push_back(kPreamble);
  f.push_back(kBusMaster);
  f.push_back(id);
  if (payload.size() >= kExtendedLength) {
    f.push_back(kExtendedLength);
    f.push_back(static_cast<std::uint8_t>((payload.size() >> 8) & 0xFFU));
    f.push_back(static_cast<std::uint8_t>(payload.size() & 0xFFU));
  } else {
    f.push_back(static_cast<std::uint8_t>(payload.size()));
  }
  f.insert(f.end(), payload.begin(), payload.end());
  const std::uint8_t sum = byte_sum(ByteSpan(f).subspan(1));
  f.push_back(static_cast<std::uint8_t>((0x100U - sum) & 0xFFU));
  return f;
}

}  // namespace fieldguard::xsens
