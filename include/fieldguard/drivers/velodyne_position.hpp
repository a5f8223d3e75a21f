#pragma once
// Velodyne position packet (UDP 8308, 512 bytes, protocols.md §1.9): timestamp, PPS status, the NMEA
// sentence the sensor received from its GPS, and the gyro/temperature/accelerometer words.

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/expected.hpp"
#include "fieldguard/drivers/nmea.hpp"
#include "fieldguard/drivers/velodyne_types.hpp"

namespace fieldguard::velodyne {

enum class PpsStatus : std::uint8_t { Absent = 0, Synchronizing = 1, Locked = 2, Error = 3, Unknown = 255 };
[[nodiscard]] std::string_view to_string(PpsStatus s);

struct PositionPacket {
  std::uint32_t timestamp_us = 0;         // past the top of the hour
  PpsStatus pps = PpsStatus::Unknown;     // byte 202 (newer firmware; HDL-32E leaves it 0 = Absent)
  std::string nmea;                       // the sentence as received, NUL padding and CR LF removed, "" if none
  std::optional<nmea::Rmc> rmc;           // decoded when nmea is a valid RMC
  std::optional<nmea::Error> nmea_error;  // why a non-empty sentence did not decode
  std::array<double, 3> gyro_dps{};       // HDL-32E gyros k = 0..2, degrees per second [single-source scales]
  std::array<double, 3> temperature_c{};
  std::array<double, 3> accel_x_g{};
  std::array<double, 3> accel_y_g{};
};

[[nodiscard]] Expected<PositionPacket, DecodeError> decode_position_packet(ByteSpan payload);

}  // namespace fieldguard::velodyne
