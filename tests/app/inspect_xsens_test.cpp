// Acceptance: real Xsens MTData2 streams (an MTi-G-710, einride/xsens-go testdata 1..5: float32, fixed 12.20,
// fixed 16.32, float64, and a set with quaternion, rotation matrix, magnetic field, pressure, GNSS) decode through
// `fieldguard inspect` to exactly the values of the golden decodes beside them. The golden numbers are Go's
// shortest representation of the same doubles, so equality is exact.
// tests/data/xsens/einride_expected.txt holds the golden decode of the first messages of each set (and of the
// first message with each data type); when ../shared/realdata is there, every message is compared as well.

#include <gtest/gtest.h>

#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"

namespace fieldguard {
namespace {

using testing::Json;
using testing::run_fieldguard;
using testing::summary_number;

const std::string kData = std::string(FIELDGUARD_TEST_DATA) + "/xsens/";
const std::filesystem::path kRealData =
    std::filesystem::path(FIELDGUARD_SOURCE_DIR) / ".." / "shared" / "realdata" / "xsens-mtdata2-einride";

// One golden message: (name, values) in order, e.g. ("Acceleration(Float32)", {"-0.017", "-7.25", "-1.2"}).
using Golden = std::vector<std::pair<std::string, std::vector<std::string>>>;

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> v;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, sep)) v.push_back(item);
  return v;
}

// A golden value line without its "X:" / "Q0:" / "Lat:" label (GNSS records keep "Key:value").
std::string golden_value(const std::string& name, const std::string& line) {
  const auto colon = line.find(':');
  if (name.rfind("GNSS", 0) == 0 || colon == std::string::npos || std::isdigit(static_cast<unsigned char>(line[0]))) {
    return line;
  }
  return line.substr(colon + 1);
}

// The whole output.golden text, one Golden a blank-line-separated block.
std::vector<Golden> parse_golden(const std::string& text) {
  std::vector<Golden> out(1);
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) {
      if (!out.back().empty()) out.emplace_back();
    } else if (line.rfind("  ", 0) == 0) {
      if (!out.back().empty())
        out.back().back().second.push_back(golden_value(out.back().back().first, line.substr(2)));
    } else {
      out.back().emplace_back(line.substr(0, line.size() - 1), std::vector<std::string>{});
    }
  }
  if (out.back().empty()) out.pop_back();
  return out;
}

// A line of einride_expected.txt: "<set> <index> Name=v1,v2 ..."
Golden parse_expected(const std::string& rest) {
  Golden g;
  for (const auto& item : split(rest, ' ')) {
    const auto eq = item.find('=');
    g.emplace_back(item.substr(0, eq), split(item.substr(eq + 1), ','));
  }
  return g;
}

double number(const std::string& s) {
  double v = 0.0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  EXPECT_TRUE(r.ec == std::errc{} && r.ptr == s.data() + s.size()) << "not a number: " << s;
  return v;
}

std::vector<double> numbers(const std::vector<std::string>& v) {
  std::vector<double> out;
  for (const auto& s : v) out.push_back(number(s));
  return out;
}

const std::map<std::string, std::string> kVectors = {{"Acceleration", "acc"},
                                                     {"DeltaV", "delta_v"},
                                                     {"RateOfTurn", "gyr"},
                                                     {"DeltaQ", "delta_q"},
                                                     {"EulerAngles", "euler_deg"},
                                                     {"Quaternion", "quat"},
                                                     {"FreeAcceleration", "free_acc"},
                                                     {"MagneticField", "mag"},
                                                     {"VelocityXYZ", "vel_mps"},
                                                     {"PositionECEF", "position_ecef_m"},
                                                     {"RotationMatrix", "rotation_matrix"}};
const std::map<std::string, std::string> kFrameKeys = {{"EulerAngles", "euler_frame"},
                                                       {"Quaternion", "quat_frame"},
                                                       {"VelocityXYZ", "vel_frame"},
                                                       {"RotationMatrix", "rotation_matrix_frame"}};
const std::map<std::string, std::string> kFrames = {
    {"EastNorthUp", "ENU"}, {"NorthEastDown", "NED"}, {"NorthWestUp", "NWU"}};
