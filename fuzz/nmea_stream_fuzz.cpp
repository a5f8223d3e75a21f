// libFuzzer target for nmea::StreamParser and parse_sentence(): the input as a byte stream, fed whole and in
// chunks whose sizes come from the input itself. Invariants (a violation traps):
//  - the chunking changes nothing: same sentences (type, talker, values) and same counters;
//  - every sentence seen is accepted or counted under exactly one rejection reason;
//  - decoded values are in range; the parser's memory does not grow with the input (it has no heap state).
// Run: fuzz_nmea_stream -max_total_time=60 CORPUS_DIR fuzz/corpus/nmea_stream

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "fieldguard/drivers/nmea.hpp"
#include "fieldguard/drivers/nmea_stream.hpp"

namespace {

namespace nmea = fieldguard::nmea;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

void check_in(const std::optional<double>& v, double lo, double hi) {
  if (v) check(std::isfinite(*v) && *v >= lo && *v <= hi);
}

void check_finite(const std::optional<double>& v) {
  if (v) check(std::isfinite(*v));
}

void check_sentence(const nmea::Sentence& s) {
  check(nmea::talker_of(s).size() <= 2);
  if (const auto* g = std::get_if<nmea::Gga>(&s)) {
    check_in(g->utc_seconds_of_day, 0.0, 86401.0);
    check_in(g->lat_deg, -90.0, 90.0);
    check_in(g->lon_deg, -180.0, 180.0);
    if (g->quality) check(*g->quality >= 0 && *g->quality <= 9);
    if (g->satellites) check(*g->satellites >= 0);
    check_finite(g->hdop);
    check_finite(g->alt_m);
    check_finite(g->geoid_sep_m);
    check_finite(g->dgps_age_s);
  } else if (const auto* r = std::get_if<nmea::Rmc>(&s)) {
    check_in(r->utc_seconds_of_day, 0.0, 86401.0);
    check_in(r->lat_deg, -90.0, 90.0);
    check_in(r->lon_deg, -180.0, 180.0);
    check(r->status == 0 || r->status == 'A' || r->status == 'V');
    check(r->valid == (r->status == 'A'));
    check_finite(r->speed_mps);
    check_finite(r->course_deg);
    check_finite(r->magnetic_variation_deg);
    if (r->day) check(*r->day >= 1 && *r->day <= 31 && *r->month >= 1 && *r->month <= 12);
  } else if (const auto* v = std::get_if<nmea::Vtg>(&s)) {
    check_in(v->course_true_deg, 0.0, 360.0);
    check_in(v->course_magnetic_deg, 0.0, 360.0);
    check_finite(v->speed_mps);
  } else if (const auto* h = std::get_if<nmea::Hdt>(&s)) {
    check_in(h->heading_deg, 0.0, 360.0);
  } else if (const auto* t = std::get_if<nmea::Ths>(&s)) {
    check_in(t->heading_deg, 0.0, 360.0);
  }
}

bool same(const std::optional<double>& a, const std::optional<double>& b) {
  return a.has_value() == b.has_value() && (!a || *a == *b || (std::isnan(*a) && std::isnan(*b)));
}

// Equal sentences: the same alternative, talker and (for the position types) position and time.
bool same(const nmea::Sentence& a, const nmea::Sentence& b) {
  if (a.index() != b.index() || nmea::talker_of(a) != nmea::talker_of(b)) return false;
  if (const auto* g = std::get_if<nmea::Gga>(&a)) {
    const auto& h = std::get<nmea::Gga>(b);
    return same(g->lat_deg, h.lat_deg) && same(g->lon_deg, h.lon_deg) &&
           same(g->utc_seconds_of_day, h.utc_seconds_of_day);
  }
  if (const auto* r = std::get_if<nmea::Rmc>(&a)) {
    const auto& s = std::get<nmea::Rmc>(b);
    return same(r->lat_deg, s.lat_deg) && same(r->lon_deg, s.lon_deg) && r->year == s.year;
  }
  return true;
}

bool same(const nmea::StreamCounters& a, const nmea::StreamCounters& b) {
  return a.sentences == b.sentences && a.accepted == b.accepted && a.bad_checksum == b.bad_checksum &&
         a.no_checksum == b.no_checksum && a.too_long == b.too_long && a.bad_field == b.bad_field &&
         a.unsupported == b.unsupported && a.interrupted == b.interrupted && a.noise_bytes == b.noise_bytes;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);

  nmea::StreamParser whole;
  std::vector<nmea::Sentence> a;
  whole.push(bytes, a);
  whole.finish(a);
  const auto& c = whole.counters();
  check(c.accepted == a.size());
  check(c.sentences == c.accepted + c.rejected());
  check(c.noise_bytes <= size);
  for (const auto& s : a) check_sentence(s);

  // Chunk sizes from the input's own bytes (1..16), cycling.
  nmea::StreamParser pieces;
  std::vector<nmea::Sentence> b;
  std::size_t k = 0;
  for (std::size_t off = 0; off < size;) {
    const std::size_t n = std::min<std::size_t>(size - off, 1U + (data[k++ % size] & 0x0FU));
    pieces.push(bytes.subspan(off, n), b);
    off += n;
  }
  pieces.finish(b);
  check(same(c, pieces.counters()));
  check(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) check(same(a[i], b[i]));

  // Unchecked mode accepts at least what strict mode does.
  nmea::StreamParser lenient(nmea::StreamOptions{false});
  std::vector<nmea::Sentence> l;
  lenient.push(bytes, l);
  lenient.finish(l);
  check(l.size() >= a.size());
  for (const auto& s : l) check_sentence(s);

  // The whole input as one sentence.
  const auto one = nmea::parse_sentence(std::string_view(reinterpret_cast<const char*>(data), size));  // NOLINT
  if (one) check_sentence(*one);
  return 0;
}
