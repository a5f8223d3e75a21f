// Record-then-replay: the emulators feed a live `fieldguard record` (3D LiDAR UDP on loopback, the 2D LiDAR
// over TCP, GNSS and AHRS on pseudo-terminals); `fieldguard replay --session` must decode the recording to
// exactly the samples record decoded live, sensor by sensor.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"
#include "app/sim_can_support.hpp"
#include "fieldguard/io/pcap_reader.hpp"
#include "io/pcap_builder.hpp"
#include "support/child_process.hpp"

namespace fieldguard {
namespace {

using namespace std::chrono_literals;

using Child = testing::ChildProcess;

std::uint16_t free_udp_port() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

// The sample lines of a --samples-out file by their "sensor", each as written (the comparison is byte for byte).
std::map<std::string, std::vector<std::string>> by_sensor(const std::string& path) {
  std::map<std::string, std::vector<std::string>> m;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    const testing::Json j = testing::Json::parse(line, nullptr, /*allow_exceptions=*/false);
    if (!j.is_object() || !j.contains("sensor") || !j.at("sensor").is_string()) continue;
    m[j.at("sensor").get<std::string>()].push_back(line);
  }
  return m;
}

// Sends every UDP datagram of `pcap` to loopback, to the port `to_port` maps its captured port to, `pause` apart
// (about the sensor's packet rate). Returns how many were sent, by captured port; a port not in the map counts as
// unsent under its own number with nothing sent.
std::map<std::uint16_t, std::size_t> send_capture(const std::string& pcap,
                                                  const std::map<std::uint16_t, std::uint16_t>& to_port,
                                                  std::chrono::microseconds pause) {
  std::map<std::uint16_t, std::size_t> sent;
  auto reader = io::PcapReader::open(pcap);
  EXPECT_TRUE(reader.has_value()) << pcap;
  if (!reader) return sent;
  const int tx = ::socket(AF_INET, SOCK_DGRAM, 0);
  while (auto d = reader->next()) {
    const auto port = to_port.find(d->dst_port);
    std::size_t& n = sent[d->dst_port];
    if (port == to_port.end()) continue;
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(port->second);
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::sendto(tx, d->payload.data(), d->payload.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to) > 0) ++n;
    std::this_thread::sleep_for(pause);
  }
  ::close(tx);
  return sent;
}

