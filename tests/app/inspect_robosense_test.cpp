// `fieldguard inspect` on a RoboSense RS-32 pcap built here (there is no real RS-32 capture): MSOP records once a
// DIFOP gave the angle table, DIFOP records, every rejection counted by reason, and the format guessed from the
// UDP ports.

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"
#include "drivers/robosense_test_support.hpp"
#include "io/pcap_builder.hpp"

namespace fieldguard {
namespace {

using robosense::test::DifopBuilder;
using robosense::test::MsopBuilder;
using testing::Bytes;
using testing::ClassicPcap;
using testing::Json;
using testing::run_fieldguard;
using testing::summary_number;
using testing::TempDir;

constexpr std::int64_t kT0 = 1'711'009'815'200'000'000;  // pcap time, ns

Bytes frame(std::uint16_t port, const Bytes& payload) {
  testing::Ipv4Udp d;
  d.src_ip = testing::ipv4(192, 168, 1, 200);
  d.src_port = port;
  d.dst_port = port;
  d.payload = payload;
  return testing::ethernet(testing::build(d));
}

// MSOP packet k of a rotation: 12 blocks of 0.2 degrees, every channel at 10 m (2000 x 0.5 cm).
Bytes msop(int k) {
  MsopBuilder b;
  b.azimuths(k * 240, 20).all_channels(2000, 50).time_us(robosense::test::kExampleUnixUs + k * 1000LL);
  return b.bytes();
}

std::string arg(const std::string& path) { return "'" + path + "'"; }

TEST(InspectRobosense, MsopAndDifopRecordsAndRejectionsByReason) {
  ClassicPcap file;
  std::int64_t t = kT0;
  const auto add = [&](std::uint16_t port, const Bytes& payload) { file.add(frame(port, payload), t += 1'000'000); };
  add(6699, msop(0));  // before any DIFOP: no angle table yet
  add(6699, msop(1));
  add(7788, DifopBuilder().bytes());
  for (int k = 2; k < 8; ++k) add(6699, msop(k));
  add(6699, testing::pattern(1248));  // msop_bad_magic
  add(6699, testing::pattern(100));   // msop_bad_length
  Bytes bad_time = msop(8);
  bad_time[21] = 13;  // month 13
  add(6699, bad_time);
  DifopBuilder bad_angles;
  bad_angles.triplet(468, 5, 0x05, 1000);  // sign byte neither 00 nor 01
  add(7788, bad_angles.bytes());
  add(7788, testing::pattern(1248, 3));  // difop_bad_magic
  add(2368, msop(9));                    // not a RoboSense port
  TempDir dir;
  const auto run = run_fieldguard("inspect " + arg(dir.write("rs32.pcap", file.bytes())));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("robosense (guessed)"), std::string::npos) << run.output;
  std::size_t bad = 0;
  const auto r = testing::json_lines(run.output, &bad);
  EXPECT_EQ(bad, 0U);
  ASSERT_EQ(r.size(), 7U) << run.output;

  const Json& difop = r[0];
  EXPECT_EQ(difop.at("type").get<std::string>(), "robosense_difop");
  EXPECT_EQ(difop.at("port").get<long long>(), 7788);
  EXPECT_EQ(difop.at("rpm").get<long long>(), 600);
  EXPECT_EQ(difop.at("firmware_top").get<std::string>(), "09230906A1");
  EXPECT_EQ(difop.at("serial").get<std::string>(), "101112131415");
  EXPECT_EQ(difop.at("return_mode").get<std::string>(), "strongest");
  EXPECT_EQ(difop.at("return_mode_byte").get<long long>(), 1);
  EXPECT_EQ(difop.at("distance_unit").get<std::string>(), "0.5cm");
  EXPECT_EQ(difop.at("fov_end_deg").get<double>(), 360.0);
  EXPECT_EQ(difop.at("timestamp_utc").get<std::string>(), "2024-03-21T08:30:15.123456Z");
  EXPECT_TRUE(difop.at("angle_table").get<bool>());
  EXPECT_EQ(testing::text(difop.at("time")), "1711009815.203");