const std::map<std::string, std::string> kPvt = {{"ITOW", "itow_ms"},
                                                 {"Year", "year"},
                                                 {"Month", "month"},
                                                 {"Day", "day"},
                                                 {"Hour", "hour"},
                                                 {"Min", "min"},
                                                 {"Sec", "sec"},
                                                 {"Valid", "valid"},
                                                 {"TAcc", "t_acc_ns"},
                                                 {"Nano", "nano_ns"},
                                                 {"FixType", "fix_type"},
                                                 {"Flags", "flags"},
                                                 {"NumSV", "num_sv"},
                                                 {"Reserved1", "reserved1"},
                                                 {"Lon", "lon_1e7deg"},
                                                 {"Lat", "lat_1e7deg"},
                                                 {"Height", "height_mm"},
                                                 {"HMSL", "hmsl_mm"},
                                                 {"HAcc", "h_acc_mm"},
                                                 {"VAcc", "v_acc_mm"},
                                                 {"VelN", "vel_n_mmps"},
                                                 {"VelE", "vel_e_mmps"},
                                                 {"VelD", "vel_d_mmps"},
                                                 {"GSpeed", "gspeed_mmps"},
                                                 {"HeadMot", "head_mot_1e5deg"},
                                                 {"SAcc", "s_acc_mmps"},
                                                 {"HeadAcc", "head_acc_1e5deg"},
                                                 {"HeadVeh", "head_veh_1e5deg"},
                                                 {"GDOP", "gdop"},
                                                 {"PDOP", "pdop"},
                                                 {"TDOP", "tdop"},
                                                 {"VDOP", "vdop"},
                                                 {"HDOP", "hdop"},
                                                 {"NDOP", "ndop"},
                                                 {"EDOP", "edop"}};

// Compares one record with its golden decode; adds the number of golden fields compared to `fields`.
void compare(const Golden& g, const Json& r, const std::string& where, std::size_t& fields) {
  fields += g.size();
  EXPECT_EQ(r.at("type").get<std::string>(), "MTData2") << where;
  std::set<std::string> expected_keys = {"type", "packet_counter", "sample_time_fine"};
  for (const auto& [name, vals] : g) {
    const std::string base = name.substr(0, name.find('('));
    const std::string at = where + " " + name;
    EXPECT_FALSE(vals.empty()) << at;
    if (vals.empty()) continue;
    const std::string& v0 = vals[0];
    if (base == "PacketCounter") {
      EXPECT_EQ(testing::text(r.at("packet_counter")), v0) << at;
    } else if (base == "SampleTimeFine") {
      EXPECT_EQ(testing::text(r.at("sample_time_fine")), v0) << at;
    } else if (base == "SampleTimeCoarse") {
      EXPECT_EQ(testing::text(r.at("sample_time_coarse")), v0) << at;
      expected_keys.insert("sample_time_coarse");
    } else if (base == "UTCTime") {
      EXPECT_EQ(testing::text(r.at("utc_time")), v0) << at;
      expected_keys.insert({"utc_time", "utc_flags"});
    } else if (base == "StatusWord" || base == "StatusByte") {
      const std::string key = base == "StatusWord" ? "status_word" : "status_byte";
      EXPECT_EQ(r.at(key).get<long long>(), std::stoll(v0, nullptr, 2)) << at;
      expected_keys.insert(key);
    } else if (base == "BaroPressure") {
      EXPECT_EQ(testing::text(r.at("baro_pa")), v0) << at;
      expected_keys.insert("baro_pa");
    } else if (base == "Temperature") {
      EXPECT_EQ(r.at("temperature_c").get<double>(), number(v0)) << at;
      expected_keys.insert("temperature_c");
    } else if (base == "AltitudeEllipsoid") {
      EXPECT_EQ(r.at("alt_ellipsoid_m").get<double>(), number(v0)) << at;
      expected_keys.insert("alt_ellipsoid_m");
    } else if (base == "LatLon") {
      EXPECT_EQ(vals.size(), 2U) << at;
      EXPECT_EQ(r.at("lat_deg").get<double>(), number(vals.front())) << at;
      EXPECT_EQ(r.at("lon_deg").get<double>(), number(vals.back())) << at;
      expected_keys.insert({"lat_deg", "lon_deg"});
    } else if (kVectors.count(base) != 0) {
      const std::string& key = kVectors.at(base);
      EXPECT_EQ(r.at(key).get<std::vector<double>>(), numbers(vals)) << at;
      expected_keys.insert(key);
      if (kFrameKeys.count(base) != 0) {
        const std::string frame = name.substr(name.find('(') + 1, name.find(',') - name.find('(') - 1);
        EXPECT_EQ(r.at(kFrameKeys.at(base)).get<std::string>(), kFrames.at(frame)) << at;
        expected_keys.insert(kFrameKeys.at(base));
      }
    } else if (base == "GNSSPVTData") {
      EXPECT_EQ(vals.size(), kPvt.size()) << at;
      for (const auto& kv : vals) {
        const auto parts = split(kv, ':');
        EXPECT_EQ(parts.size(), 2U) << at;
        if (parts.size() != 2 || kPvt.count(parts[0]) == 0) {
          ADD_FAILURE() << at << ": " << kv;
          continue;
        }
        EXPECT_EQ(testing::text(r.at("gnss_pvt").at(kPvt.at(parts[0]))), parts[1]) << at << " " << parts[0];
      }
      expected_keys.insert("gnss_pvt");
    } else if (base == "GNSSSatInfo") {
      for (const auto& kv : vals) {
        const auto parts = split(kv, ':');
        if (parts.size() == 2 && parts[0] == "ITOW") {
          EXPECT_EQ(testing::text(r.at("gnss_sat_info").at("itow_ms")), parts[1]) << at;
        }
        if (parts.size() == 2 && parts[0] == "NumSVS") {
          EXPECT_EQ(testing::text(r.at("gnss_sat_info").at("num_svs")), parts[1]) << at;
        }
      }
      expected_keys.insert("gnss_sat_info");
    } else {
      ADD_FAILURE() << at << ": golden field this test does not know";
    }
  }
  // Nothing decoded that the golden decode does not have.
  std::set<std::string> keys;
  for (const auto& [k, v] : r.items()) keys.insert(k);
  EXPECT_EQ(keys, expected_keys) << where;
}

