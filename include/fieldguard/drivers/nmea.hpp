#pragma once
// NMEA 0183 sentence parsing (protocols.md §4). Pure: one sentence of text in, a typed record or an error out.
// GGA, RMC, VTG, HDT and THS from any talker (GP, GN, GL, GA, GB, BD, GQ, HE, HC, IN, ...): the decoders
// dispatch on the three-letter type only. Empty fields are std::nullopt (or 0 for a mode letter), never 0.
// A byte stream (lines, noise, sentences split across reads) goes through nmea::StreamParser (nmea_stream.hpp).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "fieldguard/core/expected.hpp"

namespace fieldguard::nmea {

// Longest sentence accepted, from '$' to the checksum digits, line terminator excluded. The standard says
// 82 with CR LF (80 without); real receivers exceed it (Trimble BX-960: 91-char GGA, u-blox high-precision
// NMEA: ~90, Skytraq PSTI and Unicore: 100..105, protocols.md §4.3). 120 keeps those and still drops two
// merged sentences.
inline constexpr std::size_t kMaxSentenceLength = 120;

enum class Error : std::uint8_t {
  NoStart,      // does not start with '$'
  TooLong,      // longer than kMaxSentenceLength
  BadChecksum,  // '*hh' present and wrong (or not at the end)
  NoChecksum,   // no '*hh' (an error unless the caller accepts unchecked sentences, see StreamOptions)
  BadField,     // a field that must be a number (or a given letter) is not, or too few fields
  Unsupported,  // a sentence type we do not decode
};
[[nodiscard]] std::string_view to_string(Error e);

// XOR of the bytes between '$' and '*'.
[[nodiscard]] std::uint8_t checksum(std::string_view body);

struct Rmc {
  std::string talker;  // "GP", "GN", ...
  std::optional<double> utc_seconds_of_day;
  bool valid = false;             // status 'A'
  char status = 0;                // 'A' valid, 'V' warning, 0 if the field is empty
  std::optional<double> lat_deg;  // south negative
  std::optional<double> lon_deg;  // west negative
  std::optional<double> speed_mps;
  std::optional<double> course_deg;
  std::optional<int> day, month, year;           // year as 4 digits (2-digit years are 1980..2079)
  std::optional<double> magnetic_variation_deg;  // east positive, west negative
  char mode = 0;                                 // NMEA >= 2.3 mode indicator, 0 if absent
};

struct Gga {
  std::string talker;
  std::optional<double> utc_seconds_of_day;
  std::optional<double> lat_deg;
  std::optional<double> lon_deg;
  // 0 invalid, 1 GPS, 2 DGPS, 3 PPS, 4 RTK fixed, 5 RTK float, 6 estimated, 7 manual, 8 simulator (9 vendor);
  // nullopt when the field is empty (gpsd: "no data is no data, assume no fix").
  std::optional<int> quality;
  std::optional<int> satellites;
  std::optional<double> hdop;
  std::optional<double> alt_m;        // above mean sea level
  std::optional<double> geoid_sep_m;  // ellipsoidal height = alt_m + geoid_sep_m
  std::optional<double> dgps_age_s;
  std::string dgps_station;  // as sent ("0133"), empty if absent
};

struct Vtg {
  std::string talker;
  std::optional<double> course_true_deg;
  std::optional<double> course_magnetic_deg;
  std::optional<double> speed_mps;  // from the knots field, or from km/h when knots is empty
  char mode = 0;                    // NMEA >= 2.3 mode indicator, 0 if absent
};

// HDT, heading true (deprecated in favour of THS).
struct Hdt {
  std::string talker;
  std::optional<double> heading_deg;
};

// THS, true heading and status.
struct Ths {
  std::string talker;
  std::optional<double> heading_deg;
  char mode = 0;  // A autonomous, E estimated, M manual, S simulator, V invalid; 0 if empty
};

using Sentence = std::variant<Gga, Rmc, Vtg, Hdt, Ths>;

// Parses "$GPRMC,...*hh" (trailing CR/LF and NULs tolerated).
[[nodiscard]] Expected<Rmc, Error> parse_rmc(std::string_view sentence);
[[nodiscard]] Expected<Gga, Error> parse_gga(std::string_view sentence);
[[nodiscard]] Expected<Vtg, Error> parse_vtg(std::string_view sentence);
[[nodiscard]] Expected<Hdt, Error> parse_hdt(std::string_view sentence);
[[nodiscard]] Expected<Ths, Error> parse_ths(std::string_view sentence);

struct ParseOptions {
  bool require_checksum = true;  // false: a sentence without "*hh" is decoded unchecked (protocols.md §4.3)
};

// Any of the types above, chosen by the sentence's type; Error::Unsupported for another type.
[[nodiscard]] Expected<Sentence, Error> parse_sentence(std::string_view sentence, ParseOptions options = {});

// "GGA", "RMC", ... and the talker of a decoded sentence.
[[nodiscard]] std::string_view type_of(const Sentence& s);
[[nodiscard]] const std::string& talker_of(const Sentence& s);

}  // namespace fieldguard::nmea
