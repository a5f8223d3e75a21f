// `fieldguard inspect` on Hokuyo SCIP 2.0 sessions built here (there is no real SCIP capture): a fieldguard byte
// log of a scripted session (start-up, laser on, continuous scans, a single scan, bad replies), the same replies as
// raw text, and broken logs.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"
#include "drivers/scip_test_support.hpp"
#include "fieldguard/io/byte_log.hpp"
#include "io/pcap_builder.hpp"

namespace fieldguard {
namespace {

namespace st = scip::test;
using testing::Json;
using testing::run_fieldguard;
using testing::summary_number;
using testing::TempDir;

constexpr std::int64_t kT0 = 1'700'000'000'000'000'000;
constexpr const char* kMdEcho = "MD0000108001000";

struct Chunk {
  io::Direction direction;
  std::string bytes;
};

// The session, in the order the bytes went over the link.
std::vector<Chunk> session() {
  using D = io::Direction;
  std::string bad_check = st::scan_reply(kMdEcho, "99", 1500, st::range_pattern(1081, 9));
  bad_check[bad_check.find('\n', 40) - 3] ^= 0x01;  // a data character of a line: its check code no longer fits
  const std::string second = st::scan_reply(kMdEcho, "99", 1025, st::range_pattern(1081, 2));
  return {
      {D::ToSensor, "SCIP2.0\n"},
      {D::FromSensor, st::simple_reply("SCIP2.0", "0E")},  // already in SCIP 2.0: "command not defined"
      {D::ToSensor, "VV\nPP\nII\n"},
      {D::FromSensor, st::utm_vv_reply() + st::utm_pp_reply()},
      {D::FromSensor, st::utm_ii_reply()},
      {D::ToSensor, "BM\n"},
      {D::FromSensor, st::simple_reply("BM", "00")},
      {D::ToSensor, "BM\n"},
      {D::FromSensor, st::simple_reply("BM", "02")},  // laser already on
      {D::ToSensor, std::string(kMdEcho) + "\n"},
      {D::FromSensor, st::simple_reply(kMdEcho, "00")},
      {D::FromSensor, st::scan_reply(kMdEcho, "99", 1000, st::range_pattern(1081, 1))},
      {D::FromSensor, second.substr(0, 1000)},  // one scan over two reads
      {D::FromSensor, second.substr(1000)},
      {D::FromSensor, "hello\n\n"},                                                   // malformed_line
      {D::FromSensor, bad_check},                                                     // bad_check_code
      {D::FromSensor, st::scan_reply(kMdEcho, "99", 1050, st::range_pattern(1080))},  // bad_data_length
      {D::FromSensor, st::simple_reply("VV", "00", st::line("NOCOLON"))},             // bad_field
      {D::FromSensor, st::scan_reply(kMdEcho, "99", 1075, st::range_pattern(1081, 3))},
      {D::ToSensor, "QT\nGD0000108001\n"},
      {D::FromSensor, st::simple_reply("QT", "00")},
      {D::FromSensor, st::scan_reply("GD0000108001", "00", 2000, st::range_pattern(1081, 4))},
  };
}

std::int64_t time_of(std::size_t i) { return kT0 + static_cast<std::int64_t>(i) * 10'000'000; }

double seconds(std::int64_t ns) {
  return static_cast<double>(ns / 1'000'000'000) + static_cast<double>(ns % 1'000'000'000) * 1e-9;
}

std::string write_log(const TempDir& dir, const std::string& name, const std::string& source) {
  const std::string path = (dir.path() / name).string();
  auto w = io::ByteLogWriter::create(path, source);
  EXPECT_TRUE(w.has_value());
  const auto chunks = session();
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    const std::string& b = chunks[i].bytes;
    EXPECT_TRUE(w->write(Stamp{time_of(i)}, chunks[i].direction,
                         ByteSpan(reinterpret_cast<const std::uint8_t*>(b.data()), b.size())));  // NOLINT
  }
  return path;
}

std::string sensor_text() {
  std::string text;
  for (const auto& c : session()) {
    if (c.direction == io::Direction::FromSensor) text += c.bytes;
  }
  return text;
}

std::string arg(const std::string& path) { return "'" + path + "'"; }

// Valid ranges (DMIN 23 .. DMAX 60000 of the PP reply) of a pattern: count, min, max.
struct Valid {
  long long n = 0;
  long long lo = 0;
  long long hi = 0;
};
Valid valid(const std::vector<std::uint32_t>& ranges) {
  Valid v{0, 1LL << 40, 0};
  for (const auto r : ranges) {
    if (r < 23 || r > 60000) continue;
    ++v.n;
    v.lo = std::min<long long>(v.lo, r);
    v.hi = std::max<long long>(v.hi, r);
  }
  return v;
}

void expect_session(const std::string& output, bool with_times) {
  std::size_t bad = 0;
  const auto r = testing::json_lines(output, &bad);
  EXPECT_EQ(bad, 0U);
  ASSERT_EQ(r.size(), 9U) << output;
  std::vector<std::string> types;
  for (const auto& rec : r)
    types.push_back(rec.at("type").get<std::string>() + ":" + rec.at("command").get<std::string>());
  EXPECT_EQ(types, (std::vector<std::string>{"scip_status:SCIP2.0", "scip_info:VV", "scip_info:PP", "scip_info:II",
                                             "scip_status:BM", "scip_scan:MD", "scip_scan:MD", "scip_scan:MD",
                                             "scip_scan:GD"}));
  EXPECT_EQ(r[0].at("status").get<std::string>(), "0E");
  EXPECT_EQ(r[0].at("text").get<std::string>(), "command not defined");
  EXPECT_EQ(r[1].at("SERI").get<std::string>(), "H1234567");
  EXPECT_EQ(r[1].at("PROT").get<std::string>(), "SCIP 2.0");
  EXPECT_EQ(r[2].at("MODL").get<std::string>(), "UTM-30LX-EW");
  EXPECT_EQ(r[2].at("AFRT").get<std::string>(), "540");
  EXPECT_EQ(r[3].at("STAT").get<std::string>(), "Stable 000 no error.");
  EXPECT_EQ(r[4].at("status").get<std::string>(), "02");
  EXPECT_EQ(r[4].at("category").get<std::string>(), "parameter_error");
  EXPECT_EQ(r[4].at("text").get<std::string>(), "laser already on");

  const Json& scan = r[5];
  EXPECT_EQ(scan.at("timestamp_ms").get<long long>(), 1000);
  EXPECT_EQ(scan.at("first_step").get<long long>(), 0);
  EXPECT_EQ(scan.at("last_step").get<long long>(), 1080);
  EXPECT_EQ(scan.at("cluster").get<long long>(), 1);
  EXPECT_EQ(scan.at("remaining_scans").get<long long>(), 0);
  EXPECT_EQ(scan.at("values").get<long long>(), 1081);
  const Valid v = valid(st::range_pattern(1081, 1));
  EXPECT_EQ(scan.at("valid").get<long long>(), v.n);
  EXPECT_EQ(scan.at("min_range_mm").get<long long>(), v.lo);
  EXPECT_EQ(scan.at("max_range_mm").get<long long>(), v.hi);
  EXPECT_FALSE(scan.at("intensities").get<bool>());
  EXPECT_EQ(r[6].at("timestamp_ms").get<long long>(), 1025);
  EXPECT_EQ(r[7].at("timestamp_ms").get<long long>(), 1075);
  EXPECT_EQ(r[8].at("timestamp_ms").get<long long>(), 2000);
  EXPECT_EQ(r[8].at("valid").get<long long>(), valid(st::range_pattern(1081, 4)).n);
  if (with_times) {
    EXPECT_EQ(r[0].at("time").get<double>(), seconds(time_of(1)));
    EXPECT_EQ(r[3].at("time").get<double>(), seconds(time_of(4)));
    EXPECT_EQ(r[6].at("time").get<double>(), seconds(time_of(13)));  // completed by the second read
    EXPECT_EQ(r[8].at("time").get<double>(), seconds(time_of(21)));
  } else {
    for (const auto& rec : r) EXPECT_TRUE(rec.contains("time") && rec.at("time").is_null());
  }

  EXPECT_EQ(summary_number(output, "scip_scan"), 4);
  EXPECT_EQ(summary_number(output, "scip_info"), 3);
  EXPECT_EQ(summary_number(output, "scip_status"), 2);
  EXPECT_EQ(summary_number(output, "acks"), 3);  // BM, MD, QT
  EXPECT_EQ(summary_number(output, "malformed_line"), 1);
  EXPECT_EQ(summary_number(output, "bad_check_code"), 1);
  EXPECT_EQ(summary_number(output, "bad_data_length"), 1);
  EXPECT_EQ(summary_number(output, "bad_field"), 1);
  EXPECT_EQ(summary_number(output, "rejected"), 4);
}

TEST(InspectScip, ByteLogOfAScriptedSession) {
  TempDir dir;
  const std::string path = write_log(dir, "scan2d.log", "scip 192.168.0.10:10940");
  const auto run = run_fieldguard("inspect " + arg(path));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("scip (guessed)"), std::string::npos) << run.output;
  expect_session(run.output, true);
  EXPECT_EQ(summary_number(run.output, "log_records"), static_cast<long long>(session().size()));
  EXPECT_EQ(summary_number(run.output, "to_sensor_bytes"), 8 + 9 + 3 + 3 + 16 + 16);
  EXPECT_NE(run.output.find("byte log \"scip 192.168.0.10:10940\""), std::string::npos) << run.output;

