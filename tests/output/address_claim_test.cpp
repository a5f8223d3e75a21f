// The J1939-81 address claim of one node, case by case: the claim and its 250 ms, a contest won and lost (moving
// to another address, or Cannot Claim), no address left, requests for Address Claimed in every state, bus-off and
// recovery, and finding another node's address by its NAME.

#include "fieldguard/output/address_claim.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace fieldguard::output::j1939 {
namespace {

Name our_name(bool arbitrary) {
  Name n;
  n.identity_number = 4242;
  n.manufacturer_code = 0x7FE;
  n.function = 130;
  n.vehicle_system = 1;
  n.industry_group = kIndustryGroupAgricultural;
  n.arbitrary_address_capable = arbitrary;
  return n;
}

ClaimParams params(bool arbitrary) {
  ClaimParams p;
  p.name = our_name(arbitrary);
  p.preferred_address = 0x80;
  return p;
}

// Another NAME one below or above ours: the lower wins.
std::uint64_t stronger(const AddressClaimer& c) { return c.name() - 1; }
std::uint64_t weaker(const AddressClaimer& c) { return c.name() + 1; }

bool is_claim(const CanFrame& f, std::uint64_t name, std::uint8_t address) {
  return f == address_claimed(name, address);
}

TEST(AddressClaim, ClaimsAtStartAndMayTransmitAfter250Ms) {
  AddressClaimer c(params(true));
  std::vector<CanFrame> out;
  c.tick(0.0, out);
  EXPECT_EQ(c.state(), ClaimState::NotStarted);
  EXPECT_FALSE(c.address());
  c.start(1.0, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_TRUE(is_claim(out[0], c.name(), 0x80));
  EXPECT_EQ(out[0].id, 0x18EEFF80U);
  EXPECT_EQ(c.state(), ClaimState::Claiming);
  EXPECT_FALSE(c.may_transmit());
  EXPECT_EQ(c.address(), 0x80);
  EXPECT_NEAR(*c.next_due(1.1), 0.15, 1e-9);
  c.tick(1.249, out);
  EXPECT_FALSE(c.may_transmit());
  c.tick(1.25, out);
  EXPECT_TRUE(c.may_transmit());
  EXPECT_EQ(c.state(), ClaimState::Claimed);
  EXPECT_EQ(out.size(), 1U);  // nothing more sent
  EXPECT_FALSE(c.next_due(2.0));
  c.start(3.0, out);  // a second start changes nothing
  EXPECT_EQ(out.size(), 1U);
}

TEST(AddressClaim, AContestWonIsAnsweredWithOurClaimAgain) {
  AddressClaimer c(params(false));
  std::vector<CanFrame> out;
  c.start(0.0, out);
  c.tick(0.3, out);
  out.clear();
  c.receive(address_claimed(weaker(c), 0x80), 0.4, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_TRUE(is_claim(out[0], c.name(), 0x80));
  EXPECT_TRUE(c.may_transmit());
  EXPECT_EQ(c.counters().contests_won, 1U);
  EXPECT_FALSE(c.address_of(weaker(c))) << "the loser does not hold our address";
}

TEST(AddressClaim, AContestLostMovesAnArbitraryCapableNodeToAFreeAddress) {
  AddressClaimer c(params(true));
  std::vector<CanFrame> out;
  c.start(0.0, out);
  c.tick(0.3, out);
  // 0x81 is taken by someone else already; 0x80 is then contested by a stronger NAME.
  c.receive(address_claimed(0x1234, 0x81), 0.35, out);
  out.clear();
  c.receive(address_claimed(stronger(c), 0x80), 0.4, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_TRUE(is_claim(out[0], c.name(), 0x82));
  EXPECT_EQ(c.state(), ClaimState::Claiming);
  EXPECT_FALSE(c.may_transmit()) << "a new claim waits its 250 ms again";
  c.tick(0.65, out);
  EXPECT_TRUE(c.may_transmit());
  EXPECT_EQ(c.address(), 0x82);
  EXPECT_EQ(c.counters().contests_lost, 1U);
  EXPECT_EQ(c.address_of(stronger(c)), 0x80);
  EXPECT_EQ(c.address_of(0x1234), 0x81);
}

TEST(AddressClaim, AContestLostByAFixedAddressNodeIsCannotClaimAndSilence) {
  AddressClaimer c(params(false));
  std::vector<CanFrame> out;
  c.start(0.0, out);
  out.clear();
  c.receive(address_claimed(stronger(c), 0x80), 0.1, out);  // during the 250 ms
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0], cannot_claim(c.name()));
  EXPECT_EQ(out[0].id, 0x18EEFFFEU);
  EXPECT_EQ(c.state(), ClaimState::CannotClaim);
  EXPECT_FALSE(c.address());
  c.tick(1.0, out);
  EXPECT_FALSE(c.may_transmit());
  EXPECT_EQ(out.size(), 1U);
}

TEST(AddressClaim, NoFreeAddressLeftIsCannotClaim) {
  ClaimParams p = params(true);
  p.first_arbitrary = 0x80;
  p.last_arbitrary = 0x82;
  AddressClaimer c(p);
  std::vector<CanFrame> out;
  c.start(0.0, out);
  c.receive(address_claimed(0x10, 0x81), 0.05, out);
  c.receive(address_claimed(0x11, 0x82), 0.06, out);
  out.clear();
  c.receive(address_claimed(stronger(c), 0x80), 0.1, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0], cannot_claim(c.name()));
  EXPECT_EQ(c.state(), ClaimState::CannotClaim);
}

TEST(AddressClaim, RequestsForAddressClaimedInEveryState) {
  AddressClaimer c(params(false));
  std::vector<CanFrame> out;
  const CanFrame global = request(kPgnAddressClaimed, 0x26, kGlobalAddress);
  c.receive(global, 0.0, out);
  EXPECT_TRUE(out.empty()) << "no answer before the claim";
  c.start(0.0, out);
  out.clear();
  c.receive(global, 0.1, out);  // while claiming
  ASSERT_EQ(out.size(), 1U);
  EXPECT_TRUE(is_claim(out[0], c.name(), 0x80));
  c.tick(0.3, out);
  out.clear();
  c.receive(request(kPgnAddressClaimed, 0x26, 0x80), 0.4, out);  // to us
  ASSERT_EQ(out.size(), 1U);
  c.receive(request(kPgnAddressClaimed, 0x26, 0x81), 0.5, out);  // to someone else
  c.receive(request(kPgnDm1, 0x26, kGlobalAddress), 0.5, out);   // another PGN: not ours to answer here
  EXPECT_EQ(out.size(), 1U);
  EXPECT_EQ(c.counters().requests_answered, 2U);

  // Without an address, Cannot Claim 0..153 ms after the request (pseudo-random), once.
  c.receive(address_claimed(stronger(c), 0x80), 1.0, out);
  EXPECT_EQ(c.state(), ClaimState::CannotClaim);
  out.clear();
  c.receive(global, 2.0, out);
  EXPECT_TRUE(out.empty());
  const auto due = c.next_due(2.0);
  ASSERT_TRUE(due.has_value());
  EXPECT_GE(*due, 0.0);
  EXPECT_LE(*due, 0.153);
  c.tick(2.0 + *due, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0], cannot_claim(c.name()));
  c.tick(3.0, out);
  EXPECT_EQ(out.size(), 1U);
}

