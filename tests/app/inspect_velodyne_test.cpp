// `fieldguard inspect` on Velodyne pcaps: the real HDL-32E and VLP-16 captures (records, keys, model detection),
// and built pcaps with every kind of bad input counted by its reason.

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"
#include "fieldguard/io/pcap_reader.hpp"
#include "io/pcap_builder.hpp"

namespace fieldguard {
namespace {

using testing::Bytes;
using testing::ClassicPcap;
using testing::Json;
using testing::run_fieldguard;
using testing::summary_number;
using testing::TempDir;

const std::string kData = std::string(FIELDGUARD_TEST_DATA) + "/";

struct Payload {
  Bytes bytes;
  std::int64_t time_ns = 0;
};

// The first `n` data payloads (port 2368) of a real capture.
std::vector<Payload> real_data_packets(const std::string& file, std::size_t n) {
  auto r = io::PcapReader::open(kData + file);
  EXPECT_TRUE(r.has_value());
  std::vector<Payload> out;
  while (r && out.size() < n) {
    const auto d = r->next();
    if (!d) break;
    if (d->dst_port == 2368) out.push_back({Bytes(d->payload.begin(), d->payload.end()), d->host_time.ns});
  }
  return out;
}

Bytes udp_frame(std::uint16_t port, const Bytes& payload) {
  testing::Ipv4Udp d;
  d.src_port = port;
  d.dst_port = port;
  d.payload = payload;
  return testing::ethernet(testing::build(d));
}

std::string arg(const std::string& path) { return "'" + path + "'"; }

long long total_points(const std::vector<Json>& records) {
  return std::accumulate(records.begin(), records.end(), 0LL, [](long long s, const Json& r) {
    return s + (r.contains("points") ? r.at("points").get<long long>() : 0);
  });
}

TEST(InspectVelodyne, Hdl32eMontereyDataAndPositionRecords) {
  const auto run = run_fieldguard("inspect " + arg(kData + "hdl32e_monterey_600.pcap"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::size_t bad = 0;
  const auto r = testing::json_lines(run.output, &bad);
  EXPECT_EQ(bad, 0U);
  ASSERT_EQ(r.size(), 600U);
  EXPECT_NE(run.output.find("velodyne (guessed)"), std::string::npos) << run.output;
  EXPECT_EQ(summary_number(run.output, "velodyne_data"), 540);
  EXPECT_EQ(summary_number(run.output, "velodyne_position"), 60);
  EXPECT_EQ(summary_number(run.output, "rejected"), 0);
  EXPECT_NE(run.output.find("  model              HDL-32E (spacing 553 us"), std::string::npos) << run.output;

  const Json& d = r[0];
  EXPECT_EQ(d.at("type").get<std::string>(), "velodyne_data");
  EXPECT_EQ(testing::text(d.at("time")), "1355263594.123168");
  EXPECT_EQ(d.at("port").get<long long>(), 2368);
  EXPECT_EQ(d.at("timestamp_us").get<long long>(), 393203883);
  EXPECT_EQ(d.at("return_mode").get<std::string>(), "strongest");
  EXPECT_EQ(d.at("product_byte").get<long long>(), 0x21);
  EXPECT_EQ(d.at("first_azimuth_deg").get<double>(), 150.54);
  EXPECT_EQ(d.at("last_azimuth_deg").get<double>(), 152.7);
  EXPECT_EQ(d.at("points").get<long long>(), 339);

  std::size_t data = 0;
  std::size_t positions = 0;
  for (const auto& rec : r) {
    if (rec.at("type").get<std::string>() == "velodyne_data") {
      ++data;
      EXPECT_GT(rec.at("points").get<long long>(), 0);
      EXPECT_LE(rec.at("points").get<long long>(), 384);
    } else {
      ASSERT_EQ(rec.at("type").get<std::string>(), "velodyne_position");
      ++positions;
      EXPECT_EQ(rec.at("port").get<long long>(), 8308);
      EXPECT_EQ(rec.at("pps").get<std::string>(), "absent");  // the HDL-32E leaves byte 202 at 0
      EXPECT_EQ(rec.at("nmea").get<std::string>().rfind("$GPRMC,", 0), 0U) << rec.at("nmea").get<std::string>();
      EXPECT_NEAR(rec.at("lat_deg").get<double>(), 37.13, 0.01);  // Monterey highway, California
      EXPECT_NEAR(rec.at("lon_deg").get<double>(), -121.65, 0.01);
      EXPECT_TRUE(rec.contains("timestamp_us") && rec.contains("time"));
    }
  }
  EXPECT_EQ(data, 540U);
  EXPECT_EQ(positions, 60U);
  // Every decoded return is in a record; the stream's rotations are in the summary.
  EXPECT_EQ(total_points(r), summary_number(run.output, "points"));
  EXPECT_EQ(summary_number(run.output, "rotations_full"), 2);
  EXPECT_EQ(summary_number(run.output, "rotations_partial"), 2);
}

TEST(InspectVelodyne, Vlp16DetectedDespiteTheHdl32eProductByte) {
  const auto run = run_fieldguard("inspect " + arg(kData + "vlp16_veloview_300.pcap"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto r = testing::json_lines(run.output);
  ASSERT_EQ(r.size(), 300U);
  EXPECT_NE(run.output.find("  model              VLP-16 (spacing 1327 us"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("product byte 0x21 (HDL-32E) is what early VLP-16 firmware reports"), std::string::npos);
  EXPECT_EQ(r[0].at("product_byte").get<long long>(), 0x21);
  std::size_t positions = 0;
  for (const auto& rec : r) {
    if (rec.at("type").get<std::string>() == "velodyne_position") {
      ++positions;
      EXPECT_EQ(rec.at("port").get<long long>(), 8308);
    } else {
      EXPECT_LE(rec.at("points").get<long long>(), 384);  // 12 blocks x 32 slots
    }
  }
  EXPECT_EQ(total_points(r), summary_number(run.output, "points"));
  // This unit's 47 position packets claim an IP total length of 1234 in a 554-byte frame: the records are
  // whole, so the reader trusts the UDP length, decodes them and counts the repair.
  EXPECT_EQ(positions, 47U);
  EXPECT_EQ(summary_number(run.output, "velodyne_position"), 47);
  EXPECT_EQ(summary_number(run.output, "ip_length_repaired"), 47);
  EXPECT_EQ(summary_number(run.output, "bad_ip_header"), 0);
  EXPECT_EQ(summary_number(run.output, "no_model"), 0);
}

TEST(InspectVelodyne, EveryRejectionIsCountedByReason) {
  auto real = real_data_packets("hdl32e_monterey_600.pcap", 20);
  ASSERT_EQ(real.size(), 20U);
  Bytes bad_azimuth = real[15].bytes;
  bad_azimuth[2] = 0xFF;  // block 0 azimuth 0xFFxx >= 36000
  bad_azimuth[3] = 0xFF;
  testing::Ipv4Udp tcp;
  tcp.protocol = 6;
  Bytes truncated = udp_frame(2368, real[0].bytes);
  truncated.resize(100);

  ClassicPcap file;
  for (std::size_t i = 0; i < real.size(); ++i) {
    file.add(udp_frame(2368, real[i].bytes), real[i].time_ns);
    if (i == 10) {
      const std::int64_t t = real[i].time_ns + 1000;
      file.add(udp_frame(2368, testing::pattern(1206)), t)  // bad_block_flag
          .add(udp_frame(2368, testing::pattern(100)), t)   // bad_length
          .add(udp_frame(2368, bad_azimuth), t)             // bad_azimuth
          .add(udp_frame(8308, testing::pattern(200)), t)   // position_bad_length
          .add(udp_frame(9999, real[i].bytes), t)           // other_port
          .add(testing::ethernet(Bytes(28, 0), 0x0806), t)  // not_ipv4 (ARP)
          .add(testing::ethernet(testing::build(tcp)), t)   // not_udp
          .add(truncated, t, 1248);                         // truncated_record
    }
  }
  TempDir dir;
  const auto run = run_fieldguard("inspect " + arg(dir.write("bad.pcap", file.bytes())));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto r = testing::json_lines(run.output);
  EXPECT_EQ(r.size(), 20U);
  for (const auto& rec : r) EXPECT_EQ(rec.at("type").get<std::string>(), "velodyne_data");
  for (const char* reason : {"bad_block_flag", "bad_length", "bad_azimuth", "position_bad_length", "other_port",
                             "not_ipv4", "not_udp", "truncated_record"}) {
    EXPECT_EQ(summary_number(run.output, reason), 1) << reason << "\n" << run.output;
  }
  EXPECT_EQ(summary_number(run.output, "rejected"), 8);
  EXPECT_EQ(summary_number(run.output, "pcap_records"), 28);
  EXPECT_NE(run.output.find("  model              HDL-32E"), std::string::npos) << run.output;
}

TEST(InspectVelodyne, PacketsWithoutAModelAreRejectedAndPositionsStillPrinted) {
  // Product byte 0 and one timestamp for all: neither the spacing nor the factory byte tells the model.
  auto real = real_data_packets("hdl32e_monterey_600.pcap", 20);
  ASSERT_EQ(real.size(), 20U);
  ClassicPcap file;
  for (std::size_t i = 0; i < real.size(); ++i) {
    real[i].bytes[1205] = 0x00;
    for (std::size_t k = 1200; k < 1204; ++k) real[i].bytes[k] = real[0].bytes[k];
    file.add(udp_frame(2368, real[i].bytes), real[i].time_ns);
    if (i == 17) {
      Bytes position(512, 0);
      const std::string nmea = "$GPRMC,220632,A,3707.8324,N,12139.2864,W,000.0,144.7,111212,013.8,E,D*09\r\n";
      std::copy(nmea.begin(), nmea.end(), position.begin() + 206);
      file.add(udp_frame(8308, position), real[i].time_ns);
    }
  }
  TempDir dir;
  const auto run = run_fieldguard("inspect --format velodyne " + arg(dir.write("nomodel.pcap", file.bytes())));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto r = testing::json_lines(run.output);
  ASSERT_EQ(r.size(), 1U) << run.output;
  EXPECT_EQ(r[0].at("type").get<std::string>(), "velodyne_position");
  EXPECT_NEAR(r[0].at("lat_deg").get<double>(), 37.13054, 1e-9);
  EXPECT_EQ(summary_number(run.output, "no_model"), 20);
  EXPECT_NE(run.output.find("  model              undecided"), std::string::npos) << run.output;
}

TEST(InspectVelodyne, PortOptionsAndPcapng) {
  const auto real = real_data_packets("hdl32e_monterey_600.pcap", 12);
  ASSERT_EQ(real.size(), 12U);
  testing::Pcapng ng;
  ng.interface(1);
  ClassicPcap moved;
  for (const auto& p : real) {
    ng.enhanced(0, static_cast<std::uint64_t>(p.time_ns / 1000), udp_frame(2368, p.bytes));
    moved.add(udp_frame(2369, p.bytes), p.time_ns);
  }
  TempDir dir;
  // pcapng, guessed as a pcap.
  const auto a = run_fieldguard("inspect " + arg(dir.write("a.pcapng", ng.bytes())));
  ASSERT_EQ(a.exit_code, 0) << a.output;
  EXPECT_EQ(testing::json_lines(a.output).size(), 12U);
  EXPECT_NE(a.output.find("velodyne (guessed)"), std::string::npos) << a.output;

  // Data on another port: other_port without the option, decoded with it.
  const std::string moved_path = arg(dir.write("moved.pcap", moved.bytes()));
  const auto b = run_fieldguard("inspect " + moved_path);
  EXPECT_EQ(testing::json_lines(b.output).size(), 0U);
  EXPECT_EQ(summary_number(b.output, "other_port"), 12);
  const auto c = run_fieldguard("inspect --format velodyne --data-port 2369 --position-port=8309 " + moved_path);
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const auto rc = testing::json_lines(c.output);
  ASSERT_EQ(rc.size(), 12U);
  EXPECT_EQ(rc[0].at("port").get<long long>(), 2369);
  EXPECT_NE(c.output.find("data 2369, position 8309"), std::string::npos) << c.output;

  for (const char* bad : {"0", "65536", "http", "23x"}) {
    const auto e = run_fieldguard("inspect --data-port " + std::string(bad) + " " + moved_path);
    EXPECT_EQ(e.exit_code, 2) << bad;
    EXPECT_NE(e.output.find("--data-port wants a UDP port number"), std::string::npos) << e.output;
  }
}

TEST(InspectVelodyne, UnusableAndCutFiles) {
  TempDir dir;
  // Not a pcap at all, forced: unusable.
  const auto text = dir.write("text.log", Bytes{'h', 'e', 'l', 'l', 'o', '\n'});
  const auto t = run_fieldguard("inspect --format velodyne " + arg(text));
  EXPECT_EQ(t.exit_code, 2) << t.output;
  EXPECT_EQ(t.output.find("inspect summary"), std::string::npos) << t.output;
  EXPECT_NE(t.output.find("not a pcap or pcapng file (it starts with 0x68656C6C)"), std::string::npos) << t.output;

  // A real capture cut inside its 11th record: the 10 whole ones are inspected, the cut is reported.
  ClassicPcap file;
  for (const auto& p : real_data_packets("hdl32e_monterey_600.pcap", 11)) file.add(udp_frame(2368, p.bytes), p.time_ns);
  Bytes cut = file.bytes();
  cut.resize(cut.size() - 500);
  const auto c = run_fieldguard("inspect " + arg(dir.write("cut.pcap", cut)));
  EXPECT_EQ(c.exit_code, 0) << c.output;
  EXPECT_EQ(testing::json_lines(c.output).size(), 10U);
  EXPECT_NE(c.output.find("  truncated          the file ends inside a record"), std::string::npos) << c.output;
}

}  // namespace
}  // namespace fieldguard