  // A source line naming the 2D LiDAR another way is guessed too; given explicitly, any byte log is read.
  const std::string other = write_log(dir, "other.log", "Scan2D front");
  EXPECT_NE(run_fieldguard("inspect " + arg(other)).output.find("scip (guessed)"), std::string::npos);
  const std::string unnamed = write_log(dir, "unnamed.log", "tcp 10.0.0.2");
  EXPECT_EQ(run_fieldguard("inspect " + arg(unnamed)).exit_code, 2);
  const auto forced = run_fieldguard("inspect --format scip " + arg(unnamed));
  EXPECT_EQ(forced.exit_code, 0) << forced.output;
  expect_session(forced.output, true);
}

TEST(InspectScip, RawTextOfTheRepliesHasNoTimes) {
  TempDir dir;
  const std::string text = sensor_text();
  const std::string path = dir.write("replies.txt", testing::Bytes(text.begin(), text.end()));
  const auto run = run_fieldguard("inspect " + arg(path));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("scip (guessed)"), std::string::npos) << run.output;
  expect_session(run.output, false);
  // Other echoes start a capture as well.
  for (const std::string& start : {std::string("VV\n00P\n"), std::string(kMdEcho) + "\n99b\n"}) {
    const std::string p = dir.write("start.txt", testing::Bytes(start.begin(), start.end()));
    EXPECT_NE(run_fieldguard("inspect " + arg(p)).output.find("scip (guessed)"), std::string::npos) << start;
  }
}

