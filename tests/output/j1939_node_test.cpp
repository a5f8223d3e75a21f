// fieldguard as a J1939 node: requests answered (identifications, DM1, DM2, a NACK for what we do not send, nothing
// before the address is ours), DM1 once a second and on change within J1939-73's rate limit, multi-packet DM1 paced
// by BAM, and a real truck's traffic replayed into the node with our address set to one of its ECUs' (an address
// violation: we claim again, once a second, and report it).

#include "fieldguard/output/j1939_node.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fieldguard::output::j1939 {
namespace {

NodeParams params() {
  NodeParams p;
  p.claim.name.identity_number = 77;
  p.claim.name.manufacturer_code = 0x7FE;
  p.claim.name.function = 130;
  p.claim.name.industry_group = kIndustryGroupAgricultural;
  p.claim.name.arbitrary_address_capable = true;
  p.claim.preferred_address = 0x80;
  p.software_id = "fieldguard 9.8.7";
  p.component_id = "fieldguard*FG-1*0042*tractor 7*";
  return p;
}

// A started node that holds 0x80 at t = 0.25 s; `out` cleared.
Node claimed(std::vector<CanFrame>& out, const NodeParams& p = params()) {
  Node n(p);
  n.start(0.0, out);
  n.tick(0.25, out);
  out.clear();
  return n;
}

std::vector<CanFrame> with_pgn(const std::vector<CanFrame>& frames, std::uint32_t pgn) {
  std::vector<CanFrame> r;
  for (const auto& f : frames) {
    if (j1939_fields(f.id).pgn == pgn) r.push_back(f);
  }
  return r;
}

// Every TP.DT of the BAM under way, ticking 50 ms at a time from `t`; returns the message they complete.
std::vector<std::uint8_t> finish_bam(Node& n, const CanFrame& announcement, double t) {
  BamReceiver rx;
  std::vector<CanFrame> out;
  EXPECT_FALSE(rx.feed(announcement, t));
  for (int i = 1; i <= 40; ++i) {
    out.clear();
    n.tick(t + 0.05 * i, out);
    for (const auto& f : out) {
      if (auto m = rx.feed(f, t + 0.05 * i)) return m->data;
    }
  }
  ADD_FAILURE() << "the BAM did not complete";
  return {};
}

TEST(J1939Node, NothingButTheClaimUntilTheAddressIsOurs) {
  Node n(params());
  std::vector<CanFrame> out;
  n.start(0.0, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].id, 0x18EEFF80U);
  out.clear();
  n.receive(request(kPgnSoftwareId, 0x26, 0x80), 0.1, out);
  n.tick(0.2, out);
  EXPECT_TRUE(out.empty()) << "no answer, no DM1 during the 250 ms hold";
  EXPECT_EQ(n.counters().requests_unanswered, 1U);
  n.tick(0.25, out);
  ASSERT_EQ(out.size(), 1U) << "the first DM1 as soon as the address is ours";
  EXPECT_EQ(out[0].id, 0x18FECA80U);
  EXPECT_EQ(out[0].data[0], 0x00) << "lamps off";
  EXPECT_EQ(out[0].data[2], 0x00) << "the no-DTC placeholder";
}

TEST(J1939Node, AnswersIdentificationRequestsByBam) {
  std::vector<CanFrame> out;
  Node n = claimed(out);
  n.receive(request(kPgnSoftwareId, 0x26, 0xFF), 1.0, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].id, 0x1CECFF80U) << "TP.CM from us to global, priority 7";
  const auto soft = finish_bam(n, out[0], 1.0);
  EXPECT_EQ(std::string(soft.begin() + 1, soft.end()), "fieldguard 9.8.7*");
  EXPECT_EQ(soft[0], 1) << "one field";
  out.clear();
  n.receive(request(kPgnComponentId, 0x26, 0x80), 3.0, out);
  ASSERT_FALSE(out.empty());
  const auto comp = finish_bam(n, with_pgn(out, kPgnTpCm).at(0), 3.0);
  EXPECT_EQ(std::string(comp.begin(), comp.end()), "fieldguard*FG-1*0042*tractor 7*");
  EXPECT_EQ(n.counters().requests_answered, 2U);
  EXPECT_EQ(n.counters().bam_sent, 2U);
}

