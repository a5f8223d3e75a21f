// The live UDP receiver on real loopback sockets.

#include "fieldguard/io/udp_receiver.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>

namespace fieldguard::io {
namespace {

using Clock = std::chrono::steady_clock;

class Sender {
 public:
  explicit Sender(std::uint16_t port) : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    to_.sin_family = AF_INET;
    to_.sin_port = htons(port);
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  ~Sender() { ::close(fd_); }
  Sender(const Sender&) = delete;
  Sender& operator=(const Sender&) = delete;
  bool send(std::uint32_t seq, std::size_t size) {
    std::vector<std::uint8_t> p(size, 0xAB);
    std::memcpy(p.data(), &seq, sizeof seq);
    return ::sendto(fd_, p.data(), p.size(), 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_) ==
           static_cast<ssize_t>(p.size());
  }

 private:
  int fd_;
  sockaddr_in to_{};
};

struct Received {
  std::vector<std::uint32_t> seq;
  std::vector<std::int64_t> rx_ns;
  std::size_t wrong_size = 0;
};

// The HDL-32E's line rate (1808 packets/s of 1206 bytes) for 10 s on loopback: nothing may be lost,
// nothing reordered, and every datagram carries a kernel receive time.
TEST(UdpReceiver, HdlLineRateForTenSecondsLosesNothing) {
  boost::asio::io_context io;
  Received got;
  UdpReceiverOptions o;
  o.bind_address = "127.0.0.1";
  o.port = 0;
  UdpReceiver rx(io, o, [&](const UdpDatagram& d) {
    if (d.payload.size() != 1206) {
      ++got.wrong_size;
      return;
    }
    std::uint32_t seq = 0;
    std::memcpy(&seq, d.payload.data(), sizeof seq);
    got.seq.push_back(seq);
    got.rx_ns.push_back(d.host_time.ns);
  });
  rx.start();
  std::thread io_thread([&] { io.run(); });

  constexpr std::uint32_t kRate = 1808;
  constexpr std::uint32_t kSeconds = 10;
  constexpr std::uint32_t kTotal = kRate * kSeconds;
  Sender tx(rx.local_port());
  const auto start = Clock::now();
  std::uint32_t sent = 0;
  for (std::uint32_t i = 0; i < kTotal; ++i) {
    std::this_thread::sleep_until(start + std::chrono::nanoseconds(1'000'000'000LL * i / kRate));
    sent += tx.send(i, 1206) ? 1U : 0U;
  }
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (rx.stats().datagrams.load() < sent && Clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  io.stop();
  io_thread.join();

  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("sent %u datagrams in %.2f s, received %zu, kernel drops %llu, buffer %d bytes\n", sent, elapsed,
              got.seq.size(), static_cast<unsigned long long>(rx.stats().kernel_drops.load()),
              rx.granted_receive_buffer_bytes());
  ASSERT_EQ(sent, kTotal);
  ASSERT_EQ(got.seq.size(), kTotal);
  EXPECT_EQ(got.wrong_size, 0U);
  EXPECT_EQ(rx.stats().kernel_drops.load(), 0U);
  for (std::uint32_t i = 0; i < kTotal; ++i) ASSERT_EQ(got.seq[i], i) << "reordered or lost at " << i;
  const auto now_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  // Kernel receive times are wall-clock (CLOCK_REALTIME) times: they need not be monotonic (the clock may be
  // slewed or stepped, and a time sync daemon runs here), but they must follow the sender's pacing: 10 s from
  // the first to the last, and no two consecutive ones far apart.
  for (std::size_t i = 1; i < got.rx_ns.size(); ++i) {
    ASSERT_LT(std::abs(got.rx_ns[i] - got.rx_ns[i - 1]), 100'000'000) << "at " << i;
  }
  EXPECT_NEAR(static_cast<double>(got.rx_ns.back() - got.rx_ns.front()) * 1e-9, (kTotal - 1) / double{kRate}, 0.5);
  EXPECT_NEAR(static_cast<double>(got.rx_ns.back()), static_cast<double>(now_ns), 30e9);
}

// A receiver that does not read while a burst overflows its (tiny) buffer: the kernel's drop count is
// reported, and received + dropped = sent.
TEST(UdpReceiver, KernelDropsAreCounted) {
  boost::asio::io_context io;
  std::size_t received = 0;
  UdpReceiverOptions o;
  o.bind_address = "127.0.0.1";
  o.port = 0;
  o.receive_buffer_bytes = 4096;
  UdpReceiver rx(io, o, [&](const UdpDatagram&) { ++received; });
  Sender tx(rx.local_port());
  constexpr std::uint32_t kBurst = 500;
  for (std::uint32_t i = 0; i < kBurst; ++i) ASSERT_TRUE(tx.send(i, 1206));
  rx.start();
  io.run_for(std::chrono::milliseconds(200));
  ASSERT_TRUE(tx.send(kBurst, 1206));  // SO_RXQ_OVFL travels with the next datagram read
  io.restart();
  io.run_for(std::chrono::milliseconds(200));
  const auto drops = rx.stats().kernel_drops.load();
  std::printf("burst %u + 1: received %zu, kernel drops %llu\n", kBurst, received,
              static_cast<unsigned long long>(drops));
  EXPECT_GT(drops, 0U);
  EXPECT_EQ(received + drops, kBurst + 1U);
}

TEST(UdpReceiver, BindFailureNamesThePort) {
  boost::asio::io_context io;
  UdpReceiverOptions o;
  o.bind_address = "127.0.0.1";
  o.port = 0;
  UdpReceiver first(io, o, [](const UdpDatagram&) {});
  UdpReceiverOptions clash = o;
  clash.port = first.local_port();
  clash.bind_address = "192.0.2.1";  // not an address of this machine
  try {
    UdpReceiver second(io, clash, [](const UdpDatagram&) {});
    FAIL() << "bound to an address this machine does not have";
  } catch (const std::system_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot bind UDP 192.0.2.1:" + std::to_string(clash.port)), std::string::npos)
        << e.what();
  }
  o.bind_address = "not-an-address";
  EXPECT_THROW(UdpReceiver(io, o, [](const UdpDatagram&) {}), std::system_error);
}

}  // namespace
}  // namespace fieldguard::io