TEST(AddressClaim, BusOffSilencesAndRecoveryClaimsAgain) {
  AddressClaimer c(params(true));
  std::vector<CanFrame> out;
  c.start(0.0, out);
  c.tick(0.3, out);
  c.bus_off();
  EXPECT_EQ(c.state(), ClaimState::BusOff);
  EXPECT_FALSE(c.may_transmit());
  out.clear();
  c.receive(request(kPgnAddressClaimed, 0x26, kGlobalAddress), 0.5, out);
  EXPECT_TRUE(out.empty()) << "nothing goes out while off the bus";
  c.bus_recovered(1.0, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_TRUE(is_claim(out[0], c.name(), 0x80));
  EXPECT_EQ(c.state(), ClaimState::Claiming);
  c.tick(1.25, out);
  EXPECT_TRUE(c.may_transmit());
  c.bus_recovered(2.0, out);  // not off: nothing
  EXPECT_EQ(out.size(), 1U);
}

TEST(AddressClaim, AnotherNodeIsFoundByItsNameWhereverItMoves) {
  AddressClaimer c(params(true));
  std::vector<CanFrame> out;
  const std::uint64_t controller = 0xA000000000001234ULL;
  EXPECT_FALSE(c.address_of(controller));
  c.receive(address_claimed(controller, 0x26), 0.0, out);
  EXPECT_EQ(c.address_of(controller), 0x26);
  c.receive(address_claimed(controller, 0x90), 1.0, out);
  EXPECT_EQ(c.address_of(controller), 0x90);
  c.receive(address_claimed(0x5, 0x90), 2.0, out);  // someone else took it
  EXPECT_FALSE(c.address_of(controller));
  c.receive(cannot_claim(controller), 3.0, out);
  EXPECT_FALSE(c.address_of(controller));
  EXPECT_TRUE(out.empty());
}

TEST(AddressClaim, InvalidParametersAreRefused) {
  ClaimParams p = params(true);
  p.preferred_address = 0xFE;
  EXPECT_THROW(AddressClaimer{p}, std::invalid_argument);
  p = params(true);
  p.name.identity_number = 1U << 21U;
  EXPECT_THROW(AddressClaimer{p}, std::invalid_argument);
  p = params(true);
  p.first_arbitrary = 200;
  p.last_arbitrary = 100;
  EXPECT_EQ(p.validate().size(), 1U);
}

}  // namespace
}  // namespace fieldguard::output::j1939
