// The daemon's ear on a SocketCAN bus, through a socketpair standing in for the CAN_RAW socket: a request from
// the bus is answered on it, a contest moves our address, bus-off silences the node and recovery claims again.

#include "daemon/bus_listener.hpp"

#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <vector>

#include "fieldguard/config/config.hpp"
#include "fieldguard/output/j1939.hpp"

namespace fieldguard::app {
namespace {

namespace j1939 = output::j1939;

struct Bus {
  int ours = -1;
  int theirs = -1;
  Bus() {
    int sv[2];
    if (::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv) == 0) {
      ours = sv[0];
      theirs = sv[1];
    }
  }
  ~Bus() {
    if (theirs >= 0) ::close(theirs);
  }
  void send(std::uint32_t id, std::vector<std::uint8_t> data) const {
    can_frame cf{};
    cf.can_id = id | CAN_EFF_FLAG;
    cf.len = static_cast<std::uint8_t>(data.size());
    std::copy(data.begin(), data.end(), cf.data);
    ASSERT_EQ(::send(theirs, &cf, sizeof cf, 0), static_cast<ssize_t>(sizeof cf));
  }
  void send_error(canid_t what) const {
    can_frame cf{};
    cf.can_id = CAN_ERR_FLAG | what;
    cf.len = CAN_ERR_DLC;
    ASSERT_EQ(::send(theirs, &cf, sizeof cf, 0), static_cast<ssize_t>(sizeof cf));
  }
  // Every frame we wrote, ids only.
  [[nodiscard]] std::vector<std::uint32_t> written() const {
    std::vector<std::uint32_t> ids;
    can_frame cf{};
    while (::recv(theirs, &cf, sizeof cf, MSG_DONTWAIT) == static_cast<ssize_t>(sizeof cf)) {
      ids.push_back(cf.can_id & CAN_EFF_MASK);
    }
    return ids;
  }
};

bool has(const std::vector<std::uint32_t>& ids, std::uint32_t id) {
  return std::find(ids.begin(), ids.end(), id) != ids.end();
}

TEST(BusListener, TheNodeHearsTheBusAndAnswersOnIt) {
  Bus bus;
  ASSERT_GE(bus.ours, 0);
  output::SocketCanSink sink(bus.ours);
  Config cfg;
  CanLink link(cfg.can, sink);
  boost::asio::io_context io;
  BusListener listener(io, sink, link);
  const Stamp now = wall_clock_now();
  link.start(Stamp{now.ns - 1'000'000'000});  // claimed a second ago: the address is ours now
  link.advance(now);
  auto first = bus.written();
  ASSERT_GE(first.size(), 2U);
  EXPECT_EQ(first[0], 0x18EEFF80U);
  EXPECT_TRUE(has(first, 0x18FECA80U)) << "the first DM1";

  // A terminal at 0x26 asks us for our software identification: the answer is a BAM on the bus.
  bus.send(0x18EA8026U, {0xDA, 0xFE, 0x00});
  io.run_for(std::chrono::milliseconds(100));
  EXPECT_TRUE(has(bus.written(), 0x1CECFF80U)) << "TP.CM of the Software Identification";
  EXPECT_EQ(link.counts().received, 1U);
  EXPECT_EQ(link.node()->counters().requests_answered, 1U);

  // A stronger NAME claims 0x80: we move to 0x81 and the socket's filters should follow (a socketpair refuses).
  bus.send(0x18EEFF80U, {0, 0, 0, 0, 0, 0, 0, 0});
  io.run_for(std::chrono::milliseconds(100));
  EXPECT_TRUE(has(bus.written(), 0x18EEFF81U));
  EXPECT_EQ(link.node()->claimer().address(), 0x81);
  EXPECT_FALSE(listener.filter_problem().empty());

  // Bus-off: silent; recovery: the claim again.
  bus.send_error(CAN_ERR_BUSOFF);
  io.run_for(std::chrono::milliseconds(100));
  EXPECT_EQ(link.node()->claimer().state(), j1939::ClaimState::BusOff);
  bus.send(0x18EAFF26U, {0x00, 0xEE, 0x00});  // a request for Address Claimed: not answered while off
  io.run_for(std::chrono::milliseconds(100));
  EXPECT_TRUE(bus.written().empty());
  bus.send_error(CAN_ERR_RESTARTED);
  io.run_for(std::chrono::milliseconds(100));
  EXPECT_TRUE(has(bus.written(), 0x18EEFF81U)) << "claimed again on recovery";
  EXPECT_EQ(link.node()->claimer().state(), j1939::ClaimState::Claiming);
}

}  // namespace
}  // namespace fieldguard::app
