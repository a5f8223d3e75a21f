#pragma once
// The tractor's speed read off the bus, to size the stop zone: J1939 CCVS1 (PGN 65265, wheel-based vehicle
// speed, SPN 84: bytes 2-3, 1/256 km/h) or ISO 11783-7 wheel-based speed and distance (PGN 65096, SPN 1862:
// bytes 1-2, 0.001 m/s). Both are the magnitude only: the ISO message's direction bits are not decoded
// (open implementations disagree on which value is forward). Pure decoder: bytes in, value or error out.

#include <cstdint>
#include <span>
#include <string_view>

#include "fieldguard/core/expected.hpp"

namespace fieldguard::output {

inline constexpr std::uint32_t kPgnCcvs1 = 65265;               // 0xFEF1
inline constexpr std::uint32_t kPgnIsoWheelBasedSpeed = 65096;  // 0xFE48

enum class SpeedSource : std::uint8_t { Ccvs1 = 0, IsoWheelBased = 1 };

struct BusSpeed {
  double speed_mps = 0.0;
  SpeedSource source = SpeedSource::Ccvs1;
  std::uint8_t source_address = 0;
};

enum class SpeedError : std::uint8_t {
  OtherPgn,      // not a speed message: ignore it
  TooShort,      // fewer data bytes than the parameter needs
  NotAvailable,  // 0xFFxx: the sender has no speed
  SenderError,   // 0xFExx: the sender flags an error
  Reserved,      // 0xFB00-0xFDFF: outside the J1939 valid range
};
[[nodiscard]] std::string_view to_string(SpeedError e);

// `can_id` is the 29-bit id (no flag bits).
[[nodiscard]] Expected<BusSpeed, SpeedError> decode_speed(std::uint32_t can_id, std::span<const std::uint8_t> data);

}  // namespace fieldguard::output
