// `fieldguard inspect` as a user meets it: exit codes, format guessing, the key names scripts rely on.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"

namespace fieldguard {
namespace {

using testing::Json;
using testing::run_fieldguard;
using testing::summary_number;

namespace fs = std::filesystem;

// A temporary file with the given bytes, removed at the end of the test.
class TempFile {
 public:
  TempFile(const std::string& name, const std::string& bytes)
      : path_(fs::temp_directory_path() / ("fieldguard_inspect_" + std::to_string(::getpid()) + "_" + name)) {
    std::ofstream(path_, std::ios::binary) << bytes;
  }
  ~TempFile() { fs::remove(path_); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  [[nodiscard]] std::string arg() const { return "'" + path_.string() + "'"; }

 private:
  fs::path path_;
};

std::string bytes(std::initializer_list<int> b) {
  std::string s;
  for (const int v : b) s += static_cast<char>(v);
  return s;
}

TEST(InspectCli, HelpAndUsage) {
  const auto h = run_fieldguard("inspect --help");
  EXPECT_EQ(h.exit_code, 0);
  EXPECT_NE(h.output.find("usage: fieldguard inspect"), std::string::npos);
  EXPECT_NE(run_fieldguard("--help").output.find("inspect"), std::string::npos);
  EXPECT_EQ(run_fieldguard("inspect").exit_code, 2);
  const auto f = run_fieldguard("inspect x --format gopher");
  EXPECT_EQ(f.exit_code, 2);
  EXPECT_NE(f.output.find("unknown format 'gopher'"), std::string::npos) << f.output;
}

TEST(InspectCli, UnusableFilesExitTwo) {
  const auto missing = run_fieldguard("inspect /nonexistent/capture.log");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.output.find("cannot open"), std::string::npos) << missing.output;

  const TempFile empty("empty", "");
  const auto e = run_fieldguard("inspect " + empty.arg());
  EXPECT_EQ(e.exit_code, 2);
  EXPECT_NE(e.output.find("empty"), std::string::npos) << e.output;

  const TempFile unknown("unknown", "hello, world\nnothing to see here\n");
  const auto u = run_fieldguard("inspect " + unknown.arg());
  EXPECT_EQ(u.exit_code, 2);
  EXPECT_NE(u.output.find("cannot tell the format"), std::string::npos) << u.output;

