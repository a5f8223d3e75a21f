// The link between the output stage and the bus: our messages only once the address is ours and from the address we
// hold, the stop request to the controller found by its NAME, the alive counters and the stop request's cycle going
// on across a reload, and no address at all as the safety monitor's STOP.

#include "fieldguard/engine/can_link.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "app/recording_sink.hpp"
#include "daemon/run_stage.hpp"
#include "fieldguard/output/can_layout.hpp"
#include "fieldguard/output/j1939.hpp"

namespace fieldguard::app {
namespace {

namespace j1939 = output::j1939;
constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kT0 = 1'700'000'000'000 * kMs;

using testing::RecordingSink;
using testing::Sent;

std::uint32_t pgn_of(const output::CanFrame& f) { return output::j1939_fields(f.id).pgn; }

std::vector<Sent> with_pgn(const std::vector<Sent>& sent, std::uint32_t pgn) {
  std::vector<Sent> r;
  std::copy_if(sent.begin(), sent.end(), std::back_inserter(r), [&](const Sent& s) { return pgn_of(s.frame) == pgn; });
  return r;
}

constexpr std::uint32_t kStopPgn = 0xEF00;
constexpr std::uint32_t kHeartbeatPgn = 0xFF12;

std::uint64_t alive(const output::CanFrame& f) {
  return output::get_raw(f.data,
                         output::layout(output::MessageId::StopRequest).signals[output::stop_sig::AliveCounter]);
}

// A heartbeat cycle every 100 ms from kT0 to `until_ms`.
void run_cycles(CanLink& link, std::int64_t from_ms, std::int64_t until_ms) {
  for (std::int64_t ms = from_ms; ms <= until_ms; ms += 100) link.schedule().tick(Stamp{kT0 + ms * kMs}, {});
}

TEST(CanLink, NothingOfOursBeforeTheClaimHoldsThenFromTheClaimedAddress) {
  Config cfg;
  RecordingSink bus;
  CanLink link(cfg.can, bus);
  link.start(Stamp{kT0});
  run_cycles(link, 0, 500);
  ASSERT_FALSE(bus.sent.empty());
  EXPECT_EQ(bus.sent.front().frame.id, 0x18EEFF80U) << "Address Claimed first";
  EXPECT_EQ(bus.sent.front().t.ns, kT0);
  const auto beats = with_pgn(bus.sent, kHeartbeatPgn);
  ASSERT_FALSE(beats.empty());
  EXPECT_EQ(beats.front().t.ns, kT0 + 300 * kMs) << "the cycles at 0, 100 and 200 ms fell in the 250 ms hold";
  EXPECT_EQ(link.counts().withheld, 6U) << "a heartbeat and a stop request per withheld cycle";
  for (const auto& s : bus.sent) EXPECT_EQ(s.frame.id & 0xFFU, 0x80U);
  for (std::size_t i = 1; i < bus.sent.size(); ++i) EXPECT_GE(bus.sent[i].t.ns, bus.sent[i - 1].t.ns);
  EXPECT_EQ(with_pgn(bus.sent, j1939::kPgnDm1).size(), 1U) << "the first DM1 as the address became ours";
}

TEST(CanLink, AfterALostContestOurMessagesCarryTheNewAddress) {
  Config cfg;
  RecordingSink bus;
  CanLink link(cfg.can, bus);
  link.start(Stamp{kT0});
  run_cycles(link, 0, 300);
  link.receive(j1939::address_claimed(cfg.can.j1939.name.value() - 1, 0x80), Stamp{kT0 + 350 * kMs});
  EXPECT_EQ(bus.sent.back().frame.id, 0x18EEFF81U) << "moved to the next free address";
  const std::size_t before = bus.sent.size();
  run_cycles(link, 400, 800);
  const std::vector<Sent> later(bus.sent.begin() + static_cast<std::ptrdiff_t>(before), bus.sent.end());
  const auto stops = with_pgn(later, kStopPgn);
  ASSERT_FALSE(stops.empty());
  EXPECT_GE(stops.front().t.ns, kT0 + 600 * kMs) << "silent for the new claim's 250 ms";
  for (const auto& s : later) EXPECT_EQ(s.frame.id & 0xFFU, 0x81U) << std::hex << s.frame.id;
  EXPECT_FALSE(link.no_address());
}

TEST(CanLink, TheStopRequestGoesToTheControllerFoundByItsName) {
  Config cfg;
  const std::uint64_t controller = 0xA00C8100AB3C0042ULL;
  cfg.can.j1939.controller_name = controller;
  RecordingSink bus;
  CanLink link(cfg.can, bus);
  link.start(Stamp{kT0});
  run_cycles(link, 0, 300);
  EXPECT_EQ((with_pgn(bus.sent, kStopPgn).back().frame.id >> 8U) & 0xFFU, 0x26U) << "configured until heard";
  link.receive(j1939::address_claimed(controller, 0x31), Stamp{kT0 + 350 * kMs});
  run_cycles(link, 400, 400);
  EXPECT_EQ((with_pgn(bus.sent, kStopPgn).back().frame.id >> 8U) & 0xFFU, 0x31U);
}

TEST(CanLink, AReloadKeepsTheAliveCountersTheCycleAndTheAddress) {
  Config cfg;
  RecordingSink bus;
  CanLink link(cfg.can, bus);
  link.start(Stamp{kT0});
  run_cycles(link, 0, 1000);
  const auto stops = with_pgn(bus.sent, kStopPgn);
  const std::uint64_t last_alive = alive(stops.back().frame);
  const std::int64_t last_t = stops.back().t.ns;
  Config reloaded = cfg;
  reloaded.can.params.max_obstacles = 4;
  link.reconfigure(reloaded.can);
  link.start(Stamp{kT0 + 1050 * kMs});  // a new session starts the link again: nothing to claim
  const std::size_t before = bus.sent.size();
  run_cycles(link, 1050, 1250);  // the new session's clock is off the old cycle: the cycle stays
  const std::vector<Sent> after(bus.sent.begin() + static_cast<std::ptrdiff_t>(before), bus.sent.end());
  EXPECT_TRUE(with_pgn(after, j1939::kPgnAddressClaimed).empty()) << "the same NAME: no new claim";
  const auto next = with_pgn(after, kStopPgn);
  ASSERT_FALSE(next.empty());
  EXPECT_EQ(alive(next.front().frame), (last_alive + 1) % 16) << "the alive counter goes on";
  EXPECT_EQ(next.front().t.ns, last_t + 100 * kMs) << "the stop request keeps its cycle";

  // Another NAME is another node: it claims again.
  Config renamed = cfg;
  renamed.can.j1939.name.identity_number = 99;
  link.reconfigure(renamed.can);
  link.start(Stamp{kT0 + 1300 * kMs});
  EXPECT_EQ(pgn_of(bus.sent.back().frame), j1939::kPgnAddressClaimed);
}

TEST(CanLink, WithoutTheClaimEverythingGoesOutAtOnceFromTheConfiguredAddress) {
  Config cfg;
  cfg.can.j1939.address_claim = false;
  RecordingSink bus;
  CanLink link(cfg.can, bus);
  link.start(Stamp{kT0});
  run_cycles(link, 0, 0);
  ASSERT_EQ(bus.sent.size(), 2U);
  EXPECT_EQ(pgn_of(bus.sent[0].frame), kHeartbeatPgn);
  EXPECT_EQ(link.node(), nullptr);
}

TEST(CanLink, NoAddressLeftIsTheSafetyMonitorsStop) {
  Config cfg;
  cfg.can.j1939.name.arbitrary_address_capable = false;
  RecordingSink bus;
  CanLink link(cfg.can, bus);
  LiveStage stage(cfg, link);
  stage.tick(Stamp{kT0}, 0);
  stage.tick(Stamp{kT0 + 300 * kMs}, 0);
  link.receive(j1939::address_claimed(cfg.can.j1939.name.value() - 1, 0x80), Stamp{kT0 + 350 * kMs});
  EXPECT_EQ(bus.sent.back().frame, j1939::cannot_claim(cfg.can.j1939.name.value()));
  EXPECT_TRUE(link.no_address());
  const std::size_t before = bus.sent.size();
  const auto& d = stage.tick(Stamp{kT0 + 400 * kMs}, 0);
  EXPECT_TRUE(d.stop);
  EXPECT_EQ(d.reason, output::safety::Reason::NoAddress);
  stage.tick(Stamp{kT0 + 900 * kMs}, 0);
  EXPECT_EQ(bus.sent.size(), before) << "nothing more on the bus";
  EXPECT_GT(link.counts().withheld, 0U);
}

}  // namespace
}  // namespace fieldguard::app
