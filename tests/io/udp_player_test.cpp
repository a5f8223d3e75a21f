// fieldguard-udp-player, the bench LiDAR of the live-path tests: a capture's datagrams arrive over real UDP
// on loopback, byte for byte and in order, on the ports --map names, at the capture's pace.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "fieldguard/io/pcap_reader.hpp"
#include "support/child_process.hpp"

namespace fieldguard::io {
namespace {

const std::string kCapture = std::string(FIELDGUARD_TEST_DATA) + "/hdl32e_monterey_600.pcap";

// A UDP socket bound to an ephemeral loopback port, with a receive timeout and room for a burst.
class Port {
 public:
  Port() {
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    const int buf = 4 << 20;
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &buf, sizeof buf);
    timeval tv{2, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
    socklen_t len = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
  }
  ~Port() { ::close(fd_); }
  Port(const Port&) = delete;
  Port& operator=(const Port&) = delete;
  [[nodiscard]] std::uint16_t port() const { return port_; }
  // Every datagram until none arrives for the timeout.
  std::vector<std::vector<std::uint8_t>> drain() {
    std::vector<std::vector<std::uint8_t>> got;
    std::vector<std::uint8_t> buf(65536);
    for (;;) {
      const ssize_t n = ::recv(fd_, buf.data(), buf.size(), 0);
      if (n < 0) return got;
      got.emplace_back(buf.begin(), buf.begin() + n);
    }
  }

