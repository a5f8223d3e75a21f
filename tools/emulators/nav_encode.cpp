#include "nav_encode.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "fieldguard/drivers/nmea.hpp"
#include "fieldguard/drivers/xsens.hpp"
#include "fieldguard/drivers/xsens_mtdata2.hpp"

namespace fieldguard::tools {

namespace {

// Civil date of a count of days since 1970-01-01 (H. Hinnant's days_from_civil inverted).
void civil_from_days(std::int64_t z, int& y, int& m, int& d) {
  z += 719468;
  const std::int64_t era = (z >= 0 ? z : z - 146096) / 146097;
  const auto doe = static_cast<unsigned>(z - era * 146097);
  const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const unsigned mp = (5 * doy + 2) / 153;
  d = static_cast<int>(doy - (153 * mp + 2) / 5 + 1);
  m = static_cast<int>(mp < 10 ? mp + 3 : mp - 9);
  y = static_cast<int>(static_cast<std::int64_t>(yoe) + era * 400 + (m <= 2 ? 1 : 0));
}

void put_be16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 8U));
  out.push_back(static_cast<std::uint8_t>(v & 0xFFU));
}
void put_be32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>((v >> static_cast<unsigned>(s)) & 0xFFU));
}
void put_float(std::vector<std::uint8_t>& out, double v) {
  const auto f = static_cast<float>(v);
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof bits);
  put_be32(out, bits);
}

}  // namespace

std::string fixed_text(int decimals, double v) {
  char buf[64];
  const int n = std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return {buf, static_cast<std::size_t>(std::clamp(n, 0, static_cast<int>(sizeof buf) - 1))};
}

std::string nmea_sentence(const std::string& body) {
  char cs[8];
  std::snprintf(cs, sizeof cs, "*%02X\r\n", static_cast<unsigned>(nmea::checksum(body)));
  return "$" + body + cs;
}

std::string nmea_time(std::int64_t utc_ns) {
  const std::int64_t cs = utc_ns / 10000000;  // hundredths since the epoch
  const std::int64_t day_cs = cs % 8640000;
  char buf[16];
  std::snprintf(buf, sizeof buf, "%02d%02d%02d.%02d", static_cast<int>(day_cs / 360000),
                static_cast<int>(day_cs / 6000 % 60), static_cast<int>(day_cs / 100 % 60),
                static_cast<int>(day_cs % 100));
  return buf;
}

std::string nmea_date(std::int64_t utc_ns) {
  int y = 0;
  int m = 0;
  int d = 0;
  civil_from_days(utc_ns / 1000000000 / 86400, y, m, d);
  char buf[16];
  std::snprintf(buf, sizeof buf, "%02d%02d%02d", d, m, y % 100);
  return buf;
}

std::string nmea_angle(double deg, int deg_digits, char pos, char neg) {
  const auto total = static_cast<long long>(std::llround(std::abs(deg) * 60.0 * 1e7));
  const long long per_deg = 600000000LL;
  char buf[40];
  std::snprintf(buf, sizeof buf, "%0*lld%02lld.%07lld,%c", deg_digits, total / per_deg, total % per_deg / 10000000LL,
                total % 10000000LL, deg < 0.0 ? neg : pos);
  return buf;
}

std::vector<std::string> nmea_epoch(const GnssEpoch& e) {
  const std::string time = nmea_time(e.utc_ns);
  const std::string lat = nmea_angle(e.lat_deg, 2, 'N', 'S');
  const std::string lon = nmea_angle(e.lon_deg, 3, 'E', 'W');
  std::vector<std::string> out;
  out.push_back(nmea_sentence("GNGGA," + time + "," + lat + "," + lon + ",4," + std::to_string(e.satellites) + ",0.6," +
                              fixed_text(3, e.h_m - e.geoid_separation_m) + ",M," +
                              fixed_text(3, e.geoid_separation_m) + ",M,1.0,0001"));
  out.push_back(nmea_sentence(
      "GNRMC," + time + ",A," + lat + "," + lon + "," + fixed_text(3, e.speed_mps * 3600.0 / 1852.0) + "," +
      (e.course_deg ? fixed_text(2, *e.course_deg) : std::string()) + "," + nmea_date(e.utc_ns) + ",,,D"));
  out.push_back(nmea_sentence("GNHDT," + fixed_text(2, e.heading_deg) + ",T"));
  return out;
}

std::vector<std::uint8_t> mtdata2_frame(const AhrsSample& s) {
  std::vector<std::uint8_t> payload;
  put_be16(payload, xsens::data_id::kPacketCounter);
  payload.push_back(2);
  put_be16(payload, s.packet_counter);
  put_be16(payload, xsens::data_id::kSampleTimeFine);
  payload.push_back(4);
  put_be32(payload, s.sample_time_fine);
  put_be16(payload, xsens::data_id::kEulerAngles);  // Float32, ENU
  payload.push_back(12);
  put_float(payload, s.roll_deg);
  put_float(payload, s.pitch_deg);
  put_float(payload, s.yaw_deg);
  return xsens::encode_frame(xsens::mid::kMtData2, payload);
}

}  // namespace fieldguard::tools
