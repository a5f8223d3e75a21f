// J1939 on the wire: the NAME against frames printed in vendors' manuals, DM1 and the broadcast transport against
// a real truck's DM1 (tests/data/can/j1939_truck_idle_first300.log, see tests/data/PROVENANCE.txt), and what the
// decoders do with bad input.

#include "fieldguard/output/j1939.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace fieldguard::output::j1939 {
namespace {

// "(1635188455.539950) can0 1CECFF00#20120003FFCAFE00" -> time and frame; nullopt for 11-bit ids.
struct LoggedFrame {
  double time_s;
  CanFrame frame;
};
std::optional<LoggedFrame> parse(const std::string& line) {
  const auto open = line.find('(');
  const auto close = line.find(')');
  const auto hash = line.find('#');
  if (open == std::string::npos || close == std::string::npos || hash == std::string::npos) return std::nullopt;
  const auto id_at = line.rfind(' ', hash) + 1;
  if (hash - id_at != 8) return std::nullopt;
  LoggedFrame f{std::stod(line.substr(open + 1, close - open - 1)), {}};
  f.frame.id = static_cast<std::uint32_t>(std::stoul(line.substr(id_at, 8), nullptr, 16));
  const std::string hex = line.substr(hash + 1);
  f.frame.len = static_cast<std::uint8_t>(hex.size() / 2);
  for (std::size_t i = 0; i < f.frame.len; ++i) {
    f.frame.data[i] = static_cast<std::uint8_t>(std::stoul(hex.substr(2 * i, 2), nullptr, 16));
  }
  return f;
}

std::vector<LoggedFrame> truck_log() {
  std::ifstream in(std::string(FIELDGUARD_TEST_DATA) + "/can/j1939_truck_idle_first300.log");
  std::vector<LoggedFrame> out;
  std::string line;
  while (std::getline(in, line)) {
    if (auto f = parse(line)) out.push_back(*f);
  }
  return out;
}

// Blink Marine's PKP-2200-SI manual prints its Address Claimed as 18EEFF21 with data 3F 42 6F 1A 00 82 3C C0; the
// fields are the J1939-81 layout read back (identity 999999, industry group 4 marine, arbitrary address capable).
TEST(J1939Name, AVendorsClaimReadsBackToItsFields) {
  const std::array<std::uint8_t, 8> data{0x3F, 0x42, 0x6F, 0x1A, 0x00, 0x82, 0x3C, 0xC0};
  const std::uint64_t v = name_from_bytes(data);
  EXPECT_EQ(v, 0xC03C82001A6F423FULL);
  const Name n = Name::from_value(v);
  EXPECT_EQ(n.identity_number, 999999U);
  EXPECT_EQ(n.manufacturer_code, 211U);
  EXPECT_EQ(n.ecu_instance, 0U);
  EXPECT_EQ(n.function_instance, 0U);
  EXPECT_EQ(n.function, 130U);
  EXPECT_EQ(n.vehicle_system, 30U);
  EXPECT_EQ(n.vehicle_system_instance, 0U);
  EXPECT_EQ(n.industry_group, 4U);
  EXPECT_TRUE(n.arbitrary_address_capable);
  EXPECT_EQ(n.value(), v);
  EXPECT_EQ(name_bytes(v), data);
  const CanFrame f = address_claimed(v, 0x21);
  EXPECT_EQ(f.id, 0x18EEFF21U);
  EXPECT_EQ(f.len, 8U);
  EXPECT_EQ(f.data, data);
  EXPECT_EQ(cannot_claim(v).id, 0x18EEFFFEU);
}

TEST(J1939Name, EveryFieldAtItsBits) {
  Name n;
  n.identity_number = 0x1FFFFF;
  EXPECT_EQ(n.value(), 0x1FFFFFULL);
  n = Name{};
  n.manufacturer_code = 0x7FF;
  EXPECT_EQ(n.value(), 0x7FFULL << 21U);
  n = Name{};
  n.ecu_instance = 7;
  n.function_instance = 31;
  EXPECT_EQ(n.value(), 0xFFULL << 32U);
  n = Name{};
  n.function = 0xFF;
  n.vehicle_system = 0x7F;
  EXPECT_EQ(n.value(), 0xFEFFULL << 40U);  // bit 48 reserved, left 0
  n = Name{};
  n.vehicle_system_instance = 15;
  n.industry_group = kIndustryGroupAgricultural;
  n.arbitrary_address_capable = true;
  EXPECT_EQ(n.value(), 0xAFULL << 56U);
  EXPECT_TRUE(n.validate().empty());
  n.identity_number = 1U << 21U;
  n.industry_group = 8;
  const auto problems = n.validate();
  ASSERT_EQ(problems.size(), 2U);
  EXPECT_NE(problems[0].find("identity_number"), std::string::npos);
  EXPECT_NE(problems[1].find("industry_group"), std::string::npos);
}

// Akron Brass's manual asks every node for its claim with "18EAFFFE [3] 00 EE 00".
TEST(J1939Request, ForAddressClaimedAsManualsPrintIt) {
  const CanFrame f = request(kPgnAddressClaimed, kNullAddress, kGlobalAddress);
  EXPECT_EQ(f.id, 0x18EAFFFEU);
  ASSERT_EQ(f.len, 3U);
  EXPECT_EQ(f.data[0], 0x00);
  EXPECT_EQ(f.data[1], 0xEE);
  EXPECT_EQ(f.data[2], 0x00);
  EXPECT_EQ(requested_pgn(std::span<const std::uint8_t>(f.data.data(), 3)), kPgnAddressClaimed);
  const std::uint8_t too_long[] = {0, 0xEE, 0, 0};
  EXPECT_FALSE(requested_pgn(too_long));
  const std::uint8_t too_big[] = {0, 0, 0x04};  // PGN 0x40000: more than 18 bits
  EXPECT_FALSE(requested_pgn(too_big));
  // A NACK to a request for DM2 from 0x26, sent by 0x80 to global.
  const CanFrame nack = acknowledgement(AckControl::Nack, kPgnDm2, 0x26, 0x80);
  EXPECT_EQ(nack.id, 0x18E8FF80U);
  const std::array<std::uint8_t, 8> expect{0x01, 0xFF, 0xFF, 0xFF, 0x26, 0xCB, 0xFE, 0x00};
  EXPECT_EQ(nack.data, expect);
}

// The truck's engine sends its DM1 (four DTCs, 18 bytes) by BAM once a second (lines 178-252 of the slice):
// reassembled and decoded.
TEST(J1939Dm1, ARealTrucksDm1ThroughTheTransportProtocol) {
  BamReceiver rx;
  std::vector<BamReceiver::Message> done;
  for (const LoggedFrame& f : truck_log()) {
    if (auto m = rx.feed(f.frame, f.time_s)) done.push_back(std::move(*m));
  }
  EXPECT_EQ(rx.counters().dropped_sequence, 0U);
  EXPECT_EQ(rx.counters().dropped_timeout, 0U);
  EXPECT_EQ(rx.counters().bad_announcements, 0U);
  std::size_t dm1 = 0;
  for (const auto& m : done) {
    EXPECT_EQ(m.source, 0x00);
    if (m.pgn != kPgnDm1) continue;
    ++dm1;
    ASSERT_EQ(m.data.size(), 18U);
    const auto d = decode_diagnostic(m.data);
    ASSERT_TRUE(d.has_value());
    EXPECT_EQ(d->lamps.malfunction, Lamp::On);
    EXPECT_EQ(d->lamps.red_stop, Lamp::Off);
    EXPECT_EQ(d->lamps.amber_warning, Lamp::Off);
    EXPECT_EQ(d->lamps.protect, Lamp::NotAvailable);
    const std::vector<Dtc> expect{{980, 9, 126}, {3216, 20, 2}, {609, 9, 1}, {609, 12, 3}};
    EXPECT_EQ(d->dtcs, expect);
    // Encoded again, the same bytes (a DM1 with four DTCs is exactly 18 bytes: no padding).
    EXPECT_EQ(encode_diagnostic(*d), m.data);
  }
  EXPECT_EQ(dm1, 1U);
  EXPECT_EQ(done.size(), 1U);
}

TEST(J1939Dm1, OneDtcFitsAFrameAndNoneIsTheZeroPlaceholder) {
  DiagnosticMessage m;
  m.lamps.amber_warning = Lamp::On;
  m.dtcs.push_back({0x7FF00, 31, 1});
  const auto one = encode_diagnostic(m);
  const std::vector<std::uint8_t> expect_one{0x04, 0xFF, 0x00, 0xFF, 0xFF, 0x01, 0xFF, 0xFF};
  EXPECT_EQ(one, expect_one);
  const auto back = decode_diagnostic(one);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->dtcs, m.dtcs);
  EXPECT_EQ(back->lamps, m.lamps);
  const auto none = encode_diagnostic(DiagnosticMessage{});
  const std::vector<std::uint8_t> expect_none{0x00, 0xFF, 0x00, 0x00, 0x00, 0x00, 0xFF, 0xFF};
  EXPECT_EQ(none, expect_none);
  EXPECT_TRUE(decode_diagnostic(none)->dtcs.empty());
  m.dtcs.push_back({0x80000, 0, 0});  // 20 bits
  EXPECT_THROW((void)encode_diagnostic(m), std::invalid_argument);
}

