#pragma once
// NMEA 0183 sentence parsing (protocols.md §4). Pure: one sentence of text in, a typed record or an error out.
// This first cut covers what the Velodyne position packet carries (RMC) and GGA; the GNSS issue extends it.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "fieldguard/core/expected.hpp"

namespace fieldguard::nmea {

enum class Error : std::uint8_t {
  NoStart,        // does not start with '$'
  TooLong,        // over the 82-character limit (with some slack for real receivers, see src/drivers/nmea_sentence.hpp)
  BadChecksum,    // '*hh' present and wrong
  NoChecksum,     // no '*hh' (always an error for now: no caller option to accept unchecked sentences yet)
  BadField,       // a field that must be a number is not
  Unsupported,    // a sentence type we do not decode
};
[[nodiscard]] std::string_view to_string(Error e);

// XOR of the bytes between '$' and '*'.
[[nodiscard]] std::uint8_t checksum(std::string_view body);

struct Rmc {
  std::string talker;                      // "GP", "GN", ...
  std::optional<double> utc_seconds_of_day;
  bool valid = false;                      // status 'A'
  std::optional<double> lat_deg;           // south negative
  std::optional<double> lon_deg;           // west negative
  std::optional<double> speed_mps;
  std::optional<double> course_deg;
  std::optional<int> day, month, year;     // year as 4 digits (2-digit years are 1980..2079)
  char mode = 0;                           // NMEA >= 2.3 mode indicator, 0 if absent
};

struct Gga {
  std::string talker;
  std::optional<double> utc_seconds_of_day;
  std::optional<double> lat_deg;
  std::optional<double> lon_deg;
  int quality = 0;                         // 0 invalid, 1 GPS, 2 DGPS, 4 RTK fixed, 5 RTK float, ...
  std::optional<int> satellites;
  std::optional<double> hdop;
  std::optional<double> alt_m;             // above mean sea level
  std::optional<double> geoid_sep_m;
};

// Parses "$GPRMC,...*hh" (trailing CR/LF and NULs tolerated).
[[nodiscard]] Expected<Rmc, Error> parse_rmc(std::string_view sentence);
[[nodiscard]] Expected<Gga, Error> parse_gga(std::string_view sentence);

}  // namespace fieldguard::nmea
