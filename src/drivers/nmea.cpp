// NMEA 0183 sentences (protocols.md §4.2). Framing and field conversions: nmea_sentence.cpp.
// Adding a sentence type: a struct in nmea.hpp, and a parse_xxx() here that calls sentence_of() and reads
// its fields with a FieldReader.

#include "fieldguard/drivers/nmea.hpp"

#include "drivers/nmea_sentence.hpp"

namespace fieldguard::nmea {
namespace {

using detail::FieldReader;
using detail::Sentence;

constexpr double kKnotsToMps = 1852.0 / 3600.0;

// Field counts of NMEA 0183 2.0; later versions append fields (RMC: mode in 2.3, navigational status in 4.1).
constexpr std::size_t kRmcMinFields = 11;
constexpr std::size_t kGgaMinFields = 14;

// Frames the sentence and checks its type and field count.
Expected<Sentence, Error> sentence_of(std::string_view text, std::string_view type, std::size_t min_fields) {
  auto s = detail::frame(text);
  if (!s) return s;
  if (s->type != type) return Unexpected{Error::Unsupported};
  if (s->field_count < min_fields) return Unexpected{Error::BadField};
  return s;
}

}  // namespace

std::string_view to_string(Error e) {
  switch (e) {
    case Error::NoStart: return "no_start";
    case Error::TooLong: return "too_long";
    case Error::BadChecksum: return "bad_checksum";
    case Error::NoChecksum: return "no_checksum";
    case Error::BadField: return "bad_field";
    case Error::Unsupported: return "unsupported";
  }
  return "unknown";
}

std::uint8_t checksum(std::string_view body) {
  std::uint8_t sum = 0;
  for (const char c : body) sum = static_cast<std::uint8_t>(sum ^ static_cast<std::uint8_t>(c));
  return sum;
}

Expected<Rmc, Error> parse_rmc(std::string_view sentence) {
  const auto s = sentence_of(sentence, "RMC", kRmcMinFields);
  if (!s) return Unexpected{s.error()};
  FieldReader in;
  Rmc r;
  r.talker = std::string(s->talker);
  r.utc_seconds_of_day = in(detail::time_of_day(s->field(0)));
  const auto status = in(detail::letter(s->field(1)));
  if (status && *status != 'A' && *status != 'V') return Unexpected{Error::BadField};
  r.valid = status == 'A';
  r.lat_deg = in(detail::latitude(s->field(2), s->field(3)));
  r.lon_deg = in(detail::longitude(s->field(4), s->field(5)));
  if (const auto knots = in(detail::decimal(s->field(6)))) r.speed_mps = *knots * kKnotsToMps;
  r.course_deg = in(detail::decimal(s->field(7)));
  if (const auto date = in(detail::date_ddmmyy(s->field(8)))) {
    r.day = date->day;
    r.month = date->month;
    r.year = date->year;
  }
  // Magnetic variation: not kept, but a damaged one means a damaged sentence.
  (void)in(detail::decimal(s->field(9)));
  const auto variation_dir = in(detail::letter(s->field(10)));
  if (variation_dir && *variation_dir != 'E' && *variation_dir != 'W') return Unexpected{Error::BadField};
  r.mode = in(detail::letter(s->field(11))).value_or(0);
  if (in.error) return Unexpected{*in.error};
  return r;
}

Expected<Gga, Error> parse_gga(std::string_view sentence) {
  const auto s = sentence_of(sentence, "GGA", kGgaMinFields);
  if (!s) return Unexpected{s.error()};
  FieldReader in;
  Gga g;
  g.talker = std::string(s->talker);
  g.utc_seconds_of_day = in(detail::time_of_day(s->field(0)));
  g.lat_deg = in(detail::latitude(s->field(1), s->field(2)));
  g.lon_deg = in(detail::longitude(s->field(3), s->field(4)));
  const auto quality = in(detail::integer(s->field(5)));
  if (quality && *quality > 9) return Unexpected{Error::BadField};
  g.quality = quality.value_or(0);
  g.satellites = in(detail::integer(s->field(6)));
  g.hdop = in(detail::decimal(s->field(7)));
  g.alt_m = in(detail::decimal(s->field(8)));
  g.geoid_sep_m = in(detail::decimal(s->field(10)));
  (void)in(detail::decimal(s->field(12)));  // age of differential data: not kept, checked
  if (in.error) return Unexpected{*in.error};
  return g;
}

}  // namespace fieldguard::nmea
