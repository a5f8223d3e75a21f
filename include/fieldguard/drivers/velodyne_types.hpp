#pragma once
// Velodyne HDL-32E / VLP-16 wire constants and small enums (../shared/docs/protocols.md §1).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace fieldguard::velodyne {

inline constexpr std::size_t kDataPacketSize = 1206;
inline constexpr std::size_t kPositionPacketSize = 512;
inline constexpr std::size_t kBlocksPerPacket = 12;
inline constexpr std::size_t kBlockSize = 100;
inline constexpr std::size_t kSlotsPerBlock = 32;
inline constexpr std::uint16_t kDefaultDataPort = 2368;
inline constexpr std::uint16_t kDefaultPositionPort = 8308;

enum class Model : std::uint8_t { Unknown = 0, HDL32E, VLP16 };
enum class ReturnMode : std::uint8_t { Strongest = 0, Last, Dual };

// Which firing the packet's 4-byte timestamp marks (protocols.md §1.7 [conflict]).
enum class TimestampReference : std::uint8_t { FirstFiring = 0, LastFiring };

[[nodiscard]] std::string_view to_string(Model m);
[[nodiscard]] std::string_view to_string(ReturnMode m);
[[nodiscard]] std::optional<Model> model_from_string(std::string_view s);  // "HDL-32E", "VLP-16", "auto"->Unknown

// Decode errors of data and position packets. Each is counted by the caller, never thrown.
enum class DecodeError : std::uint8_t {
  BadLength,      // payload is not 1206 (data) / 512 (position) bytes
  BadBlockFlag,   // a block does not start with FF EE
  BadAzimuth,     // an azimuth >= 36000
  BadReturnMode,  // factory byte 1204 not 0x37/0x38/0x39 and dual layout not recognisable
  ModelMismatch,  // packet layout contradicts the configured model
  NoModel,        // model not configured and not yet detected from the stream
};
[[nodiscard]] std::string_view to_string(DecodeError e);
inline constexpr std::size_t kDecodeErrorCount = 6;

}  // namespace fieldguard::velodyne