TEST(RecordReplay, ReplayDecodesExactlyWhatWasDecodedLive) {
  testing::TempDir dir;
  const std::string data = FIELDGUARD_TEST_DATA;
  Child scip({FIELDGUARD_SCIP_EMULATOR, "--scene", "obstacle"});
  const std::string scip_port = scip.line();
  ASSERT_FALSE(scip_port.empty());
  Child gnss(
      {FIELDGUARD_SERIAL_EMULATOR, "--file", data + "/nmea/nmea-rtk.log", "--baud", "115200", "--hold-open", "30"});
  const std::string gnss_dev = gnss.line();
  Child ahrs(
      {FIELDGUARD_SERIAL_EMULATOR, "--file", data + "/xsens/einride_1.bin", "--baud", "921600", "--hold-open", "30"});
  const std::string ahrs_dev = ahrs.line();
  ASSERT_FALSE(gnss_dev.empty());
  ASSERT_FALSE(ahrs_dev.empty());

  const std::uint16_t data_port = free_udp_port();
  const std::uint16_t position_port = free_udp_port();
  const std::string config = (dir.path() / "live.yaml").string();
  std::ofstream(config) << "lidar: {model: auto, data_port: " << data_port << ", position_port: " << position_port
                        << ", msop_port: " << free_udp_port() << ", difop_port: " << free_udp_port() << "}\n"
                        << "scan2d: {enabled: true, host: 127.0.0.1, port: " << scip_port << "}\n"
                        << "gnss: {enabled: true, device: " << gnss_dev << ", baud: 115200}\n"
                        << "ahrs: {enabled: true, device: " << ahrs_dev << ", baud: 921600}\n";
  const std::string session = (dir.path() / "session").string();
  const std::string live = (dir.path() / "live.jsonl").string();
  Child record(
      {FIELDGUARD_BINARY, "record", "--config", config, "--out", session, "--duration", "3", "--samples-out", live});
  std::this_thread::sleep_for(500ms);  // let it bind its ports

  // The real HDL-32E capture, sent to the recorder at the sensor's packet rate.
  const auto sent = send_capture(data + "/hdl32e_monterey_600.pcap", {{2368, data_port}, {8308, position_port}}, 550us);
  ASSERT_EQ(sent.at(2368) + sent.at(8308), 600U);
  ASSERT_EQ(record.wait(), 0);

  const std::string replayed = (dir.path() / "replay.jsonl").string();
  auto r = testing::run_fieldguard("replay --config '" + config + "' --session '" + session + "' --samples-out '" +
                                   replayed + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;

  const auto a = by_sensor(live);
  const auto b = by_sensor(replayed);
  for (const char* sensor : {"lidar", "lidar_position", "scan2d", "gnss", "ahrs"}) {
    ASSERT_TRUE(a.count(sensor)) << "nothing decoded live from " << sensor;
    EXPECT_FALSE(a.at(sensor).empty()) << sensor;
    ASSERT_TRUE(b.count(sensor)) << "nothing replayed from " << sensor << "\n" << r.output;
    EXPECT_EQ(a.at(sensor), b.at(sensor)) << sensor;
  }
  std::printf("live samples: lidar %zu, lidar_position %zu, scan2d %zu, gnss %zu, ahrs %zu\n", a.at("lidar").size(),
              a.at("lidar_position").size(), a.at("scan2d").size(), a.at("gnss").size(), a.at("ahrs").size());
  EXPECT_EQ(a.at("lidar_position").size(), 60U);
  EXPECT_EQ(a.at("gnss").size(), 244U);   // every sentence of the log (122 GGA + 122 RMC)
  EXPECT_EQ(a.at("ahrs").size(), 100U);   // every message of the einride stream
  EXPECT_GT(a.at("scan2d").size(), 60U);  // 40 Hz for about 2.5 s

  // The same recording given file by file.
  const std::string one_by_one = (dir.path() / "files.jsonl").string();
  auto f =
      testing::run_fieldguard("replay --config '" + config + "' --pcap '" + session + "/lidar.pcap' --scan2d-log '" +
                              session + "/scan2d.log' --gnss-log '" + session + "/gnss.log' --ahrs-log '" + session +
                              "/ahrs.log' --samples-out '" + one_by_one + "'");
  ASSERT_EQ(f.exit_code, 0) << f.output;
  EXPECT_EQ(by_sensor(one_by_one), b);
}

// The same for an RS-LiDAR-32 alone (the simulator's MSOP and DIFOP, model auto): the rotations replay decodes
// from the recording are the ones record decoded live, point for point (the digests), DIFOP's angles included.
TEST(RecordReplay, Rs32ReplayDecodesExactlyWhatWasDecodedLive) {
  testing::TempDir dir;
  testing::PedestrianCapture capture(12, "rs32");
  ASSERT_TRUE(capture.ok) << capture.command;
  const std::uint16_t msop_port = free_udp_port();
  const std::uint16_t difop_port = free_udp_port();
  const std::string config = (dir.path() / "live.yaml").string();
  std::ofstream(config) << "lidar: {model: auto, data_port: " << free_udp_port()
                        << ", position_port: " << free_udp_port() << ", msop_port: " << msop_port
                        << ", difop_port: " << difop_port << "}\n";
  const std::string session = (dir.path() / "session").string();
  const std::string live = (dir.path() / "live.jsonl").string();
  Child record(
      {FIELDGUARD_BINARY, "record", "--config", config, "--out", session, "--duration", "3", "--samples-out", live});
  std::this_thread::sleep_for(500ms);  // let it bind its ports

  // About the sensor's packet rate (666 us at 600 rpm).
  const auto sent = send_capture(capture.pcap, {{6699, msop_port}, {7788, difop_port}}, 600us);
  EXPECT_EQ(sent.size(), 2U) << "datagrams to other ports than MSOP and DIFOP";
  EXPECT_EQ(sent.at(6699), 12U * 150U);
  EXPECT_EQ(sent.at(7788), 2U);  // at 0 s and 1 s
  ASSERT_EQ(record.wait(), 0);

  const std::string replayed = (dir.path() / "replay.jsonl").string();
  auto r = testing::run_fieldguard("replay --config '" + config + "' --session '" + session + "' --samples-out '" +
                                   replayed + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("model             RS-32"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("angles from DIFOP"), std::string::npos) << r.output;
  const auto a = by_sensor(live);
  const auto b = by_sensor(replayed);
  ASSERT_TRUE(a.count("lidar")) << "nothing decoded live";
  ASSERT_TRUE(b.count("lidar")) << r.output;
  EXPECT_GE(a.at("lidar").size(), 12U);  // every rotation, the first and last partial ones too
  EXPECT_EQ(a.at("lidar"), b.at("lidar"));
}

}  // namespace
}  // namespace fieldguard
