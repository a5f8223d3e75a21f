// CanReader: CAN frames from a socket on the io thread, filtered by id. A socketpair carrying struct can_frame
// stands in for the CAN_RAW socket (the kernel here has no SocketCAN).
#include "fieldguard/io/can_reader.hpp"

#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <sys/socket.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <chrono>
#include <cstdint>
#include <vector>

namespace fieldguard::io {
namespace {

constexpr std::uint32_t kCcvs1FromEngine = 0x18FEF100;  // priority 6, PGN 65265, source address 0x00

void send_frame(int fd, std::uint32_t can_id, std::vector<std::uint8_t> data) {
  can_frame cf{};
  cf.can_id = can_id;
  cf.can_dlc = static_cast<std::uint8_t>(data.size());
  for (std::size_t i = 0; i < data.size(); ++i) cf.data[i] = data[i];
  ASSERT_EQ(::send(fd, &cf, sizeof cf, 0), static_cast<ssize_t>(sizeof cf));
}

struct Got {
  std::uint32_t id;
  std::vector<std::uint8_t> data;
};

TEST(CanReader, HandsOverOnlyExtendedFramesItsFiltersPassAndCountsTheRest) {
  int sv[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
  boost::asio::io_context io;
  std::vector<Got> got;
  // PGN 65265 from any source address: the PGN bits of the 29-bit id, not the priority nor the sender.
  CanReader reader(io, sv[0], {CanFilter{0x00FEF100, 0x00FFFF00}},
                   [&](std::uint32_t id, std::span<const std::uint8_t> d, Stamp t) {
                     EXPECT_GT(t.ns, 0);
                     got.push_back({id, {d.begin(), d.end()}});
                   });
  reader.start();
  send_frame(sv[1], kCcvs1FromEngine | CAN_EFF_FLAG, {0xFF, 0x00, 0x0A, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF});
  send_frame(sv[1], 0x0CFEF117 | CAN_EFF_FLAG, {1, 2, 3});                     // same PGN, other sender
  send_frame(sv[1], 0x18FEF000 | CAN_EFF_FLAG, {0});                           // another PGN
  send_frame(sv[1], 0x123, {0});                                               // standard 11-bit frame
  send_frame(sv[1], kCcvs1FromEngine | CAN_EFF_FLAG | CAN_RTR_FLAG, {});       // remote request
  send_frame(sv[1], CAN_ERR_FLAG | CAN_ERR_BUSOFF, {0, 0, 0, 0, 0, 0, 0, 0});  // error frame
  const std::uint8_t half[5] = {1, 2, 3, 4, 5};
  ASSERT_EQ(::send(sv[1], half, sizeof half, 0), 5);  // not a can_frame
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (reader.stats().frames + reader.stats().not_ours + reader.stats().bad_size < 7 &&
         std::chrono::steady_clock::now() < end) {
    io.run_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(got.size(), 2U);
  EXPECT_EQ(got[0].id, kCcvs1FromEngine);
  EXPECT_EQ(got[0].data, (std::vector<std::uint8_t>{0xFF, 0x00, 0x0A, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}));
  EXPECT_EQ(got[1].id, 0x0CFEF117U);
  EXPECT_EQ(got[1].data.size(), 3U);
  EXPECT_EQ(reader.stats().frames, 2U);
  EXPECT_EQ(reader.stats().not_ours, 4U);
  EXPECT_EQ(reader.stats().bad_size, 1U);
  reader.stop();
  ::close(sv[1]);
}

TEST(CanReader, NoFiltersPassNothing) {
  int sv[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
  boost::asio::io_context io;
  int calls = 0;
  CanReader reader(io, sv[0], {}, [&](std::uint32_t, std::span<const std::uint8_t>, Stamp) { ++calls; });
  reader.start();
  send_frame(sv[1], kCcvs1FromEngine | CAN_EFF_FLAG, {0, 0, 0});
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (reader.stats().not_ours == 0 && std::chrono::steady_clock::now() < end)
    io.run_for(std::chrono::milliseconds(20));
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(reader.stats().not_ours, 1U);
  ::close(sv[1]);
}

TEST(CanReader, OpeningAMissingInterfaceSaysWhatIsWrong) {
  const auto r = CanReader::open_socket("fgnocan0", {CanFilter{0x00FEF100, 0x00FFFF00}});
  ASSERT_FALSE(r.has_value());
  // Without SocketCAN in the kernel (this machine, CI) or without the interface: either is named.
  EXPECT_TRUE(r.error().find("SocketCAN") != std::string::npos || r.error().find("fgnocan0") != std::string::npos)
      << r.error();
  EXPECT_FALSE(CanReader::open_socket("", {}).has_value());
}

}  // namespace
}  // namespace fieldguard::io