TEST(J1939Node, NacksAnUnknownRequestToUsAloneOnly) {
  std::vector<CanFrame> out;
  Node n = claimed(out);
  n.receive(request(0xFEE5, 0x26, 0xFF), 1.0, out);  // engine hours, to global: not ours to send, no answer
  EXPECT_TRUE(out.empty());
  n.receive(request(0xFEE5, 0x26, 0x81), 1.0, out);  // to another node
  EXPECT_TRUE(out.empty());
  n.receive(request(0xFEE5, 0x26, 0x80), 1.0, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0], acknowledgement(AckControl::Nack, 0xFEE5, 0x26, 0x80));
  EXPECT_EQ(out[0].id, 0x18E8FF80U);
  EXPECT_EQ(n.counters().nacks_sent, 1U);
  out.clear();
  NodeParams anonymous = params();
  anonymous.component_id.clear();
  std::vector<CanFrame> out2;
  Node plain = claimed(out2, anonymous);
  plain.receive(request(kPgnComponentId, 0x26, 0x80), 1.0, out2);
  ASSERT_EQ(out2.size(), 1U) << "no component id configured: not something we send";
  EXPECT_EQ(out2[0], acknowledgement(AckControl::Nack, kPgnComponentId, 0x26, 0x80));
  CanFrame bad = request(0xFEE5, 0x26, 0x80);
  bad.len = 2;  // not a request
  n.receive(bad, 1.1, out);
  EXPECT_TRUE(out.empty());
}

TEST(J1939Node, Dm1EverySecondAndAtOnceOnChangeRateLimited) {
  std::vector<CanFrame> out;
  Node n = claimed(out);
  auto dm1_at = [&](double t) {
    out.clear();
    n.tick(t, out);
    return with_pgn(out, kPgnDm1).size() + with_pgn(out, kPgnTpCm).size();
  };
  EXPECT_EQ(dm1_at(0.3), 0U);
  EXPECT_EQ(dm1_at(1.25), 1U) << "a second after the first";
  EXPECT_EQ(dm1_at(1.5), 0U);
  DiagnosticMessage fault;
  fault.lamps.amber_warning = Lamp::On;
  fault.dtcs.push_back(Dtc{520194, 9, 1});
  out.clear();
  n.set_dm1(fault, 1.6, out);
  ASSERT_EQ(out.size(), 1U) << "a change goes out at once";
  EXPECT_EQ(out[0].data[0], 0x04) << "amber on";
  EXPECT_EQ(out[0].data[2], 0x02);  // SPN 520194 = 0x7F002: bits 0-7
  EXPECT_EQ(out[0].data[4], (0x7U << 5U) | 9U) << "SPN bits 16-18 with FMI 9";
  out.clear();
  n.set_dm1(DiagnosticMessage{}, 2.0, out);  // cleared 0.4 s later: held to a second after the last change
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(dm1_at(2.5), 0U);
  ASSERT_EQ(dm1_at(2.6), 1U);
  EXPECT_EQ(out.at(0).data[0], 0x00) << "the clearing, lamps off";
  EXPECT_EQ(dm1_at(3.0), 0U);
  EXPECT_EQ(dm1_at(3.6), 1U) << "and the period goes on from there";
  EXPECT_EQ(n.counters().dm1_sent, 5U) << "0.25 s (the first), 1.25, 1.6, 2.6, 3.6";
}

TEST(J1939Node, SeveralDtcsGoAsBamPacedFiftyMsApart) {
  std::vector<CanFrame> out;
  Node n = claimed(out);
  DiagnosticMessage m;
  m.lamps.amber_warning = Lamp::On;
  m.lamps.red_stop = Lamp::On;
  m.dtcs = {Dtc{520192, 9, 1}, Dtc{520193, 9, 1}, Dtc{520200, 9, 3}};
  n.set_dm1(m, 0.5, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].id, 0x1CECFF80U);
  out.clear();
  n.tick(0.54, out);
  EXPECT_TRUE(out.empty()) << "no packet before 50 ms";
  const auto data = finish_bam(n, CanFrame{0x1CECFF80U, 8, {0x20, 14, 0, 2, 0xFF, 0xCA, 0xFE, 0x00}}, 0.5);
  const auto back = decode_diagnostic(data);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->dtcs, m.dtcs);
  EXPECT_EQ(back->lamps, m.lamps);
}

TEST(J1939Node, Dm1AndDm2OnRequest) {
  std::vector<CanFrame> out;
  Node n = claimed(out);
  DiagnosticMessage old;
  old.dtcs.push_back(Dtc{520195, 2, 4});
  n.set_dm2(old);
  n.receive(request(kPgnDm2, 0x26, 0x80), 0.5, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].id, 0x18FECB80U);
  EXPECT_EQ(decode_diagnostic(std::span<const std::uint8_t>(out[0].data.data(), 8))->dtcs, old.dtcs);
  out.clear();
  n.receive(request(kPgnDm1, 0x26, 0xFF), 0.6, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].id, 0x18FECA80U);
  EXPECT_EQ(n.counters().dm2_sent, 1U);
}

