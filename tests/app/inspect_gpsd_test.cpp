// Acceptance: every gpsd regression NMEA log decodes through `fieldguard inspect`, and the fixes equal what gpsd
// itself decoded (the TPV objects of its .chk files, condensed into tests/data/nmea/<log>.expected by
// tests/data/nmea/make_expected.py; see tests/data/PROVENANCE.txt).
//
// Like is compared with like:
//  - lat/lon: gpsd prints %.9f; ours must round to the same 9 decimals (a tie is allowed: gpsd's own arithmetic
//    differs from ours in the last bit, which is what nmea-fuzzy-cases.log is about).
//  - altMSL is the GGA altitude field (our alt_m); altHAE is altitude + geoid separation (our alt_hae_m), compared
//    only where the sentence has a separation (without one, gpsd substitutes its own geoid model). gpsd prints %.4f.
//  - status is gpsd's reading of the GGA fix quality (0 unknown, 1 GPS, 2 DGPS, 4 -> 3 RTK fixed, 5 -> 4 RTK float,
//    6 -> 5 dead reckoning, 7 -> 7, 8 -> 8, 3 -> 9 PPS); gpsd prints it only when it is 2 or more.
//  - mode (1 no fix, 2 2D, 3 3D) is gpsd's fusion of several sentences (GSA, per-talker satellite counts), not a GGA
//    field: a gpsd fix (mode 2 or 3) must be a GGA with a position and a quality of 1 or more.
//  - RMC: position, and date + time against the TPV time.
// Corrupted sentences: the logs have none, so each log is also fed with every GGA and RMC corrupted by one byte;
// each must then be rejected as a bad checksum, and everything else still decoded.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"