  // A pcap cut inside its file header is unusable; one with a header and no records is read: nothing in it.
  const TempFile cut("cut_pcap", bytes({0xD4, 0xC3, 0xB2, 0xA1, 2, 0, 4, 0}));
  const auto c = run_fieldguard("inspect " + cut.arg());
  EXPECT_EQ(c.exit_code, 2);
  EXPECT_NE(c.output.find("cut short"), std::string::npos) << c.output;
  const TempFile pcap("pcap", bytes({0xD4, 0xC3, 0xB2, 0xA1, 2, 0, 4, 0}) + std::string(8, '\0') +
                                  bytes({0xFF, 0xFF, 0, 0, 1, 0, 0, 0}));  // snaplen 65535, Ethernet
  const auto p = run_fieldguard("inspect " + pcap.arg());
  EXPECT_EQ(p.exit_code, 0) << p.output;
  EXPECT_NE(p.output.find("velodyne (guessed)"), std::string::npos) << p.output;
  EXPECT_EQ(summary_number(p.output, "records"), 0);
  EXPECT_EQ(summary_number(p.output, "pcap_records"), 0);
}

TEST(InspectCli, NmeaRecordsCarryTheDocumentedKeys) {
  const std::string text =
      "# a comment line, as in gpsd logs: $GPGGA is not a sentence here\n"
      "$GNGGA,083015.00,3954.12345,N,11623.45678,E,4,18,0.7,52.3,M,-8.4,M,1.0,0123*79\r\n"
      "$GNRMC,083015.00,A,3954.12345,N,11623.45678,E,0.52,87.3,210324,,,R,V*2E\r\n"
      "$GNVTG,87.3,T,,M,0.52,N,0.96,K,R*34\r\n"
      "$GNHDT,271.45,T*1E\r\n"
      "$GNTHS,271.45,A*1C\r\n"
      "$GPGGA,,,,,,0,,,,M,,M,,*66\r\n"
      "$GPGGA,123519,4807.038,S,01131.000,W,1,08,0.9,545.4,M,46.9,M,,*47\r\n"  // checksum of the N/E original
      "$GPGSV,1,1,00*79\r\n";
  const TempFile f("keys.nmea", text);
  const auto run = run_fieldguard("inspect " + f.arg());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto r = testing::json_lines(run.output);
  ASSERT_EQ(r.size(), 6U) << run.output;

  const Json& gga = r[0];
  EXPECT_EQ(gga.at("type").get<std::string>(), "GNGGA");
  EXPECT_EQ(gga.at("time_utc").get<std::string>(), "08:30:15.000");
  EXPECT_NEAR(gga.at("lat_deg").get<double>(), 39.90205750, 1e-8);
  EXPECT_NEAR(gga.at("lon_deg").get<double>(), 116.39094633, 1e-8);
  EXPECT_EQ(gga.at("alt_m").get<double>(), 52.3);
  EXPECT_EQ(gga.at("quality").get<long long>(), 4);
  EXPECT_EQ(gga.at("sats").get<long long>(), 18);
  EXPECT_EQ(gga.at("hdop").get<double>(), 0.7);
  EXPECT_NEAR(gga.at("alt_hae_m").get<double>(), 43.9, 1e-9);  // protocols.md §4.4

  EXPECT_EQ(r[1].at("type").get<std::string>(), "GNRMC");
  EXPECT_EQ(r[1].at("status").get<std::string>(), "A");
  EXPECT_EQ(r[1].at("date").get<std::string>(), "2024-03-21");
  EXPECT_NEAR(r[1].at("speed_mps").get<double>(), 0.52 * 1852.0 / 3600.0, 1e-12);
  EXPECT_EQ(r[1].at("course_deg").get<double>(), 87.3);
  EXPECT_EQ(r[1].at("mode").get<std::string>(), "R");
  EXPECT_EQ(r[2].at("type").get<std::string>(), "GNVTG");
  EXPECT_EQ(r[2].at("course_true_deg").get<double>(), 87.3);
  EXPECT_TRUE(r[2].at("course_mag_deg").is_null());
  EXPECT_EQ(r[3].at("type").get<std::string>(), "GNHDT");
  EXPECT_EQ(r[3].at("heading_deg").get<double>(), 271.45);
  EXPECT_EQ(r[4].at("type").get<std::string>(), "GNTHS");
  EXPECT_EQ(r[4].at("mode").get<std::string>(), "A");

  // Empty fields are null, not 0; the fix quality "0" is there.
  const Json& empty = r[5];
  for (const char* k : {"time_utc", "lat_deg", "lon_deg", "alt_m", "sats", "hdop"}) {
    EXPECT_TRUE(empty.contains(k) && empty.at(k).is_null()) << k;
  }
  EXPECT_EQ(empty.at("quality").get<long long>(), 0);

  EXPECT_EQ(summary_number(run.output, "records"), 6);
  EXPECT_EQ(summary_number(run.output, "GNGGA"), 1);
  EXPECT_EQ(summary_number(run.output, "GPGGA"), 1);
  EXPECT_EQ(summary_number(run.output, "bad_checksum"), 1);
  EXPECT_EQ(summary_number(run.output, "unsupported"), 1);
  EXPECT_EQ(summary_number(run.output, "rejected"), 2);
}

TEST(InspectCli, XsensRecordsCarryTheDocumentedKeys) {
  // protocols.md §5.4: counter 42581, STF 5719854, roll 1.5, pitch -2.25, yaw 90, status 0x00400003; noise first.
  const std::string frame = bytes({0xFA, 0xFF, 0x36, 0x22, 0x10, 0x20, 0x02, 0xA6, 0x55, 0x10, 0x60, 0x04, 0x00,
                                   0x57, 0x47, 0x2E, 0x20, 0x30, 0x0C, 0x3F, 0xC0, 0x00, 0x00, 0xC0, 0x10, 0x00,
                                   0x00, 0x42, 0xB4, 0x00, 0x00, 0xE0, 0x20, 0x04, 0x00, 0x40, 0x00, 0x03, 0xD4});
  const std::string ack = bytes({0xFA, 0xFF, 0x31, 0x00, 0xD0});
  const TempFile f("keys.xbus", bytes({0x00, 0x13, 0xFA}) + frame + ack);
  const auto run = run_fieldguard("inspect " + f.arg());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto r = testing::json_lines(run.output);
  ASSERT_EQ(r.size(), 2U) << run.output;
  EXPECT_EQ(r[0].at("type").get<std::string>(), "MTData2");
  EXPECT_EQ(r[0].at("packet_counter").get<long long>(), 42581);
  EXPECT_EQ(r[0].at("sample_time_fine").get<long long>(), 5719854);
  EXPECT_EQ(r[0].at("euler_deg").get<std::vector<double>>(), (std::vector<double>{1.5, -2.25, 90.0}));
  EXPECT_EQ(r[0].at("euler_frame").get<std::string>(), "ENU");
  EXPECT_EQ(r[0].at("status_word").get<long long>(), 0x00400003);
  EXPECT_FALSE(r[0].contains("quat"));
  EXPECT_EQ(r[1].at("type").get<std::string>(), "GoToConfigAck");
  EXPECT_EQ(summary_number(run.output, "garbage_bytes"), 3);
  EXPECT_EQ(summary_number(run.output, "GoToConfigAck"), 1);

  // Given explicitly, the same.
  EXPECT_EQ(run_fieldguard("inspect --format xsens " + f.arg()).exit_code, 0);
}

TEST(InspectCli, FormatGivenExplicitlyOverridesTheGuess) {
  // NMEA text inspected as xsens: read, nothing decoded, exit 0.
  const TempFile f("nmea_as_xsens", "$GNHDT,271.45,T*1E\r\n");
  const auto run = run_fieldguard("inspect " + f.arg() + " --format xsens");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(summary_number(run.output, "records"), 0);
  EXPECT_EQ(summary_number(run.output, "garbage_bytes"), 20);
}

TEST(InspectCli, PipesAndCapturesThatStartMidSentence) {
  // A capture cut in the middle of a sentence, with a UTF-8 BOM: still recognised as NMEA.
  const std::string text =
      "\xEF\xBB\xBF"
      "45.4,M,46.9,M,,*47\r\n$GNHDT,271.45,T*1E\r\n$GNTHS,271.45,A*1C\r\n"
      "$GNVTG,87.3,T,,M,0.52,N,0.96,K,R*34\r\n";
  const TempFile f("midsentence", text);
  const auto run = run_fieldguard("inspect " + f.arg());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("nmea (guessed)"), std::string::npos) << run.output;
  EXPECT_EQ(summary_number(run.output, "records"), 3);
  // From a pipe: the bytes read to guess the format are not lost.
  const auto piped = run_fieldguard("inspect /dev/stdin < " + f.arg());
  EXPECT_EQ(piped.exit_code, 0) << piped.output;
  EXPECT_EQ(summary_number(piped.output, "records"), 3);
  EXPECT_EQ(summary_number(piped.output, "bytes"), static_cast<long long>(text.size()));
}

}  // namespace
}  // namespace fieldguard