 private:
  int fd_ = -1;
  std::uint16_t port_ = 0;
};

// The capture's payloads by destination port, as our reader sees them.
std::vector<std::vector<std::uint8_t>> payloads(std::uint16_t port) {
  auto r = PcapReader::open(kCapture);
  EXPECT_TRUE(r.has_value());
  std::vector<std::vector<std::uint8_t>> v;
  while (auto d = r->next()) {
    if (d->dst_port == port) v.emplace_back(d->payload.begin(), d->payload.end());
  }
  return v;
}

TEST(UdpPlayer, PlaysEveryDatagramInOrderToTheMappedPorts) {
  Port data;
  Port position;
  const auto t0 = std::chrono::steady_clock::now();
  testing::ChildProcess player({FIELDGUARD_UDP_PLAYER, "--pcap", kCapture, "--map",
                                "2368:" + std::to_string(data.port()), "--map",
                                "8308:" + std::to_string(position.port())});
  EXPECT_EQ(player.line(), "playing 600 datagrams");
  // Both ports are drained after the player is done; the kernel buffers hold the 0.3 s of data.
  EXPECT_EQ(player.wait(), 0);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(data.drain(), payloads(2368));
  EXPECT_EQ(position.drain(), payloads(8308));
  // At the capture's pace: the 600 records span 0.3 s, which the player may not beat (it may be later).
  EXPECT_GE(took, 0.29);
}

TEST(UdpPlayer, UnmappedPortsAreSkippedAndLoopsRepeat) {
  Port data;
  testing::ChildProcess player({FIELDGUARD_UDP_PLAYER, "--pcap", kCapture, "--map",
                                "2368:" + std::to_string(data.port()), "--loop", "2", "--speed", "0"});
  EXPECT_EQ(player.line(), "playing 540 datagrams");
  EXPECT_EQ(player.wait(), 0);
  auto expected = payloads(2368);
  const auto once = expected;
  expected.insert(expected.end(), once.begin(), once.end());
  EXPECT_EQ(data.drain().size(), expected.size());
}

std::int64_t wall_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::uint32_t stamp_of(const std::vector<std::uint8_t>& p) {
  return static_cast<std::uint32_t>(p[1200]) | static_cast<std::uint32_t>(p[1201]) << 8U |
         static_cast<std::uint32_t>(p[1202]) << 16U | static_cast<std::uint32_t>(p[1203]) << 24U;
}

// --live-time: a looped capture's LiDAR clock runs on with the host's UTC clock instead of jumping back to the
// capture's first stamp at every loop; everything else in every datagram is the capture's.
TEST(UdpPlayer, LiveTimeStampsDataPacketsWithTheWallClockAcrossLoops) {
  constexpr std::int64_t kHourUs = 3'600'000'000LL;
  const auto data_in = payloads(2368);
  const auto position_in = payloads(8308);
  ASSERT_EQ(data_in.size(), 540U);
  // Without the rewrite the stamps would go back at each seam: the capture's last stamp is after its first.
  ASSERT_GT(stamp_of(data_in.back()), stamp_of(data_in.front()));
  Port data;
  Port position;
  const std::int64_t before = wall_us();
  testing::ChildProcess player({FIELDGUARD_UDP_PLAYER, "--pcap", kCapture, "--map",
                                "2368:" + std::to_string(data.port()), "--map",
                                "8308:" + std::to_string(position.port()), "--loop", "3", "--live-time"});
  EXPECT_EQ(player.line(), "playing 600 datagrams");
  EXPECT_EQ(player.wait(), 0);
  const std::int64_t after = wall_us();
  const auto got = data.drain();
  ASSERT_EQ(got.size(), 3 * data_in.size());
  std::int64_t previous = 0;
  std::int64_t first = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    const auto& in = data_in[i % data_in.size()];
    ASSERT_EQ(got[i].size(), in.size());
    EXPECT_TRUE(std::equal(in.begin(), in.begin() + 1200, got[i].begin())) << i;
    EXPECT_TRUE(std::equal(in.begin() + 1204, in.end(), got[i].begin() + 1204)) << i;
    // The stamp is µs past the UTC hour at sending: between `before` and `after`, across an hour's top too.
    std::int64_t at = before - before % kHourUs + stamp_of(got[i]);
    if (at < before - 1000) at += kHourUs;
    EXPECT_GE(at, before - 1000) << i;  // 1 ms for the microsecond truncation of both clocks
    EXPECT_LE(at, after) << i;
    if (i > 0) {
      EXPECT_GE(at, previous) << i;
    }
    if (i == 0) first = at;
    previous = at;
  }
  // At the capture's pace: three loops of 0.3 s span at least 0.85 s of sensor time.
  EXPECT_GE(previous - first, 850'000);
  // Position packets (512 bytes) are not data packets: untouched.
  auto position_expected = position_in;
  for (int l = 0; l < 2; ++l) position_expected.insert(position_expected.end(), position_in.begin(), position_in.end());
  EXPECT_EQ(position.drain(), position_expected);
}

TEST(UdpPlayer, SigtermStopsAndStillPrintsTheSummary) {
  Port data;
  testing::ChildProcess player(
      {FIELDGUARD_UDP_PLAYER, "--pcap", kCapture, "--map", "2368:" + std::to_string(data.port()), "--loop", "1000000"});
  EXPECT_EQ(player.line(), "playing 540 datagrams");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  player.signal(SIGTERM);
  EXPECT_EQ(player.wait(), 0);  // exited by itself (-1 if the signal had killed it)
  EXPECT_GT(data.drain().size(), 0U);
}

TEST(UdpPlayer, BadCommandLinesExitTwo) {
  for (const std::vector<std::string>& args :
       std::vector<std::vector<std::string>>{{"--pcap", "/nonexistent.pcap"},
                                             {"--pcap", kCapture, "--map", "2368"},
                                             {"--pcap", kCapture, "--speed", "fast"},
                                             {"--pcap", kCapture, "--host", "localhost.invalid"},
                                             {"--pcap", kCapture, "--map", "9999:5000"},  // nothing left to play
                                             {"--bogus"}}) {
    std::vector<std::string> argv{FIELDGUARD_UDP_PLAYER};
    argv.insert(argv.end(), args.begin(), args.end());
    testing::ChildProcess player(argv);
    EXPECT_EQ(player.wait(), 2) << args[0] << " " << (args.size() > 1 ? args.back() : "");
  }
}

}  // namespace
}  // namespace fieldguard::io
