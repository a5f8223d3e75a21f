// libFuzzer target for the NMEA parsers (parse_rmc, parse_gga) and the Velodyne position packet decoder.
// The input is tried as a sentence, as a sentence with its checksum made right, as a whole packet, and as the
// sentence field of an otherwise empty packet.
// Invariants that a decoded value must satisfy are checked too (a violation traps).
// Run: fuzz_nmea -max_total_time=60 CORPUS_DIR   (seed with lines of ../shared/realdata/nmea-gpsd-regress/*.log)

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "fieldguard/drivers/nmea.hpp"
#include "fieldguard/drivers/velodyne_position.hpp"

namespace {

namespace nmea = fieldguard::nmea;
namespace velodyne = fieldguard::velodyne;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

void check_in(const std::optional<double>& v, double lo, double hi) {
  if (v) check(std::isfinite(*v) && *v >= lo && *v <= hi);
}

void check_rmc(const nmea::Rmc& r) {
  check_in(r.utc_seconds_of_day, 0.0, 86401.0);
  check_in(r.lat_deg, -90.0, 90.0);
  check_in(r.lon_deg, -180.0, 180.0);
  if (r.speed_mps) check(std::isfinite(*r.speed_mps));
  if (r.course_deg) check(std::isfinite(*r.course_deg));
  check(r.day.has_value() == r.month.has_value() && r.month.has_value() == r.year.has_value());
  if (r.day)
    check(*r.day >= 1 && *r.day <= 31 && *r.month >= 1 && *r.month <= 12 && *r.year >= 1980 && *r.year <= 2079);
  check(r.talker.size() <= 2);
}

void check_gga(const nmea::Gga& g) {
  check_in(g.utc_seconds_of_day, 0.0, 86401.0);
  check_in(g.lat_deg, -90.0, 90.0);
  check_in(g.lon_deg, -180.0, 180.0);
  if (g.quality) check(*g.quality >= 0 && *g.quality <= 9);  // empty quality field: nullopt
  if (g.satellites) check(*g.satellites >= 0);
  for (const auto& v : {g.hdop, g.alt_m, g.geoid_sep_m}) {
    if (v) check(std::isfinite(*v));
  }
}

void check_packet(const velodyne::PositionPacket& p) {
  check(p.nmea.size() <= velodyne::kPositionPacketSize - 206);
  check(p.nmea.find('\0') == std::string_view::npos);
  check(!(p.rmc && p.nmea_error));
  check(p.nmea.empty() || p.rmc || p.nmea_error);
  if (p.rmc) check_rmc(*p.rmc);
  (void)velodyne::to_string(p.pps);
  if (p.nmea_error) (void)nmea::to_string(*p.nmea_error);
}

// "$" + body + "*hh" with the right checksum, so that mutations reach the field decoders instead of
// stopping at the checksum. The body is the input without a leading '$' and from its first '*' on.
std::string with_checksum(std::string_view text) {
  if (!text.empty() && text.front() == '$') text.remove_prefix(1);
  text = text.substr(0, text.find('*'));
  constexpr std::string_view kHex = "0123456789ABCDEF";
  const std::uint8_t sum = nmea::checksum(text);
  std::string out = "$";
  out.append(text);
  out += '*';
  out += kHex[sum >> 4];
  out += kHex[sum & 0x0F];
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);  // NOLINT: bytes as characters

  const auto rmc = nmea::parse_rmc(text);
  if (rmc) check_rmc(*rmc);
  const auto gga = nmea::parse_gga(text);
  if (gga) check_gga(*gga);
  const std::string fixed = with_checksum(text);
  const auto fixed_rmc = nmea::parse_rmc(fixed);
  if (fixed_rmc) check_rmc(*fixed_rmc);
  const auto fixed_gga = nmea::parse_gga(fixed);
  if (fixed_gga) check_gga(*fixed_gga);

  // The input as a whole packet (any length: only 512 decodes).
  const auto raw = velodyne::decode_position_packet(fieldguard::ByteSpan(data, size));
  check(raw.has_value() == (size == velodyne::kPositionPacketSize));
  if (raw) check_packet(*raw);

  // The input as the NMEA field of a packet, cut at the packet's end.
  std::array<std::uint8_t, velodyne::kPositionPacketSize> packet{};
  const std::size_t n = std::min(size, packet.size() - 206);
  std::copy_n(data, n, packet.begin() + 206);
  const auto framed = velodyne::decode_position_packet(packet);
  check(framed.has_value());
  check_packet(*framed);
  return 0;
}
