// The daemon's session decides a frame as soon as a worker has finished it: the worker wakes the io thread.
// No timer runs here (only the 3D LiDAR is enabled, and the daemon's output timer, which belongs to
// run_daemon, is never armed), so a decision can come from the wake-up alone.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <chrono>
#include <string>
#include <vector>

#include "daemon/session.hpp"
#include "fieldguard/io/pcap_reader.hpp"
#include "fieldguard/output/can_encoder.hpp"

namespace fieldguard::app {
namespace {

class RecordingSink final : public output::CanSink {
 public:
  void write(std::span<const output::CanFrame> frames, Stamp) override {
    for (const auto& f : frames) ids.push_back(f.id);
    stats_.sent += frames.size();
  }
  [[nodiscard]] const output::CanSinkStats& stats() const override { return stats_; }
  std::vector<std::uint32_t> ids;

 private:
  output::CanSinkStats stats_;
};

TEST(SessionWake, AFinishedFrameIsDecidedWithoutAnyTimer) {
  Config cfg;
  cfg.lidar.data_port = 0;  // the kernel chooses (for the RS-32's ports too: model auto listens on them)
  cfg.lidar.msop_port = 0;
  cfg.lidar.difop_port = 0;
  cfg.pipeline.workers = 2;
  boost::asio::io_context io;
  cfg.can.j1939.address_claim = false;  // the STOP of start-up at once, not after the claim's 250 ms
  RecordingSink sink;
  CanLink link(cfg.can, sink);
  SystemdNotifier notify = SystemdNotifier::from_environment();
  bool ready = false;
  Session session(io, cfg, link, notify, ready);
  session.start();
  const output::CanEncoder enc(cfg.can.params);
  const auto stop_requests = [&] {
    return std::count(sink.ids.begin(), sink.ids.end(), enc.id_of(output::MessageId::StopRequest));
  };
  const auto at_start = stop_requests();  // STOP, starting up: written by start()
  ASSERT_GE(at_start, 1);

  // Three and a half rotations of a real HDL-32E, sent to the session's port on loopback.
  auto pcap = io::PcapReader::open(std::string(FIELDGUARD_TEST_DATA) + "/hdl32e_monterey_600.pcap");
  ASSERT_TRUE(pcap) << pcap.error();
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(session.lidar_port());
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::size_t sent = 0;
  while (auto dg = pcap->next()) {
    if (dg->dst_port != 2368) continue;
    ASSERT_EQ(::sendto(fd, dg->payload.data(), dg->payload.size(), 0, reinterpret_cast<const sockaddr*>(&to),  // NOLINT
                       sizeof to),
              static_cast<ssize_t>(dg->payload.size()));
    ++sent;
    io.poll();  // the receiver reads what arrived; a finished frame's wake-up runs here too
  }
  ::close(fd);
  ASSERT_GT(sent, 500U);

  // Only the io context's own work from here: the receiver and the workers' wake-ups. The deadline is there to
  // end a failing run, not a measure of speed.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (session.counts().frames < 3 && std::chrono::steady_clock::now() < deadline) {
    io.run_one_for(std::chrono::milliseconds(100));
  }
  EXPECT_GE(session.counts().frames, 3U) << "rotations finished by the workers were not decided without a timer";
  // Each decision wrote its stop request then and there.
  EXPECT_GE(stop_requests(), at_start + 3);
  session.stop();
}

}  // namespace
}  // namespace fieldguard::app
