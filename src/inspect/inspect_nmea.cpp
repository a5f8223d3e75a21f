// `fieldguard inspect --format nmea`: NMEA 0183 text (a receiver's serial output, a gpsd log).

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>
#include <variant>

#include "fieldguard/drivers/nmea_stream.hpp"
#include "inspect/inspect_byte_log.hpp"
#include "inspect/inspect_format.hpp"
#include "inspect/json_line.hpp"

namespace fieldguard::app::inspect {
namespace {

// "hh:mm:ss.fff" (more decimals when the receiver sent them, up to microseconds); a leap second stays 23:59:60.
std::string time_of_day(double seconds) {
  constexpr long long kDay = 86400LL * 1000000LL;
  const bool leap = seconds >= 86400.0;
  auto us = std::llround(seconds * 1e6);
  if (!leap && us >= kDay) us = kDay - 1;  // 23:59:59.9999999 stays in the day
  if (leap) us -= 60LL * 1000000LL;        // 23:59:60.x is printed from 23:59:00.x + 60 s
  const long long s = us / 1000000LL;
  long long frac = us % 1000000LL;
  std::array<char, 32> buf{};
  const int hh = static_cast<int>(s / 3600);
  const int mm = static_cast<int>(s / 60 % 60);
  const int ss = static_cast<int>(s % 60) + (leap ? 60 : 0);
  int digits = 6;
  while (digits > 3 && frac % 10 == 0) {
    frac /= 10;
    --digits;
  }
  std::snprintf(buf.data(), buf.size(), "%02d:%02d:%02d.%0*lld", hh, mm, ss, digits, frac);
  return buf.data();
}

std::string type_name(const nmea::Sentence& s) { return nmea::talker_of(s) + std::string(nmea::type_of(s)); }

void add_time(JsonLine& j, const std::optional<double>& sod) {
  if (sod) {
    j.field("time_utc", time_of_day(*sod));
  } else {
    j.null("time_utc");
  }
}

std::string record(const nmea::Sentence& sentence) {
  JsonLine j;
  j.field("type", type_name(sentence));
  if (const auto* g = std::get_if<nmea::Gga>(&sentence)) {
    add_time(j, g->utc_seconds_of_day);
    j.field("lat_deg", g->lat_deg).field("lon_deg", g->lon_deg).field("alt_m", g->alt_m);
    j.field("quality", g->quality).field("sats", g->satellites).field("hdop", g->hdop);
    j.field("geoid_sep_m", g->geoid_sep_m);
    if (g->alt_m && g->geoid_sep_m) {
      j.field("alt_hae_m", *g->alt_m + *g->geoid_sep_m);
    } else {
      j.null("alt_hae_m");
    }
    j.field("dgps_age_s", g->dgps_age_s);
    if (g->dgps_station.empty()) {
      j.null("dgps_station");
    } else {
      j.field("dgps_station", g->dgps_station);
    }
  } else if (const auto* r = std::get_if<nmea::Rmc>(&sentence)) {
    add_time(j, r->utc_seconds_of_day);
    j.letter("status", r->status);
    j.field("lat_deg", r->lat_deg).field("lon_deg", r->lon_deg);
    j.field("speed_mps", r->speed_mps).field("course_deg", r->course_deg);
    if (r->year) {
      std::array<char, 16> date{};
      std::snprintf(date.data(), date.size(), "%04d-%02d-%02d", *r->year, r->month.value_or(0), r->day.value_or(0));
      j.field("date", date.data());
    } else {
      j.null("date");
    }
    j.field("mag_var_deg", r->magnetic_variation_deg);
    j.letter("mode", r->mode);
  } else if (const auto* v = std::get_if<nmea::Vtg>(&sentence)) {
    j.field("course_true_deg", v->course_true_deg).field("course_mag_deg", v->course_magnetic_deg);
    j.field("speed_mps", v->speed_mps);
    j.letter("mode", v->mode);
  } else if (const auto* h = std::get_if<nmea::Hdt>(&sentence)) {
    j.field("heading_deg", h->heading_deg);
  } else if (const auto* t = std::get_if<nmea::Ths>(&sentence)) {
    j.field("heading_deg", t->heading_deg);
    j.letter("mode", t->mode);
  }
  return std::move(j).str();
}

}  // namespace

bool looks_like_nmea(ByteSpan head) {
  if (starts_with_byte_log(head)) {
    // What `fieldguard record` saves of the serial line; the source line names it ("gnss /dev/ttyUSB0 ...").
    const std::string source = byte_log_source(head);
    return source.find("gnss") != std::string::npos || source.find("nmea") != std::string::npos ||
           source.find("gps") != std::string::npos;
  }
  // Text starting with a sentence or a comment line (gpsd logs), after blank space.
  const auto first = std::find_if(head.begin(), head.end(),
                                  [](std::uint8_t b) { return b != ' ' && b != '\t' && b != '\r' && b != '\n'; });
  if (first != head.end() && (*first == '$' || *first == '#')) return true;
  // Or text (a capture that starts mid-sentence, after a BOM, ...) with several lines that start like a sentence.
  std::size_t printable = 0;
  std::size_t sentences = 0;
  for (std::size_t i = 0; i < head.size(); ++i) {
    const std::uint8_t b = head[i];
    printable += (b >= 0x20 && b < 0x7F) || b == '\r' || b == '\n' || b == '\t' ? 1U : 0U;
    if (b == '$' && i > 0 && (head[i - 1] == '\n' || head[i - 1] == '\r') && i + 6 < head.size() &&
        std::isupper(head[i + 1]) != 0 && std::isupper(head[i + 2]) != 0) {
      ++sentences;
    }
  }
  return sentences >= 3 && printable * 10 >= head.size() * 9;
}

void inspect_nmea(Capture& in, Output& out, Summary& summary) {
  nmea::StreamParser parser;
  std::vector<nmea::Sentence> sentences;
  const auto take = [&] {
    for (const auto& s : sentences) {
      ++summary.kinds[type_name(s)];
      out.line(record(s));
    }
    sentences.clear();
  };
  // A byte log of the serial line (`fieldguard record`), or the raw bytes.
  SensorBytes bytes_in([&](ByteSpan bytes, std::optional<Stamp>) {
    parser.push(bytes, sentences);
    take();
  });
  bytes_in.read(in);
  parser.finish(sentences);
  take();
  const auto& c = parser.counters();
  summary.rejections = {{"bad_checksum", c.bad_checksum}, {"no_checksum", c.no_checksum},
                        {"too_long", c.too_long},         {"bad_field", c.bad_field},
                        {"unsupported", c.unsupported},   {"interrupted", c.interrupted}};
  summary.extra = {{"sentences", c.sentences}, {"noise_bytes", c.noise_bytes}};
  bytes_in.finish(summary);
}

}  // namespace fieldguard::app::inspect
