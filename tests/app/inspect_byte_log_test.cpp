// `fieldguard inspect` of the GNSS and AHRS byte logs `fieldguard record` writes: the format is guessed from
// the log's source line, and the samples are exactly those of the same bytes inspected raw, however the
// serial reads cut them into records, with bytes sent to the sensor counted and not decoded.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "app/run_command.hpp"
#include "fieldguard/io/byte_log.hpp"
#include "io/pcap_builder.hpp"

namespace fieldguard::app {
namespace {

using testing::run_fieldguard;
using testing::summary_number;
using testing::TempDir;

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

ByteSpan span_of(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}  // NOLINT

// The bytes as a serial reader delivers them: records of uneven size (1..97 bytes) that cut sentences and
// frames anywhere, 5 ms apart, with a command to the sensor now and then.
std::string write_log(const TempDir& dir, const std::string& source, const std::string& bytes) {
  const std::string path = (dir.path() / "serial.log").string();
  auto w = io::ByteLogWriter::create(path, source);
  EXPECT_TRUE(w.has_value());
  std::size_t at = 0;
  std::int64_t t = 1'718'449'170'000'000'000;
  for (std::size_t k = 0; at < bytes.size(); ++k) {
    const std::size_t n = std::min<std::size_t>(1 + (k * 37) % 97, bytes.size() - at);
    EXPECT_TRUE(w->write(Stamp{t}, io::Direction::FromSensor, span_of(bytes.substr(at, n))));
    if (k % 50 == 7) {
      EXPECT_TRUE(w->write(Stamp{t}, io::Direction::ToSensor, span_of("$PASHS,NME,GGA,A,ON\r\n")));
    }
    at += n;
    t += 5'000'000;
  }
  return path;
}

// The JSON lines of an inspect run (its summary lines do not start with '{').
std::vector<std::string> samples(const std::string& output) {
  std::vector<std::string> lines;
  std::istringstream in(output);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.front() == '{') lines.push_back(line);
  }
  return lines;
}

void expect_same_samples(const std::string& raw_path, const std::string& source, const std::string& format) {
  TempDir dir;
  const std::string log = write_log(dir, source, read_file(raw_path));
  const auto raw = run_fieldguard("inspect '" + raw_path + "'");
  const auto logged = run_fieldguard("inspect '" + log + "'");
  ASSERT_EQ(raw.exit_code, 0) << raw.output;
  ASSERT_EQ(logged.exit_code, 0) << logged.output;
  EXPECT_NE(logged.output.find(format + " (guessed)"), std::string::npos) << logged.output;
  const auto expected = samples(raw.output);
  ASSERT_GT(expected.size(), 50U);
  EXPECT_EQ(samples(logged.output), expected);
  EXPECT_GT(summary_number(logged.output, "log_records"), 100);
  EXPECT_GT(summary_number(logged.output, "to_sensor_bytes"), 0);
}

TEST(InspectByteLog, GnssLogDecodesLikeTheRawNmea) {
  expect_same_samples(std::string(FIELDGUARD_TEST_DATA) + "/nmea/nmea-rtk.log", "gnss /dev/ttyUSB0 115200", "nmea");
}

TEST(InspectByteLog, AhrsLogDecodesLikeTheRawXsensStream) {
  expect_same_samples(std::string(FIELDGUARD_TEST_DATA) + "/xsens/einride_1.bin", "ahrs /dev/ttyUSB1 921600", "xsens");
}

TEST(InspectByteLog, CorruptRecordStopsReadingWithANote) {
  TempDir dir;
  std::string nmea = read_file(std::string(FIELDGUARD_TEST_DATA) + "/nmea/nmea-rtk.log");
  std::string log = read_file(write_log(dir, "gnss /dev/ttyUSB0 115200", nmea));
  // Make the 3rd record's direction byte 7 (header: magic, source line, then u64 time, u32 length, u8 dir).
  std::size_t at = log.find('\n', log.find('\n') + 1) + 1;  // past the magic line and the source line
  for (int r = 0; r < 2; ++r) {
    std::uint32_t len = 0;
    for (int b = 3; b >= 0; --b)
      len = (len << 8U) | static_cast<std::uint8_t>(log[at + 8 + static_cast<std::size_t>(b)]);
    at += 13 + len;
  }
  ASSERT_LT(at + 12, log.size());
  log[at + 12] = 7;
  const std::string path = (dir.path() / "corrupt.log").string();
  std::ofstream(path, std::ios::binary) << log;
  const auto r = run_fieldguard("inspect --format nmea '" + path + "'");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("corrupt record 3"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace fieldguard::app
