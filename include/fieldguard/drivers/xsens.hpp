#pragma once
// Xsens Xbus frames (protocols.md §5.1): preamble 0xFA, bus id 0xFF, message id, length (0xFF: a 2-byte
// big-endian extended length follows), payload, checksum (bus id .. checksum sum to 0 mod 256).
// Pure: bytes in, a view of the message or an error out. MTData2 payloads: xsens_mtdata2.hpp; a byte stream
// with garbage and resynchronisation: xsens_stream.hpp.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/expected.hpp"

namespace fieldguard::xsens {

inline constexpr std::uint8_t kPreamble = 0xFA;
inline constexpr std::uint8_t kBusMaster = 0xFF;       // the only bus id an MTi uses
inline constexpr std::uint8_t kExtendedLength = 0xFF;  // length byte announcing the 2-byte length
// Largest payload accepted. The Xbus extended length goes to 65535, but Xsens devices send at most 2048 bytes
// (MT Manager's EMTS dump, the longest message in the captures we have, is 1320); capping keeps the stream
// parser's buffer bounded and a corrupted length from stalling it for long.
inline constexpr std::size_t kMaxPayload = 2048;
inline constexpr std::size_t kMaxFrameSize = 6 + kMaxPayload + 1;

// Message ids (protocols.md §5.2). Replies are the request + 1.
namespace mid {
inline constexpr std::uint8_t kReqDeviceId = 0x00;
inline constexpr std::uint8_t kDeviceId = 0x01;
inline constexpr std::uint8_t kInitMt = 0x02;
inline constexpr std::uint8_t kInitMtResults = 0x03;
inline constexpr std::uint8_t kReqConfiguration = 0x0C;
inline constexpr std::uint8_t kConfiguration = 0x0D;
inline constexpr std::uint8_t kGoToMeasurement = 0x10;
inline constexpr std::uint8_t kGoToMeasurementAck = 0x11;
inline constexpr std::uint8_t kReqFirmwareRevision = 0x12;
inline constexpr std::uint8_t kFirmwareRevision = 0x13;
inline constexpr std::uint8_t kReqProductCode = 0x1C;
inline constexpr std::uint8_t kProductCode = 0x1D;
inline constexpr std::uint8_t kGoToConfig = 0x30;
inline constexpr std::uint8_t kGoToConfigAck = 0x31;
inline constexpr std::uint8_t kMtData = 0x32;  // legacy measurement message: layout depends on the configuration
inline constexpr std::uint8_t kMtData2 = 0x36;
inline constexpr std::uint8_t kWakeUp = 0x3E;
inline constexpr std::uint8_t kWakeUpAck = 0x3F;
inline constexpr std::uint8_t kReset = 0x40;
inline constexpr std::uint8_t kError = 0x42;
inline constexpr std::uint8_t kReqFilterProfile = 0x64;
inline constexpr std::uint8_t kFilterProfile = 0x65;
inline constexpr std::uint8_t kSetOutputConfiguration = 0xC0;
inline constexpr std::uint8_t kOutputConfiguration = 0xC1;
}  // namespace mid

// A name for a message id ("MTData2", "GoToConfigAck", ...), or "" when we do not know it.
[[nodiscard]] std::string_view message_name(std::uint8_t mid);

enum class Error : std::uint8_t {
  TooShort,     // fewer bytes than the header or the length field says
  BadPreamble,  // not 0xFA 0xFF
  TooLong,      // payload length over kMaxPayload
  BadChecksum,
  NotMtData2,       // decode_mtdata2_message on another message id
  TruncatedPacket,  // an MTData2 packet (id, size, data) runs past the end of the payload
  BadPacketSize,    // a known data id whose size does not fit its type and precision
};
[[nodiscard]] std::string_view to_string(Error e);

// One message: a view into the caller's bytes.
struct Message {
  std::uint8_t bus_id = kBusMaster;
  std::uint8_t mid = 0;
  ByteSpan payload;
  std::size_t frame_size = 0;  // preamble to checksum, inclusive
};

// Sum of the bytes, mod 256. A frame is valid when the sum from the bus id to the checksum is 0.
[[nodiscard]] std::uint8_t byte_sum(ByteSpan bytes);

// Decodes the frame at the start of `bytes` (which may hold more after it).
[[nodiscard]] Expected<Message, Error> decode_frame(ByteSpan bytes);

// A complete frame for `payload` (extended length when it is over 254 bytes). For tests and emulators.
[[nodiscard]] std::vector<std::uint8_t> encode_frame(std::uint8_t mid, ByteSpan payload);

}  // namespace fieldguard::xsens
