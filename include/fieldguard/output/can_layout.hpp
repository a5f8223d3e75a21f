#pragma once
// The CAN messages fieldguard sends, defined once: every signal's place, scaling, range, unit and value
// names. The encoder packs from this table and config/fieldguard.dbc is printed from it (dbc.hpp), so the
// two cannot drift apart. Conventions (protocols.md §7.3-7.5): 29-bit J1939 ids with proprietary PGNs,
// little-endian (Intel, DBC @1) signals as J1939 does for multi-byte parameters, physical = raw * scale +
// offset.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace fieldguard::output {

enum class ByteOrder : std::uint8_t { Intel, Motorola };  // DBC @1 / @0

// What the packer does with a value outside [min, max]: clamp it and count it (a measurement), or take it
// modulo 2^length (a counter, which the receiver differences).
enum class Overflow : std::uint8_t { Saturate, Wrap };

struct ValueName {
  std::int64_t raw;
  std::string_view name;
};

struct Signal {
  std::string_view name;
  std::uint16_t start_bit;  // Intel: the LSB; Motorola: the MSB in DBC sawtooth numbering
  std::uint8_t length;      // bits, 1..64
  ByteOrder order = ByteOrder::Intel;
  bool is_signed = false;  // two's complement raw value
  double scale = 1.0;
  double offset = 0.0;
  double min = 0.0;  // physical range; values beyond it saturate (Overflow::Saturate)
  double max = 0.0;
  std::string_view unit = {};
  std::string_view comment = {};
  std::span<const ValueName> values = {};
  Overflow overflow = Overflow::Saturate;
};

enum class MessageId : std::uint8_t { ObstacleSummary = 0, Obstacle = 1, StopRequest = 2, Heartbeat = 3 };
inline constexpr std::size_t kMessageCount = 4;

struct MessageLayout {
  MessageId id;
  std::string_view name;
  std::uint32_t pgn;  // 18 bits; PDU1 (PF < 240) PGNs are addressed to the controller
  std::uint8_t default_priority;
  std::uint8_t dlc;
  std::uint32_t cycle_ms;  // 0 = once per pipeline frame, not on a timer
  std::string_view comment;
  std::span<const Signal> signals;
  // The DBC's view only (dbc.cpp), the frame is the same: the signal every other signal is multiplexed on, so that
  // a tool's signal view shows each of its values apart (FG_OBSTACLE: Index, XMin_0 ... XMin_15). "" = none.
  std::string_view multiplexor = {};
};

[[nodiscard]] std::span<const MessageLayout> message_layouts();
[[nodiscard]] const MessageLayout& layout(MessageId id);

// Signal indices into each message's table (checked against the names at compile time in can_layout.cpp).
namespace summary_sig {
enum : std::size_t { ObstacleCount, NearestDistance, NearestBearing, FrameCounter, Status, ListTruncated, Saturated };
}
namespace obstacle_sig {
enum : std::size_t { Index, SizeClass, XMin, XMax, YMin, YMax, Height, Points };
}
namespace stop_sig {
enum : std::size_t {
  Command,
  ReasonObstacle,
  ReasonSensorFault,
  ReasonPipelineLate,
  ReasonStartingUp,
  ReasonShuttingDown,
  AliveCounter,
  Crc
};
}
namespace heartbeat_sig {
enum : std::size_t { Lidar3d, Lidar2d, Gnss, Ahrs, FramesLost, SaturatedValues, AliveCounter, Crc };
}

// Raw field access. Bits outside the signal are left alone; `raw` is taken modulo 2^length.
void put_raw(std::span<std::uint8_t, 8> data, const Signal& s, std::uint64_t raw);
[[nodiscard]] std::uint64_t get_raw(std::span<const std::uint8_t, 8> data, const Signal& s);

// Physical value -> raw field. Returns false when the value was outside [min, max] (or NaN) and was
// clamped: the caller counts it. NaN goes to `min`'s raw value. Counters (Overflow::Wrap) never clamp.
[[nodiscard]] bool put_physical(std::span<std::uint8_t, 8> data, const Signal& s, double value);
// Raw field -> physical value (sign-extended for signed signals).
[[nodiscard]] double get_physical(std::span<const std::uint8_t, 8> data, const Signal& s);

}  // namespace fieldguard::output