std::vector<Json> inspect_set(int set, std::string* output = nullptr) {
  const std::string path = kData + "einride_" + std::to_string(set) + ".bin";
  const auto run = run_fieldguard("inspect '" + path + "'");
  EXPECT_EQ(run.exit_code, 0) << run.output.substr(0, 2000);
  if (output != nullptr) *output = run.output;
  return testing::json_lines(run.output);
}

TEST(InspectXsens, EveryMessageOfTheRealStreamsDecodes) {
  for (int set = 1; set <= 5; ++set) {
    std::string out;
    const auto records = inspect_set(set, &out);
    EXPECT_EQ(records.size(), 100U) << "set " << set;
    EXPECT_NE(out.find("format             xsens (guessed)"), std::string::npos) << out.substr(out.size() - 800);
    EXPECT_EQ(summary_number(out, "MTData2"), 100) << "set " << set;
    EXPECT_EQ(summary_number(out, "rejected"), 0) << "set " << set;
    EXPECT_EQ(summary_number(out, "garbage_bytes"), 0) << "set " << set;
    EXPECT_EQ(summary_number(out, "unknown_data_ids"), 0) << "set " << set;
    for (const auto& r : records) {
      EXPECT_TRUE(r.at("packet_counter").is_number() && r.at("sample_time_fine").is_number());
    }
  }
}

TEST(InspectXsens, ValuesEqualTheGoldenDecodes) {
  std::map<int, std::vector<Json>> sets;
  for (int set = 1; set <= 5; ++set) sets[set] = inspect_set(set);
  std::ifstream f(kData + "einride_expected.txt");
  ASSERT_TRUE(f) << "einride_expected.txt";
  std::string line;
  std::size_t messages = 0;
  std::size_t fields = 0;
  while (std::getline(f, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    int set = 0;
    std::size_t index = 0;
    in >> set >> index;
    std::string rest;
    std::getline(in >> std::ws, rest);
    ASSERT_LT(index, sets[set].size());
    compare(parse_expected(rest), sets[set][index], "set " + std::to_string(set) + " #" + std::to_string(index),
            fields);
    ++messages;
  }
  EXPECT_GE(messages, 60U);
  std::printf("[ xsens    ] %zu messages, %zu golden fields compared (fixture)\n", messages, fields);
}

TEST(InspectXsens, EveryMessageEqualsTheFullGoldenDecodeWhenTheRealDataIsThere) {
  if (!std::filesystem::exists(kRealData / "1" / "output.golden")) {
    GTEST_SKIP() << "no " << kRealData << " (the full golden files are not copied into tests/data)";
  }
  std::size_t messages = 0;
  std::size_t fields = 0;
  for (int set = 1; set <= 5; ++set) {
    std::ifstream f(kRealData / std::to_string(set) / "output.golden");
    std::stringstream s;
    s << f.rdbuf();
    const auto golden = parse_golden(s.str());
    const auto records = inspect_set(set);
    ASSERT_EQ(golden.size(), records.size()) << "set " << set;
    for (std::size_t i = 0; i < golden.size(); ++i) {
      compare(golden[i], records[i], "set " + std::to_string(set) + " #" + std::to_string(i), fields);
      ++messages;
    }
  }
  EXPECT_EQ(messages, 500U);
  std::printf("[ xsens    ] %zu messages, %zu golden fields compared (full golden files)\n", messages, fields);
}

}  // namespace
}  // namespace fieldguard
