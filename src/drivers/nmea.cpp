// NMEA 0183 sentences (protocols.md §4.2). Framing and field conversions: nmea_sentence.cpp.
// Adding a sentence type: a struct in nmea.hpp (and in the Sentence variant), and a decode_xxx() here that
// reads the fields of a Frame with a FieldReader, listed in kDecoders.

#include "fieldguard/drivers/nmea.hpp"

#include <array>

#include "drivers/nmea_sentence.hpp"

namespace fieldguard::nmea {
namespace {

using detail::FieldReader;
using detail::Frame;

constexpr double kKnotsToMps = 1852.0 / 3600.0;
constexpr double kKmhToMps = 1.0 / 3.6;

// Field counts of NMEA 0183 2.0; later versions append fields (RMC: mode in 2.3, navigational status in 4.1;
// VTG: mode in 2.3).
constexpr std::size_t kRmcMinFields = 11;
constexpr std::size_t kGgaMinFields = 14;
constexpr std::size_t kVtgMinFields = 8;
constexpr std::size_t kHdtMinFields = 2;
constexpr std::size_t kThsMinFields = 2;

// A unit or reference letter ("T", "M", "N", "K"): empty or exactly `expected`.
bool unit_ok(std::string_view field, char expected) {
  return field.empty() || (field.size() == 1 && field[0] == expected);
}

// A heading or course in degrees: empty, or 0..360 (some receivers send 360.0 for north).
std::optional<double> heading(FieldReader& in, std::string_view field) {
  const auto v = in(detail::decimal(field));
  if (v && (*v < 0.0 || *v > 360.0) && !in.error) in.error = Error::BadField;
  return v;
}

Expected<Rmc, Error> decode_rmc(const Frame& s) {
  if (s.field_count < kRmcMinFields) return Unexpected{Error::BadField};
  FieldReader in;
  Rmc r;
  r.talker = std::string(s.talker);
  r.utc_seconds_of_day = in(detail::time_of_day(s.field(0)));
  const auto status = in(detail::letter(s.field(1)));
  if (status && *status != 'A' && *status != 'V') return Unexpected{Error::BadField};
  r.status = status.value_or(0);
  r.valid = status == 'A';
  r.lat_deg = in(detail::latitude(s.field(2), s.field(3)));
  r.lon_deg = in(detail::longitude(s.field(4), s.field(5)));
  if (const auto knots = in(detail::decimal(s.field(6)))) r.speed_mps = *knots * kKnotsToMps;
  r.course_deg = in(detail::decimal(s.field(7)));
  if (const auto date = in(detail::date_ddmmyy(s.field(8)))) {
    r.day = date->day;
    r.month = date->month;
    r.year = date->year;
  }
  const auto variation = in(detail::decimal(s.field(9)));
  const auto variation_dir = in(detail::letter(s.field(10)));
  if (variation_dir && *variation_dir != 'E' && *variation_dir != 'W') return Unexpected{Error::BadField};
  if (variation) r.magnetic_variation_deg = variation_dir == 'W' ? -*variation : *variation;
  r.mode = in(detail::letter(s.field(11))).value_or(0);
  if (in.error) return Unexpected{*in.error};
  return r;
}

Expected<Gga, Error> decode_gga(const Frame& s) {
  if (s.field_count < kGgaMinFields) return Unexpected{Error::BadField};
  FieldReader in;
  Gga g;
  g.talker = std::string(s.talker);
  g.utc_seconds_of_day = in(detail::time_of_day(s.field(0)));
  g.lat_deg = in(detail::latitude(s.field(1), s.field(2)));
  g.lon_deg = in(detail::longitude(s.field(3), s.field(4)));
  g.quality = in(detail::integer(s.field(5)));
  if (g.quality && *g.quality > 9) return Unexpected{Error::BadField};
  g.satellites = in(detail::integer(s.field(6)));
  g.hdop = in(detail::decimal(s.field(7)));
  g.alt_m = in(detail::decimal(s.field(8)));
  g.geoid_sep_m = in(detail::decimal(s.field(10)));
  g.dgps_age_s = in(detail::decimal(s.field(12)));
  g.dgps_station = std::string(s.field(13));  // an identifier, kept as sent
  if (in.error) return Unexpected{*in.error};
  return g;
}

Expected<Vtg, Error> decode_vtg(const Frame& s) {
  if (s.field_count < kVtgMinFields) return Unexpected{Error::BadField};
  if (!unit_ok(s.field(1), 'T') || !unit_ok(s.field(3), 'M') || !unit_ok(s.field(5), 'N') ||
      !unit_ok(s.field(7), 'K')) {
    return Unexpected{Error::BadField};
  }
  FieldReader in;
  Vtg v;
  v.talker = std::string(s.talker);
  v.course_true_deg = heading(in, s.field(0));
  v.course_magnetic_deg = heading(in, s.field(2));
  const auto knots = in(detail::decimal(s.field(4)));
  const auto kmh = in(detail::decimal(s.field(6)));
  if (knots) {
    v.speed_mps = *knots * kKnotsToMps;
  } else if (kmh) {
    v.speed_mps = *kmh * kKmhToMps;
  }
  v.mode = in(detail::letter(s.field(8))).value_or(0);
  if (in.error) return Unexpected{*in.error};
  return v;
}

Expected<Hdt, Error> decode_hdt(const Frame& s) {
  if (s.field_count < kHdtMinFields || !unit_ok(s.field(1), 'T')) return Unexpected{Error::BadField};
  FieldReader in;
  Hdt h;
  h.talker = std::string(s.talker);
  h.heading_deg = heading(in, s.field(0));
  if (in.error) return Unexpected{*in.error};
  return h;
}

Expected<Ths, Error> decode_ths(const Frame& s) {
  if (s.field_count < kThsMinFields) return Unexpected{Error::BadField};
  FieldReader in;
  Ths t;
  t.talker = std::string(s.talker);
  t.heading_deg = heading(in, s.field(0));
  t.mode = in(detail::letter(s.field(1))).value_or(0);
  if (in.error) return Unexpected{*in.error};
  return t;
}

template <typename T>
Expected<Sentence, Error> widen(Expected<T, Error> r) {
  if (!r) return Unexpected{r.error()};
  return Sentence{std::move(r).value()};
}

struct Decoder {
  std::string_view type;
  Expected<Sentence, Error> (*decode)(const Frame&);
};

const std::array<Decoder, 5> kDecoders = {{
    {"GGA", [](const Frame& f) { return widen(decode_gga(f)); }},
    {"RMC", [](const Frame& f) { return widen(decode_rmc(f)); }},
    {"VTG", [](const Frame& f) { return widen(decode_vtg(f)); }},
    {"HDT", [](const Frame& f) { return widen(decode_hdt(f)); }},
    {"THS", [](const Frame& f) { return widen(decode_ths(f)); }},
}};

// Frames the sentence and checks its type.
Expected<Frame, Error> frame_of(std::string_view text, std::string_view type) {
  auto f = detail::frame(text);
  if (f && f->type != type) return Unexpected{Error::Unsupported};
  return f;
}

template <typename T>
Expected<T, Error> parse_one(std::string_view text, std::string_view type, Expected<T, Error> (*decode)(const Frame&)) {
  const auto f = frame_of(text, type);
  if (!f) return Unexpected{f.error()};
  return decode(*f);
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

Expected<Rmc, Error> parse_rmc(std::string_view sentence) { return parse_one(sentence, "RMC", decode_rmc); }
Expected<Gga, Error> parse_gga(std::string_view sentence) { return parse_one(sentence, "GGA", decode_gga); }
Expected<Vtg, Error> parse_vtg(std::string_view sentence) { return parse_one(sentence, "VTG", decode_vtg); }
Expected<Hdt, Error> parse_hdt(std::string_view sentence) { return parse_one(sentence, "HDT", decode_hdt); }
Expected<Ths, Error> parse_ths(std::string_view sentence) { return parse_one(sentence, "THS", decode_ths); }

Expected<Sentence, Error> parse_sentence(std::string_view sentence, ParseOptions options) {
  const auto f = detail::frame(sentence, options.require_checksum);
  if (!f) return Unexpected{f.error()};
  for (const Decoder& d : kDecoders) {
    if (f->type == d.type) return d.decode(*f);
  }
  return Unexpected{Error::Unsupported};
}

std::string_view type_of(const Sentence& s) {
  struct Visitor {
    std::string_view operator()(const Gga&) const { return "GGA"; }
    std::string_view operator()(const Rmc&) const { return "RMC"; }
    std::string_view operator()(const Vtg&) const { return "VTG"; }
    std::string_view operator()(const Hdt&) const { return "HDT"; }
    std::string_view operator()(const Ths&) const { return "THS"; }
  };
  return std::visit(Visitor{}, s);
}

const std::string& talker_of(const Sentence& s) {
  return std::visit([](const auto& v) -> const std::string& { return v.talker; }, s);
}

}  // namespace fieldguard::nmea