TEST(J1939Dm1, BadDataIsAnErrorNotAGuess) {
  const std::uint8_t short5[] = {0, 0xFF, 1, 2, 3};
  EXPECT_EQ(decode_diagnostic(short5).error(), DiagnosticError::TooShort);
  const std::uint8_t partial[] = {0, 0xFF, 1, 2, 3, 4, 5, 6, 7};  // a DTC and three bytes that are not padding
  EXPECT_EQ(decode_diagnostic(partial).error(), DiagnosticError::Truncated);
  // More than BAM carries cannot have come off a bus (and would not go back on it): refused (found by fuzz_j1939).
  std::vector<std::uint8_t> huge(2 + 4 * 447, 0x01);
  EXPECT_EQ(decode_diagnostic(huge).error(), DiagnosticError::TooLong);
  huge.resize(1785);  // 445 DTCs and 3 bytes: within the size, so judged on its content
  EXPECT_EQ(decode_diagnostic(huge).error(), DiagnosticError::Truncated);
  huge.resize(1782);
  EXPECT_EQ(decode_diagnostic(huge)->dtcs.size(), 445U);
}

TEST(J1939Bam, FramesOfOurOwnReassembleAndBrokenOnesAreCounted) {
  std::vector<std::uint8_t> data(20);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i);
  const auto frames = bam_frames(7, kPgnDm1, 0x80, data);
  ASSERT_EQ(frames.size(), 4U);  // announcement and 3 packets
  EXPECT_EQ(frames[0].id, 0x1CECFF80U);
  const std::array<std::uint8_t, 8> cm{32, 20, 0, 3, 0xFF, 0xCA, 0xFE, 0x00};
  EXPECT_EQ(frames[0].data, cm);
  EXPECT_EQ(frames[1].id, 0x1CEBFF80U);
  const std::array<std::uint8_t, 8> last{3, 14, 15, 16, 17, 18, 19, 0xFF};
  EXPECT_EQ(frames[3].data, last);

  BamReceiver rx;
  double t = 10.0;
  std::optional<BamReceiver::Message> got;
  for (const auto& f : frames) got = rx.feed(f, t += 0.05);
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->pgn, kPgnDm1);
  EXPECT_EQ(got->source, 0x80);
  EXPECT_EQ(got->data, data);
  // A packet lost: nothing completes, the next packet is out of sequence.
  EXPECT_FALSE(rx.feed(frames[0], t += 0.05));
  EXPECT_FALSE(rx.feed(frames[1], t += 0.05));
  EXPECT_FALSE(rx.feed(frames[3], t += 0.05));
  EXPECT_EQ(rx.counters().dropped_sequence, 1U);
  // Too slow: more than 750 ms between two packets.
  EXPECT_FALSE(rx.feed(frames[0], t += 0.05));
  EXPECT_FALSE(rx.feed(frames[1], t += 1.0));
  EXPECT_EQ(rx.counters().dropped_timeout, 1U);
  // Announced again halfway.
  EXPECT_FALSE(rx.feed(frames[0], t += 0.05));
  EXPECT_FALSE(rx.feed(frames[1], t += 0.05));
  EXPECT_FALSE(rx.feed(frames[0], t += 0.05));
  EXPECT_EQ(rx.counters().dropped_restart, 1U);
  // An announcement whose packet count does not match its size.
  CanFrame bad = frames[0];
  bad.data[3] = 9;
  EXPECT_FALSE(rx.feed(bad, t += 0.05));
  EXPECT_EQ(rx.counters().bad_announcements, 1U);
  EXPECT_EQ(rx.counters().completed, 1U);
  EXPECT_THROW((void)bam_frames(7, kPgnDm1, 0x80, std::vector<std::uint8_t>(8)), std::invalid_argument);
  EXPECT_THROW((void)bam_frames(7, kPgnDm1, 0x80, std::vector<std::uint8_t>(1786)), std::invalid_argument);
}

}  // namespace
}  // namespace fieldguard::output::j1939
