// `fieldguard replay` on real and malformed captures, through the real binary.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "app/run_command.hpp"
#include "fieldguard/io/pcap_reader.hpp"
#include "io/pcap_builder.hpp"

namespace fieldguard {
namespace {

namespace fs = std::filesystem;
using testing::Bytes;
using testing::run_fieldguard;
using testing::summary_number;

const std::string kData = FIELDGUARD_TEST_DATA;
const std::string kConfig = std::string(FIELDGUARD_SOURCE_DIR) + "/config/fieldguard.yaml";
const std::string kHdl = kData + "/hdl32e_monterey_600.pcap";

std::string replay(const std::string& pcap, const std::string& extra = "") {
  return "replay --config '" + kConfig + "' --pcap '" + pcap + "' " + extra;
}

// Real data-packet payloads from the shipped HDL-32E capture.
std::vector<Bytes> real_payloads(std::uint16_t port, std::size_t n) {
  std::vector<Bytes> out;
  auto r = io::PcapReader::open(kHdl);
  EXPECT_TRUE(r.has_value());
  while (auto d = r->next()) {
    if (d->dst_port == port) out.emplace_back(d->payload.begin(), d->payload.end());
    if (out.size() == n) break;
  }
  return out;
}

Bytes frame_for(const Bytes& payload, std::uint16_t port) {
  testing::Ipv4Udp d;
  d.dst_port = port;
  d.payload = payload;
  return testing::ethernet(testing::build(d));
}

TEST(Replay, RealHdl32eCaptureGivesRotationsAndPcds) {
  testing::TempDir dir;
  const auto pcd = (dir.path() / "pcd").string();
  auto r = run_fieldguard(replay(kHdl, "--pcd-dir '" + pcd + "'"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(summary_number(r.output, "records read"), 600) << r.output;
  const auto data = summary_number(r.output, "data packets");
  EXPECT_GT(data, 500);
  EXPECT_NE(r.output.find(std::to_string(data) + " read, " + std::to_string(data) + " decoded"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("model             HDL-32E"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("with RMC"), std::string::npos);
  EXPECT_EQ(summary_number(r.output, "dropped"), 0) << r.output;
  // 540 data packets at ~11.7 Hz: the block azimuths wrap past 0 three times (counted independently with a
  // script over the pcap), so two full turns between two partial ones.
  EXPECT_EQ(data, 540);
  EXPECT_NE(r.output.find("rotations         2 full, 2 partial"), std::string::npos) << r.output;
  EXPECT_GT(summary_number(r.output, "points"), 100000);

  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(pcd)) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_EQ(files.size(), 4U);
  EXPECT_EQ(files.front().filename(), "frame_000000_partial.pcd");
  EXPECT_EQ(files[1].filename(), "frame_000001.pcd");
  EXPECT_EQ(files.back().filename(), "frame_000003_partial.pcd");
  std::ifstream in(files[1]);
  std::string line;
  std::string fields;
  long long points = -1;
  while (std::getline(in, line) && line.rfind("DATA", 0) != 0) {
    if (line.rfind("FIELDS", 0) == 0) fields = line;
    if (line.rfind("POINTS", 0) == 0) points = std::stoll(line.substr(7));
  }
  EXPECT_EQ(fields, "FIELDS x y z intensity ring time");
  EXPECT_GT(points, 40000);  // a full HDL-32E turn at ~11.7 Hz: ~155 packets of up to 384 returns
  EXPECT_EQ(line, "DATA binary");
}

TEST(Replay, EarlyVlp16FirmwareIsDetectedAsVlp16) {
  auto r = run_fieldguard(replay(kData + "/vlp16_veloview_300.pcap"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("model             VLP-16"), std::string::npos) << r.output;
}

TEST(Replay, MissingFile) {
  auto r = run_fieldguard(replay("/nonexistent/capture.pcap"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("/nonexistent/capture.pcap"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("replay summary"), std::string::npos);
}

TEST(Replay, NotAPcap) {
  testing::TempDir dir;
  const auto path = dir.write("notes.pcap", Bytes{'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd', '\n',
                                                  'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd', '\n'});
  auto r = run_fieldguard(replay(path));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("not a pcap"), std::string::npos) << r.output;
}

TEST(Replay, EmptyFile) {
  testing::TempDir dir;
  auto r = run_fieldguard(replay(dir.write("empty.pcap", {})));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("empty.pcap"), std::string::npos) << r.output;
}

TEST(Replay, TruncatedFileKeepsEverythingBeforeTheCut) {
  std::ifstream in(kHdl, std::ios::binary);
  Bytes bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Walk the classic-pcap records (little-endian, as this file is) to the last one, and cut it in half.
  std::size_t off = 24;
  std::size_t last = off;
  while (off + 16 <= bytes.size()) {
    last = off;
    const std::size_t caplen =
        bytes[off + 8] | (std::size_t{bytes[off + 9]} << 8) | (std::size_t{bytes[off + 10]} << 16);
    off += 16 + caplen;
  }
  ASSERT_EQ(off, bytes.size());
  bytes.resize(last + 16 + (bytes.size() - last - 16) / 2);
  testing::TempDir dir;
  auto r = run_fieldguard(replay(dir.write("cut.pcap", bytes)));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(summary_number(r.output, "records read"), 599) << r.output;
  EXPECT_NE(r.output.find("file truncated    yes"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("truncated"), std::string::npos);
}

TEST(Replay, GarbagePayloadsAreCountedAndTheInputIsUnusable) {
  testing::ClassicPcap pcap;
  for (int i = 0; i < 5; ++i) pcap.add(frame_for(testing::pattern(1206, static_cast<std::uint8_t>(i)), 2368), 1000 + i);
  testing::TempDir dir;
  auto r = run_fieldguard(replay(dir.write("garbage.pcap", pcap.bytes())));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("data_bad_block_flag     5"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("none of the 5 datagrams to port 2368"), std::string::npos) << r.output;
}

TEST(Replay, BadLengthsOtherPortsAndGoodPacketsMixed) {
  const auto good = real_payloads(2368, 40);
  ASSERT_EQ(good.size(), 40U);
  testing::ClassicPcap pcap;
  std::int64_t t = 1'700'000'000'000'000'000;
  for (const auto& p : good) pcap.add(frame_for(p, 2368), t += 552'960);
  Bytes short_payload(good[0].begin(), good[0].begin() + 1000);
  pcap.add(frame_for(short_payload, 2368), t += 1000);         // wrong length on the data port
  pcap.add(frame_for(testing::pattern(64), 9999), t += 1000);  // another port
  testing::Ipv4Udp frag;
  frag.payload = good[0];
  frag.flags_fragment = 0x2000;  // more fragments
  pcap.add(testing::ethernet(testing::build(frag)), t += 1000);
  testing::TempDir dir;
  auto r = run_fieldguard(replay(dir.write("mixed.pcap", pcap.bytes())));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("40 read, 40 decoded"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("data_bad_length         1"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("other_port              1"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("ip_fragment             1"), std::string::npos) << r.output;
  EXPECT_EQ(summary_number(r.output, "dropped"), 3) << r.output;
}

TEST(Replay, NoDataPortTrafficIsUnusable) {
  testing::ClassicPcap pcap;
  pcap.add(frame_for(testing::pattern(100), 5000), 1);
  testing::TempDir dir;
  auto r = run_fieldguard(replay(dir.write("other.pcap", pcap.bytes())));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("no UDP datagram to the data port 2368"), std::string::npos) << r.output;
}

// RS-32 MSOP headers (model byte at 30), otherwise empty: enough for the stream to tell the sensor.
Bytes msop_payload(std::uint8_t model_byte) {
  Bytes b(1248, 0);
  const std::uint8_t header[] = {0x55, 0xAA, 0x05, 0x0A, 0x5A, 0xA5, 0x50, 0xA0};
  std::copy(std::begin(header), std::end(header), b.begin());
  b[30] = model_byte;
  return b;
}

// The model says one family, the capture holds the other's packets: the error says so instead of "no datagram".
TEST(Replay, AnotherLidarFamilyThanTheModelIsNamed) {
  testing::ClassicPcap pcap;
  for (int i = 0; i < 3; ++i) pcap.add(frame_for(msop_payload(0x02), 6699), 1000 * (i + 1));
  testing::TempDir dir;
  const auto cfg = dir.write("hdl.yaml", Bytes{});
  std::ofstream(cfg) << "lidar: {model: HDL-32E}\n";
  auto r = run_fieldguard("replay --config '" + cfg + "' --pcap '" + dir.write("rs.pcap", pcap.bytes()) + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("holds only packets of another 3D LiDAR than lidar.model HDL-32E (3 dropped)"),
            std::string::npos)
      << r.output;
}

// MSOP packets of another RoboSense model: refused and named, never decoded as RS-32 ones.
TEST(Replay, AnotherRoboSenseModelIsRefusedByName) {
  testing::ClassicPcap pcap;
  for (int i = 0; i < 3; ++i) pcap.add(frame_for(msop_payload(0x01), 6699), 1000 * (i + 1));
  testing::TempDir dir;
  auto r = run_fieldguard(replay(dir.write("rs16.pcap", pcap.bytes())));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("MSOP packets of RS-LiDAR-16 (model byte 0x01)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("msop_refused            3"), std::string::npos) << r.output;
}

TEST(Replay, InvalidConfigIsRefused) {
  testing::TempDir dir;
  const auto cfg = dir.write("bad.yaml", Bytes{'l', 'i', 'd', 'a', 'r', ':', ' ', '3', '\n'});
  auto r = run_fieldguard("replay --config '" + cfg + "' --pcap '" + kHdl + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("bad.yaml:1: lidar: expected a mapping"), std::string::npos) << r.output;
}

TEST(Replay, PcdDirThatIsAFile) {
  testing::TempDir dir;
  const auto file = dir.write("taken", Bytes{1});
  auto r = run_fieldguard(replay(kHdl, "--pcd-dir '" + file + "'"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("cannot create the PCD directory"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace fieldguard