namespace fieldguard {
namespace {

using testing::Json;
using testing::run_fieldguard;
using testing::summary_number;

const std::string kData = std::string(FIELDGUARD_TEST_DATA) + "/nmea/";

constexpr double kLatLonTolerance = 5e-10 + 1e-12;  // half a unit of %.9f, plus the double's own rounding
constexpr double kAltTolerance = 5e-5 + 1e-9;       // half a unit of %.4f

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

double seconds_of_day(const std::string& hh_mm_ss) {
  int h = 0;
  int m = 0;
  double s = 0.0;
  std::sscanf(hh_mm_ss.c_str(), "%d:%d:%lf", &h, &m, &s);
  return h * 3600.0 + m * 60.0 + s;
}

int gpsd_status(const Json& quality) {
  if (quality.is_null()) return 0;
  switch (quality.get<long long>()) {
    case 1: return 1;
    case 2: return 2;
    case 3: return 9;
    case 4: return 3;
    case 5: return 4;
    case 6: return 5;
    case 7: return 7;
    case 8: return 8;
    default: return 0;
  }
}

struct Expected {
  std::string kind;  // GGA or RMC
  std::size_t index = 0;
  std::string time;  // gpsd's ISO time
  int mode = 0;
  std::string status, lat, lon, alt_hae, alt_msl;  // "-" where gpsd printed nothing
};

std::vector<Expected> read_expected(const std::string& path) {
  std::vector<Expected> v;
  std::ifstream f(path);
  std::string line;
  while (std::getline(f, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    Expected e;
    in >> e.kind >> e.index >> e.time >> e.mode >> e.status >> e.lat >> e.lon;
    if (e.kind == "GGA") in >> e.alt_hae >> e.alt_msl;
    v.push_back(e);
  }
  return v;
}

struct LogResult {
  std::size_t compared = 0;  // sentences compared (GGA + RMC)
  std::size_t gga = 0;
  double max_pos_diff = 0.0;
};

// Checks one log's records against gpsd; `result` says what was compared.
void compare_with_gpsd(const std::string& log, const std::vector<Json>& records, LogResult& result) {
  std::vector<const Json*> gga;
  std::vector<const Json*> rmc;
  for (const auto& r : records) {
    const std::string type = r.at("type").get<std::string>();
    if (type.size() == 5 && type.substr(2) == "GGA") gga.push_back(&r);
    if (type.size() == 5 && type.substr(2) == "RMC") rmc.push_back(&r);
  }
  for (const auto& e : read_expected(kData + log + ".expected")) {
    const auto& list = e.kind == "GGA" ? gga : rmc;
    ASSERT_LT(e.index, list.size()) << log << ": " << e.kind << " " << e.index;
    const Json& r = *list[e.index];
    const std::string where = log + " " + e.kind + " #" + std::to_string(e.index) + " at " + e.time;
    ++result.compared;

    // Time (and for RMC the date) against the TPV time.
    ASSERT_FALSE(r.at("time_utc").is_null()) << where;
    EXPECT_NEAR(seconds_of_day(r.at("time_utc").get<std::string>()), seconds_of_day(e.time.substr(11, 12)), 5e-4)
        << where;
    if (e.kind == "RMC") {
      EXPECT_EQ(r.at("date").get<std::string>(), e.time.substr(0, 10)) << where;
    }

    if (e.lat != "-") {
      ASSERT_TRUE(r.at("lat_deg").is_number() && r.at("lon_deg").is_number()) << where;
      const double d = std::max(std::abs(r.at("lat_deg").get<double>() - std::stod(e.lat)),
                                std::abs(r.at("lon_deg").get<double>() - std::stod(e.lon)));
      EXPECT_LE(d, kLatLonTolerance) << where;
      result.max_pos_diff = std::max(result.max_pos_diff, d);
    }
    if (e.kind != "GGA") continue;
    ++result.gga;

    const int status = gpsd_status(r.at("quality"));
    EXPECT_EQ(status >= 2 ? std::to_string(status) : std::string("-"), e.status)
        << where << " quality " << testing::text(r.at("quality"));
    if (e.mode >= 2) {
      EXPECT_TRUE(r.at("lat_deg").is_number()) << where << ": gpsd has a fix, the GGA no position";
      EXPECT_GE(r.at("quality").is_number() ? r.at("quality").get<double>() : 0.0, 1.0)
          << where << ": gpsd has a fix, the GGA quality is 0";
    }
    if (e.alt_msl != "-") {
      ASSERT_TRUE(r.at("alt_m").is_number()) << where;
      EXPECT_NEAR(r.at("alt_m").get<double>(), std::stod(e.alt_msl), kAltTolerance) << where;
    }
    if (e.alt_hae != "-" && r.at("alt_hae_m").is_number()) {
      EXPECT_NEAR(r.at("alt_hae_m").get<double>(), std::stod(e.alt_hae), kAltTolerance) << where;
    }
  }
}

// The sentences of a log of the given types (every sentence when `types` is empty).
std::size_t count_lines(const std::string& text, std::initializer_list<const char*> types) {
  std::size_t n = 0;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.size() < 6 || line[0] != '$') continue;
    if (types.size() == 0) ++n;
    for (const char* t : types) n += line.compare(3, 3, t) == 0 ? 1U : 0U;
  }
  return n;
}

class GpsdLog : public ::testing::TestWithParam<const char*> {};

TEST_P(GpsdLog, DecodesLikeGpsd) {
  const std::string log = GetParam();
  const std::string path = kData + log;
  const std::string text = read_file(path);
  ASSERT_FALSE(text.empty()) << path;
  const auto run = run_fieldguard("inspect '" + path + "'");
  ASSERT_EQ(run.exit_code, 0) << run.output.substr(0, 2000);
  std::size_t bad_json = 0;
  const auto records = testing::json_lines(run.output, &bad_json);
  EXPECT_EQ(bad_json, 0U);

  // Every sentence of a type we decode is accepted (the logs have no corrupted ones); the rest are counted as
  // unsupported, and nothing is rejected for any other reason.
  const std::size_t ours = count_lines(text, {"GGA", "RMC", "VTG", "HDT", "THS"});
  const std::size_t all = count_lines(text, {});  // every '$' line
  EXPECT_EQ(records.size(), ours);
  EXPECT_EQ(summary_number(run.output, "records"), static_cast<long long>(ours));
  EXPECT_EQ(summary_number(run.output, "sentences"), static_cast<long long>(all));
  EXPECT_EQ(summary_number(run.output, "unsupported"), static_cast<long long>(all - ours));
  EXPECT_EQ(summary_number(run.output, "rejected"), static_cast<long long>(all - ours));

  LogResult r;
  compare_with_gpsd(log, records, r);
  EXPECT_GT(r.compared, 0U);
  std::printf(
      "[ gpsd     ] %-24s sentences %4zu: accepted %3zu, unsupported type %3zu, other rejections 0; "
      "compared with gpsd: %3zu GGA + %3zu RMC; max |dlat|,|dlon| %.3g deg\n",
      log.c_str(), all, records.size(), all - ours, r.gga, r.compared - r.gga, r.max_pos_diff);
}

TEST_P(GpsdLog, CorruptedSentencesAreRejectedAndCounted) {
  const std::string log = GetParam();
  std::string text = read_file(kData + log);
  // Flip the first character after the address ("$GPGGA,") of every GGA and RMC: the checksum must catch it.
  std::size_t corrupted = 0;
  std::size_t pos = 0;
  while ((pos = text.find('$', pos)) != std::string::npos) {
    const bool ours = text.compare(pos + 3, 3, "GGA") == 0 || text.compare(pos + 3, 3, "RMC") == 0;
    const std::size_t end = text.find_first_of("\r\n", pos);
    if (ours && end != std::string::npos) {
      char& c = text[pos + 7];
      c = c == '1' ? '2' : '1';
      ++corrupted;
    }
    pos = end == std::string::npos ? text.size() : end;
  }
  ASSERT_GT(corrupted, 0U);
  const auto tmp =
      std::filesystem::temp_directory_path() / ("fieldguard_corrupt_" + std::to_string(::getpid()) + "_" + log);
  std::ofstream(tmp, std::ios::binary) << text;
  const auto run = run_fieldguard("inspect --format nmea '" + tmp.string() + "'");
  std::filesystem::remove(tmp);
  ASSERT_EQ(run.exit_code, 0) << run.output.substr(0, 2000);
  const auto records = testing::json_lines(run.output);
  const std::size_t others = count_lines(text, {"VTG", "HDT", "THS"});
  EXPECT_EQ(records.size(), others);
  EXPECT_EQ(summary_number(run.output, "bad_checksum"), static_cast<long long>(corrupted));
}

INSTANTIATE_TEST_SUITE_P(Logs, GpsdLog,
                         ::testing::Values("haicom-305N.log", "hemi.log", "nmea-fuzzy-cases.log", "nmea-rtk.log",
                                           "sirfstarv-nmea.log", "skytraq-PX1172RH_DS.log", "telit-he910.log",
                                           "ublox-f9p-hpnmea.log", "ublox-zed-f9p-nmea.log", "unicore-um621.log"),
                         [](const auto& tp) {
                           std::string n = tp.param;
                           for (char& c : n) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return n;
                         });

}  // namespace
}  // namespace fieldguard
