// RoboSense RS-32 small pieces: enum names, the 3-byte angle record, the YMD time, the firmware rule.
#include <array>
#include <cassert>
#include <cstdint>

#include "fieldguard/drivers/robosense.hpp"

namespace fieldguard::robosense {

namespace {

bool is_leap(int year) { return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0; }

int days_in_month(int year, int month) {
  constexpr std::array<int, 12> kDays = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (month == 2 && is_leap(year)) return 29;
  return kDays[static_cast<std::size_t>(month - 1)];
}

// Days since 1970-01-01 of a date in the proleptic Gregorian calendar (year >= 1970): whole years, then whole
// months of the year. Plain counting: the years here are 2000..2255, so a loop is cheap and obviously right.
std::int64_t days_since_epoch(int year, int month, int day) {
  std::int64_t days = 0;
  for (int y = 1970; y < year; ++y) days += is_leap(y) ? 366 : 365;
  for (int m = 1; m < month; ++m) days += days_in_month(year, m);
  return days + (day - 1);
}

}  // namespace

std::string_view to_string(ReturnMode m) {
  switch (m) {
    case ReturnMode::Dual: return "dual";
    case ReturnMode::Strongest: return "strongest";
    case ReturnMode::Last: return "last";
  }
  return "unknown";
}

std::string_view to_string(DistanceUnit u) {
  switch (u) {
    case DistanceUnit::HalfCm: return "0.5cm";
    case DistanceUnit::OneCmGrouped: return "1cm_grouped";
  }
  return "unknown";
}

std::string_view to_string(DecodeError e) {
  switch (e) {
    case DecodeError::BadLength: return "bad_length";
    case DecodeError::BadMagic: return "bad_magic";
    case DecodeError::BadBlockFlag: return "bad_block_flag";
    case DecodeError::BadAzimuth: return "bad_azimuth";
    case DecodeError::BadTimestamp: return "bad_timestamp";
    case DecodeError::BadAngleTable: return "bad_angle_table";
    case DecodeError::NoCalibration: return "no_calibration";
  }
  return "unknown";
}

std::optional<std::int32_t> decode_angle_millideg(ByteSpan triplet) {
  assert(triplet.size() >= 3);
  const auto magnitude = static_cast<std::int32_t>(load_be16(triplet, 1));
  if (triplet[0] == 0x00) return magnitude;
  if (triplet[0] == 0x01) return -magnitude;
  return std::nullopt;
}

std::optional<Stamp> decode_ymd_time(ByteSpan b) {
  assert(b.size() >= 10);
  const int year = 2000 + b[0];
  const int month = b[1];
  const int day = b[2];
  const int hour = b[3];
  const int minute = b[4];
  const int second = b[5];
  const int ms = load_be16(b, 6);
  const int us = load_be16(b, 8);
  if (month < 1 || month > 12 || day < 1 || day > days_in_month(year, month)) return std::nullopt;
  if (hour > 23 || minute > 59 || second > 60 || ms > 999 || us > 999) return std::nullopt;
  const std::int64_t seconds = days_since_epoch(year, month, day) * 86'400 + hour * 3'600 + minute * 60 + second;
  const std::int64_t micros = seconds * 1'000'000 + ms * 1'000 + us;
  return Stamp{micros * 1'000};
}

DistanceUnit distance_unit_from_firmware(std::uint8_t b41, std::uint8_t b42, std::uint8_t b43) {
  const auto is = [&](std::uint8_t x, std::uint8_t y, std::uint8_t z) { return b41 == x && b42 == y && b43 == z; };
  if (is(0x00, 0x00, 0x00) || is(0xFF, 0xFF, 0xFF) || is(0x55, 0xAA, 0x5A) || is(0xE9, 0x01, 0x00)) {
    return DistanceUnit::OneCmGrouped;
  }
  return DistanceUnit::HalfCm;
}

}  // namespace fieldguard::robosense