TEST(J1939Node, AMovedAddressCarriesEveryLaterFrame) {
  std::vector<CanFrame> out;
  Node n = claimed(out);
  n.receive(address_claimed(n.claimer().name() - 1, 0x80), 1.0, out);  // a stronger NAME takes 0x80
  ASSERT_EQ(n.claimer().address(), 0x81);
  n.tick(1.3, out);
  out.clear();
  n.receive(request(kPgnDm1, 0x26, 0x81), 1.4, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].id & 0xFFU, 0x81U);
}

TEST(J1939Node, CannotClaimSilencesEverythingButTheClaimer) {
  NodeParams p = params();
  p.claim.name.arbitrary_address_capable = false;
  std::vector<CanFrame> out;
  Node n = claimed(out, p);
  n.receive(address_claimed(n.claimer().name() - 1, 0x80), 1.0, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0], cannot_claim(n.claimer().name()));
  out.clear();
  n.set_dm1(DiagnosticMessage{{Lamp::Off, Lamp::Off, Lamp::On, Lamp::Off}, {Dtc{520201, 31, 1}}}, 1.1, out);
  n.receive(request(kPgnSoftwareId, 0x26, 0xFF), 1.2, out);
  for (double t = 1.2; t < 5.0; t += 0.1) n.tick(t, out);
  EXPECT_TRUE(out.empty());
}

TEST(J1939Node, BusOffDropsTheBamUnderWay) {
  std::vector<CanFrame> out;
  Node n = claimed(out);
  n.receive(request(kPgnSoftwareId, 0x26, 0xFF), 1.0, out);
  ASSERT_EQ(out.size(), 1U);
  n.bus_off();
  out.clear();
  n.tick(1.1, out);
  EXPECT_TRUE(out.empty());
  n.bus_recovered(2.0, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(out[0].id, 0x18EEFF80U) << "the claim again, then 250 ms";
  out.clear();
  n.tick(2.1, out);
  EXPECT_TRUE(out.empty()) << "no stale TP.DT of the abandoned BAM";
}

// The real truck log (CSS Electronics CANedge, tests/data/can): its engine ECU transmits from address 0x00, at
// 100 Hz. A node set to claim 0x00 sees every one of those frames as an address violation; it claims again once
// a second, not once a frame, and reports the conflict. (The log has no Address Claimed of its own: the contest
// by NAME is the address-claim tests'.)
TEST(J1939Node, RealTruckTrafficOnOurAddressIsAViolation) {
  std::ifstream in(std::string(FIELDGUARD_TEST_DATA) + "/can/j1939_truck_idle_first300.log");
  ASSERT_TRUE(in) << "tests/data/can/j1939_truck_idle_first300.log";
  NodeParams p = params();
  p.claim.preferred_address = 0x00;
  Node n(p);
  std::vector<CanFrame> out;
  std::string line;
  std::size_t frames = 0;
  std::size_t from_zero = 0;
  std::size_t claims = 0;
  double first = -1.0;
  double last = 0.0;
  while (std::getline(in, line)) {
    double t = 0.0;
    char iface[16] = {};
    char body[64] = {};
    if (std::sscanf(line.c_str(), "(%lf) %15s %63s", &t, iface, body) != 3) continue;
    const std::string b(body);
    const auto hash = b.find('#');
    if (hash != 8) continue;  // 29-bit frames only
    CanFrame f;
    f.id = static_cast<std::uint32_t>(std::stoul(b.substr(0, 8), nullptr, 16));
    const std::string hex = b.substr(9);
    f.len = static_cast<std::uint8_t>(hex.size() / 2);
    for (std::size_t i = 0; i < f.len && i < 8; ++i) {
      f.data[i] = static_cast<std::uint8_t>(std::stoul(hex.substr(2 * i, 2), nullptr, 16));
    }
    if (first < 0) {
      first = t;
      n.start(t, out);
    }
    last = t;
    out.clear();
    n.tick(t, out);
    n.receive(f, t, out);
    ++frames;
    if ((f.id & 0xFFU) == 0) ++from_zero;
    claims += with_pgn(out, kPgnAddressClaimed).size();
  }
  ASSERT_GT(frames, 250U);
  const double span = last - first;
  EXPECT_GT(from_zero, frames / 2) << "the engine's frames dominate the log";
  EXPECT_TRUE(n.claimer().may_transmit()) << "no NAME contested the address: it stays ours";
  EXPECT_GT(n.counters().address_violations, from_zero / 2);
  EXPECT_TRUE(n.address_conflict(last));
  EXPECT_GE(claims, 1U);
  EXPECT_LE(static_cast<double>(claims), span + 1.0) << "claimed again once a second at most";
}

}  // namespace
}  // namespace fieldguard::output::j1939