  for (std::size_t i = 1; i < r.size(); ++i) {
    const Json& m = r[i];
    const int k = static_cast<int>(i) + 1;
    EXPECT_EQ(m.at("type").get<std::string>(), "robosense_msop");
    EXPECT_EQ(m.at("port").get<long long>(), 6699);
    EXPECT_EQ(m.at("points").get<long long>(), 384) << i;  // 12 blocks x 32 channels, all in range
    EXPECT_EQ(m.at("first_azimuth_deg").get<double>(), (k * 240) / 100.0);
    EXPECT_EQ(m.at("last_azimuth_deg").get<double>(), (k * 240 + 220) / 100.0);
    EXPECT_FALSE(m.at("dual_layout").get<bool>());
    EXPECT_EQ(m.at("temperature_c").get<double>(), 0.0);
  }
  EXPECT_EQ(r[1].at("timestamp_utc").get<std::string>(), "2024-03-21T08:30:15.125456Z");

  EXPECT_EQ(summary_number(run.output, "robosense_msop"), 6);
  EXPECT_EQ(summary_number(run.output, "robosense_difop"), 1);
  EXPECT_EQ(summary_number(run.output, "msop_no_calibration"), 2);
  EXPECT_EQ(summary_number(run.output, "msop_bad_magic"), 1);
  EXPECT_EQ(summary_number(run.output, "msop_bad_length"), 1);
  EXPECT_EQ(summary_number(run.output, "msop_bad_timestamp"), 1);
  EXPECT_EQ(summary_number(run.output, "difop_bad_angle_table"), 1);
  EXPECT_EQ(summary_number(run.output, "difop_bad_magic"), 1);
  EXPECT_EQ(summary_number(run.output, "other_port"), 1);
  EXPECT_EQ(summary_number(run.output, "rejected"), 8);
  EXPECT_EQ(summary_number(run.output, "points"), 6 * 384);
  EXPECT_NE(run.output.find("angle table from DIFOP, distance unit 0.5cm"), std::string::npos) << run.output;
}

TEST(InspectRobosense, WithoutDifopNothingDecodes) {
  ClassicPcap file;
  for (int k = 0; k < 4; ++k) file.add(frame(6699, msop(k)), kT0 + k * 1'000'000LL);
  TempDir dir;
  const auto run = run_fieldguard("inspect " + arg(dir.write("msop_only.pcap", file.bytes())));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("robosense (guessed)"), std::string::npos) << run.output;
  EXPECT_TRUE(testing::json_lines(run.output).empty());
  EXPECT_EQ(summary_number(run.output, "msop_no_calibration"), 4);
  EXPECT_NE(run.output.find("none: no valid DIFOP packet"), std::string::npos) << run.output;

  // The same as pcapng (nanosecond timestamps): guessed from its first datagrams as well.
  testing::Pcapng ng;
  ng.interface(1, std::uint8_t{9});
  for (int k = 0; k < 4; ++k) ng.enhanced(0, static_cast<std::uint64_t>(kT0 + k * 1'000'000LL), frame(6699, msop(k)));
  const auto g = run_fieldguard("inspect " + arg(dir.write("msop_only.pcapng", ng.bytes())));
  ASSERT_EQ(g.exit_code, 0) << g.output;
  EXPECT_NE(g.output.find("robosense (guessed)"), std::string::npos) << g.output;
  EXPECT_EQ(summary_number(g.output, "msop_no_calibration"), 4);
}

TEST(InspectRobosense, PortOptionsAndTheGuessFromSizes) {
  // Sent to other ports: guessed from the 1248-byte payloads; decoded with --data-port / --position-port.
  ClassicPcap file;
  file.add(frame(7000, DifopBuilder().bytes()), kT0);
  for (int k = 0; k < 3; ++k) file.add(frame(7001, msop(k)), kT0 + (k + 1) * 1'000'000LL);
  TempDir dir;
  const std::string path = arg(dir.write("ports.pcap", file.bytes()));
  const auto plain = run_fieldguard("inspect " + path);
  EXPECT_NE(plain.output.find("robosense (guessed)"), std::string::npos) << plain.output;
  EXPECT_EQ(summary_number(plain.output, "other_port"), 4);
  const auto run = run_fieldguard("inspect " + path + " --data-port 7001 --position-port 7000");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto r = testing::json_lines(run.output);
  ASSERT_EQ(r.size(), 4U) << run.output;
  EXPECT_EQ(r[0].at("type").get<std::string>(), "robosense_difop");
  EXPECT_EQ(r[3].at("points").get<long long>(), 384);
}

}  // namespace
}  // namespace fieldguard