TEST(InspectScip, BrokenByteLogs) {
  TempDir dir;
  const std::string good = write_log(dir, "good.log", "scip x");
  const auto size = std::filesystem::file_size(good);
  std::ifstream in(good, std::ios::binary);
  testing::Bytes bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());

  // Cut inside the last record: what came before is decoded, the cut is reported.
  testing::Bytes cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(size - 100));
  const auto c = run_fieldguard("inspect " + arg(dir.write("cut.log", cut)));
  EXPECT_EQ(c.exit_code, 0) << c.output;
  EXPECT_EQ(summary_number(c.output, "scip_scan"), 3);
  EXPECT_NE(c.output.find("  truncated          the file ends inside a record"), std::string::npos) << c.output;

  // A record header claiming 4 GiB: reading stops there, with a note.
  testing::Bytes corrupt = bytes;
  const testing::Bytes header{1, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0xFF, 0xFF, 0xFF, 0};
  corrupt.insert(corrupt.end(), header.begin(), header.end());
  corrupt.insert(corrupt.end(), bytes.begin(), bytes.end());
  const auto k = run_fieldguard("inspect " + arg(dir.write("corrupt.log", corrupt)));
  EXPECT_EQ(k.exit_code, 0) << k.output;
  EXPECT_EQ(summary_number(k.output, "scip_scan"), 4);
  EXPECT_NE(k.output.find("corrupt record 23 (length 4294967295, direction 0)"), std::string::npos) << k.output;

  // A header line without its end: unusable.
  const std::string h = std::string(io::kByteLogMagic) + "scip 192.168.0.10";
  const auto u = run_fieldguard("inspect " + arg(dir.write("header.log", testing::Bytes(h.begin(), h.end()))));
  EXPECT_EQ(u.exit_code, 2) << u.output;
  EXPECT_NE(u.output.find("header is cut short"), std::string::npos) << u.output;
}

}  // namespace
}  // namespace fieldguard
