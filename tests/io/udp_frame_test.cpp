#include "fieldguard/io/udp_frame.hpp"

#include <gtest/gtest.h>

#include <ostream>
#include <string>
#include <vector>

#include "io/pcap_builder.hpp"

namespace fieldguard::io {
namespace {

using testing::Bytes;
using testing::Ipv4Udp;

Ipv4Udp velodyne_data() {
  Ipv4Udp d;
  d.src_ip = testing::ipv4(192, 168, 1, 201);
  d.dst_ip = testing::ipv4(255, 255, 255, 255);
  d.src_port = 2368;
  d.dst_port = 2368;
  d.payload = testing::pattern(1206, 3);
  return d;
}

Bytes payload_bytes(const UdpDatagram& d) { return {d.payload.begin(), d.payload.end()}; }

Expected<UdpDatagram, FrameDrop> extract(int link_type, const Bytes& frame) {
  return extract_udp(link_type, frame, static_cast<std::uint32_t>(frame.size()), Stamp{42});
}

TEST(UdpFrame, EthernetDatagramFields) {
  const Ipv4Udp d = velodyne_data();
  const Bytes frame = testing::ethernet(testing::build(d));
  ASSERT_EQ(frame.size(), 1248U);  // an HDL-32E data frame on Ethernet (protocols.md §9.1)
  const auto r = extract_udp(kLinkEthernet, frame, 1248, Stamp{1'700'000'000'123'456'000});
  ASSERT_TRUE(r.has_value()) << to_string(r.error());
  EXPECT_EQ(r->host_time, Stamp{1'700'000'000'123'456'000});
  EXPECT_EQ(r->src_ip, 0xC0A801C9U);
  EXPECT_EQ(r->dst_ip, 0xFFFFFFFFU);
  EXPECT_EQ(r->src_port, 2368);
  EXPECT_EQ(r->dst_port, 2368);
  EXPECT_EQ(r->payload.data(), frame.data() + 42);  // points into the frame, no copy
  EXPECT_EQ(payload_bytes(*r), d.payload);
}

// The VLP-16's position packets claim an IP total length of 1234 in a 554-byte frame (real captures:
// tests/data/vlp16_veloview_300.pcap). The record is whole, the UDP length (520) fits: the datagram is
// used and flagged, and a normal one is not flagged.
TEST(UdpFrame, ImpossibleTotalLengthFallsBackToTheUdpLength) {
  Ipv4Udp d = velodyne_data();
  d.src_port = 8308;
  d.dst_port = 8308;
  d.payload = testing::pattern(512, 5);
  d.total_length = 1234;
  const Bytes frame = testing::ethernet(testing::build(d));
  ASSERT_EQ(frame.size(), 554U);
  const auto r = extract(kLinkEthernet, frame);
  ASSERT_TRUE(r.has_value()) << to_string(r.error());
  EXPECT_TRUE(r->ip_length_repaired);
  EXPECT_EQ(payload_bytes(*r), d.payload);

  const auto normal = extract(kLinkEthernet, testing::ethernet(testing::build(velodyne_data())));
  ASSERT_TRUE(normal.has_value());
  EXPECT_FALSE(normal->ip_length_repaired);

  // The same frame cut by the snaplen stays a truncated record: only a whole record is repaired.
  const auto cut = extract_udp(kLinkEthernet, frame, 600, Stamp{1});
  ASSERT_FALSE(cut.has_value());
  EXPECT_EQ(cut.error(), FrameDrop::TruncatedRecord);
}

struct DecodeCase {
  std::string name;
  int link_type;
  Bytes frame;
  std::size_t payload_offset;
};
void PrintTo(const DecodeCase& c, std::ostream* os) { *os << c.name; }

class UdpFrameDecode : public ::testing::TestWithParam<DecodeCase> {};

TEST_P(UdpFrameDecode, FindsThePayload) {
  const DecodeCase& c = GetParam();
  const auto r = extract(c.link_type, c.frame);
  ASSERT_TRUE(r.has_value()) << to_string(r.error());
  EXPECT_EQ(r->src_port, 2368);
  EXPECT_EQ(r->dst_port, 2368);
  EXPECT_EQ(r->payload.data(), c.frame.data() + c.payload_offset);
  EXPECT_EQ(payload_bytes(*r), velodyne_data().payload);
}

std::vector<DecodeCase> decode_cases() {
  const Bytes ip = testing::build(velodyne_data());
  Ipv4Udp with_options = velodyne_data();
  with_options.ip_options = {0x94, 0x04, 0x00, 0x00, 0x01, 0x01, 0x01, 0x00};  // router alert, NOP x3, EOL
  Bytes padded = testing::ethernet(ip);
  padded.insert(padded.end(), {0x00, 0x00, 0xDE, 0xAD, 0xBE, 0xEF});  // padding + FCS after the datagram
  return {
      {"ethernet", kLinkEthernet, testing::ethernet(ip), 42},
      {"vlan_8100", kLinkEthernet, testing::ethernet(ip, 0x0800, {0x8100}), 46},
      {"qinq_88a8_8100", kLinkEthernet, testing::ethernet(ip, 0x0800, {0x88A8, 0x8100}), 50},
      {"qinq_8100_8100", kLinkEthernet, testing::ethernet(ip, 0x0800, {0x8100, 0x8100}), 50},
      {"ethernet_trailing_fcs", kLinkEthernet, padded, 42},
      {"ip_options", kLinkEthernet, testing::ethernet(testing::build(with_options)), 50},
      {"linux_sll", kLinkLinuxSll, testing::linux_sll(ip), 44},  // 1250 bytes in SLL (§9.1)
      {"linux_sll2", kLinkLinuxSll2, testing::linux_sll2(ip), 48},
      {"raw", kLinkRaw, ip, 28},
  };
}

INSTANTIATE_TEST_SUITE_P(Links, UdpFrameDecode, ::testing::ValuesIn(decode_cases()),
                         [](const auto& p) { return p.param.name; });

TEST(UdpFrame, MinimumEthernetFramePaddingIsNotPayload) {
  Ipv4Udp d = velodyne_data();
  d.payload = {1, 2, 3, 4};
  Bytes frame = testing::ethernet(testing::build(d));
  frame.resize(60, 0xAA);  // padded to the 60-byte Ethernet minimum
  const auto r = extract(kLinkEthernet, frame);
  ASSERT_TRUE(r.has_value()) << to_string(r.error());
  EXPECT_EQ(payload_bytes(*r), (Bytes{1, 2, 3, 4}));
}

TEST(UdpFrame, UdpLengthShorterThanIpPayloadWins) {
  Ipv4Udp d = velodyne_data();
  d.payload = testing::pattern(20);
  d.udp_length = 8 + 12;
  const auto r = extract(kLinkRaw, testing::build(d));
  ASSERT_TRUE(r.has_value()) << to_string(r.error());
  EXPECT_EQ(r->payload.size(), 12U);
}

TEST(UdpFrame, EmptyPayload) {
  Ipv4Udp d = velodyne_data();
  d.payload.clear();
  const auto r = extract(kLinkEthernet, testing::ethernet(testing::build(d)));
  ASSERT_TRUE(r.has_value()) << to_string(r.error());
  EXPECT_TRUE(r->payload.empty());
}

struct DropCase {
  std::string name;
  int link_type;
  Bytes frame;
  std::uint32_t original_length;  // 0: the frame's size
  FrameDrop expected;
};
void PrintTo(const DropCase& c, std::ostream* os) { *os << c.name; }

class UdpFrameDrop : public ::testing::TestWithParam<DropCase> {};

TEST_P(UdpFrameDrop, GivesItsReason) {
  const DropCase& c = GetParam();
  const std::uint32_t original =
      c.original_length != 0 ? c.original_length : static_cast<std::uint32_t>(c.frame.size());
  const auto r = extract_udp(c.link_type, c.frame, original, Stamp{1});
  ASSERT_FALSE(r.has_value()) << "decoded a datagram to port " << r->dst_port;
  EXPECT_EQ(r.error(), c.expected) << to_string(r.error());
}

Ipv4Udp small() {
  Ipv4Udp d = velodyne_data();
  d.payload = testing::pattern(16);
  return d;
}

Bytes eth(const Ipv4Udp& d) { return testing::ethernet(testing::build(d)); }

Bytes cut(Bytes b, std::size_t n) {
  b.resize(n);
  return b;
}

std::vector<DropCase> drop_cases() {
  std::vector<DropCase> cases;
  const Bytes ip = testing::build(small());
  const auto ip_size = static_cast<std::uint32_t>(ip.size());
  auto with = [](auto change) {
    Ipv4Udp d = small();
    change(d);
    return d;
  };
  // Link layer.
  cases.push_back(
      {"snaplen_cut", kLinkEthernet, cut(testing::ethernet(ip), 40), 14 + ip_size, FrameDrop::TruncatedRecord});
  cases.push_back({"snaplen_cut_in_link_header", kLinkEthernet, cut(testing::ethernet(ip), 10), 14 + ip_size,
                   FrameDrop::TruncatedRecord});
  cases.push_back({"can_socketcan", 227, Bytes(16, 0), 0, FrameDrop::UnsupportedLink});
  cases.push_back({"ethernet_13_bytes", kLinkEthernet, cut(testing::ethernet(ip), 13), 0, FrameDrop::ShortLinkHeader});
  cases.push_back(
      {"vlan_tag_cut", kLinkEthernet, cut(testing::ethernet(ip, 0x0800, {0x8100}), 17), 0, FrameDrop::ShortLinkHeader});
  cases.push_back({"inner_tag_cut", kLinkEthernet, cut(testing::ethernet(ip, 0x0800, {0x88A8, 0x8100}), 20), 0,
                   FrameDrop::ShortLinkHeader});
  cases.push_back({"sll_15_bytes", kLinkLinuxSll, cut(testing::linux_sll(ip), 15), 0, FrameDrop::ShortLinkHeader});
  cases.push_back({"sll2_19_bytes", kLinkLinuxSll2, cut(testing::linux_sll2(ip), 19), 0, FrameDrop::ShortLinkHeader});
  cases.push_back({"ipv6_ethertype", kLinkEthernet, testing::ethernet(ip, 0x86DD), 0, FrameDrop::NotIpv4});
  cases.push_back({"arp", kLinkEthernet, testing::ethernet(Bytes(28, 0), 0x0806), 0, FrameDrop::NotIpv4});
  cases.push_back(
      {"vlan_arp", kLinkEthernet, testing::ethernet(Bytes(28, 0), 0x0806, {0x8100}), 0, FrameDrop::NotIpv4});
  cases.push_back({"sll_ipv6", kLinkLinuxSll, testing::linux_sll(ip, 0x86DD), 0, FrameDrop::NotIpv4});
  cases.push_back({"sll2_arp", kLinkLinuxSll2, testing::linux_sll2(Bytes(28, 0), 0x0806), 0, FrameDrop::NotIpv4});
  cases.push_back(
      {"raw_ipv6", kLinkRaw, testing::build(with([](Ipv4Udp& d) { d.version = 6; })), 0, FrameDrop::NotIpv4});
  // IPv4 header.
  cases.push_back({"raw_empty", kLinkRaw, Bytes{}, 0, FrameDrop::BadIpHeader});
  cases.push_back({"ihl_4", kLinkEthernet, eth(with([](Ipv4Udp& d) { d.ihl = 4; })), 0, FrameDrop::BadIpHeader});
  cases.push_back({"ihl_0", kLinkRaw, testing::build(with([](Ipv4Udp& d) { d.ihl = 0; })), 0, FrameDrop::BadIpHeader});
  cases.push_back({"version_6_in_ipv4_ethertype", kLinkEthernet, eth(with([](Ipv4Udp& d) { d.version = 6; })), 0,
                   FrameDrop::BadIpHeader});
  cases.push_back(
      {"raw_version_5", kLinkRaw, testing::build(with([](Ipv4Udp& d) { d.version = 5; })), 0, FrameDrop::BadIpHeader});
  cases.push_back({"ip_header_cut", kLinkEthernet, cut(testing::ethernet(ip), 14 + 19), 0, FrameDrop::BadIpHeader});
  cases.push_back({"ihl_past_frame", kLinkRaw, cut(testing::build(with([](Ipv4Udp& d) { d.ihl = 15; })), 40), 0,
                   FrameDrop::BadIpHeader});
  // A total length past the whole record is trusted no further than the UDP length: when that does not
  // fit either, the header is bad (see ImpossibleTotalLengthFallsBackToTheUdpLength for when it fits).
  cases.push_back({"total_length_past_frame_udp_too", kLinkEthernet, eth(with([&](Ipv4Udp& d) {
                     d.total_length = static_cast<std::uint16_t>(ip_size + 1);
                     d.udp_length = static_cast<std::uint16_t>(ip_size - 20 + 1);
                   })),
                   0, FrameDrop::BadIpHeader});
  cases.push_back({"total_length_below_header", kLinkEthernet, eth(with([](Ipv4Udp& d) { d.total_length = 19; })), 0,
                   FrameDrop::BadIpHeader});
  cases.push_back({"total_length_below_options", kLinkRaw, testing::build(with([](Ipv4Udp& d) {
                     d.ip_options = Bytes(8, 1);
                     d.total_length = 24;
                   })),
                   0, FrameDrop::BadIpHeader});
  // Protocol and fragments.
  cases.push_back({"tcp", kLinkEthernet, eth(with([](Ipv4Udp& d) { d.protocol = 6; })), 0, FrameDrop::NotUdp});
  cases.push_back({"icmp", kLinkRaw, testing::build(with([](Ipv4Udp& d) { d.protocol = 1; })), 0, FrameDrop::NotUdp});
  cases.push_back({"first_fragment", kLinkEthernet, eth(with([](Ipv4Udp& d) { d.flags_fragment = 0x2000; })), 0,
                   FrameDrop::IpFragment});
  cases.push_back({"middle_fragment", kLinkEthernet, eth(with([](Ipv4Udp& d) { d.flags_fragment = 0x2000 | 185; })), 0,
                   FrameDrop::IpFragment});
  cases.push_back({"last_fragment", kLinkEthernet, eth(with([](Ipv4Udp& d) { d.flags_fragment = 185; })), 0,
                   FrameDrop::IpFragment});
  // UDP header.
  cases.push_back({"udp_length_past_ip", kLinkEthernet, eth(with([](Ipv4Udp& d) { d.udp_length = 8 + 17; })), 0,
                   FrameDrop::BadUdpLength});
  cases.push_back(
      {"udp_length_7", kLinkEthernet, eth(with([](Ipv4Udp& d) { d.udp_length = 7; })), 0, FrameDrop::BadUdpLength});
  cases.push_back({"udp_length_0", kLinkRaw, testing::build(with([](Ipv4Udp& d) { d.udp_length = 0; })), 0,
                   FrameDrop::BadUdpLength});
  cases.push_back({"udp_header_cut_by_total_length", kLinkEthernet,
                   eth(with([](Ipv4Udp& d) { d.total_length = 20 + 7; })), 0, FrameDrop::BadUdpLength});
  // UDP length that fits the frame (trailing FCS) but not the IP total length.
  Bytes fcs = eth(with([](Ipv4Udp& d) { d.udp_length = 8 + 16 + 4; }));
  fcs.insert(fcs.end(), {0xDE, 0xAD, 0xBE, 0xEF});
  cases.push_back({"udp_length_into_fcs", kLinkEthernet, fcs, 0, FrameDrop::BadUdpLength});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Malformed, UdpFrameDrop, ::testing::ValuesIn(drop_cases()),
                         [](const auto& p) { return p.param.name; });

TEST(UdpFrame, DropNamesAreSnakeCaseAndDistinct) {
  const std::vector<std::string> expected{"truncated_record", "unsupported_link", "short_link_header",
                                          "not_ipv4",         "bad_ip_header",    "ip_fragment",
                                          "not_udp",          "bad_udp_length"};
  ASSERT_EQ(expected.size(), kFrameDropCount);
  for (std::size_t i = 0; i < kFrameDropCount; ++i) {
    EXPECT_EQ(to_string(static_cast<FrameDrop>(i)), expected[i]);
  }
}

}  // namespace
}  // namespace fieldguard::io
