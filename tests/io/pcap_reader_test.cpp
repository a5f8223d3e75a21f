#include "fieldguard/io/pcap_reader.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <map>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "io/pcap_builder.hpp"
#include "io/pcap_reader_support.hpp"

namespace fieldguard::io {
namespace {

using namespace reader_test;  // NOLINT(google-build-using-namespace): test helpers
using testing::ClassicPcap;
using testing::Ipv4Udp;
using testing::Pcapng;
using testing::TempDir;

// ---- open errors ----

TEST(PcapReaderOpen, MissingFile) {
  TempDir dir;
  const std::string path = (dir.path() / "nope.pcap").string();
  const auto r = PcapReader::open(path);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error(), "cannot open " + path + ": No such file or directory");
}

TEST(PcapReaderOpen, DirectoryIsNotAFile) {
  TempDir dir;
  const std::string path = dir.path().string();
  const auto r = PcapReader::open(path);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error(), "cannot read " + path + ": Is a directory");
}

TEST(PcapReaderOpen, UnreadableFile) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads files whatever their mode (DirectoryIsNotAFile covers read errors)";
  TempDir dir;
  const std::string path = dir.write("locked.pcap", ClassicPcap().add(eth(2368, 10), kT0).bytes());
  ASSERT_EQ(::chmod(path.c_str(), 0), 0);
  const auto r = PcapReader::open(path);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error(), "cannot open " + path + ": Permission denied");
}

struct OpenErrorCase {
  std::string name;
  Bytes bytes;
  std::string expected;  // what follows the path; for libpcap's own words, only their start
};
void PrintTo(const OpenErrorCase& c, std::ostream* os) { *os << c.name; }

class PcapReaderOpenError : public ::testing::TestWithParam<OpenErrorCase> {};

TEST_P(PcapReaderOpenError, NamesTheFileAndTheProblem) {
  const OpenErrorCase& c = GetParam();
  TempDir dir;
  const std::string path = dir.write(c.name + ".pcap", c.bytes);
  const auto r = PcapReader::open(path);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error().find('\n'), std::string::npos) << r.error();
  EXPECT_EQ(r.error().rfind(path, 0), 0U) << r.error();
  EXPECT_EQ(r.error().substr(path.size(), c.expected.size()), c.expected) << r.error();
}

Bytes head(const Bytes& b, std::size_t n) { return {b.begin(), b.begin() + static_cast<std::ptrdiff_t>(n)}; }

std::vector<OpenErrorCase> open_error_cases() {
  const Bytes pcap = ClassicPcap().bytes();
  const Bytes pcapng = Pcapng().interface(1).bytes();
  Bytes bad_bom = pcapng;
  bad_bom[8] = 0x00;  // byte-order magic 0x1A2B3C4D -> 0x1A2B3C00
  return {
      {"empty", {}, " is empty: not a pcap or pcapng file"},
      {"three_bytes", {0xD4, 0xC3, 0xB2}, " is too short to be a pcap or pcapng file (3 bytes)"},
      {"elf",
       {0x7F, 'E', 'L', 'F', 2, 1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
       " is not a pcap or pcapng file (magic 0x7f454c46)"},
      {"text", Bytes(40, 'x'), " is not a pcap or pcapng file (magic 0x78787878)"},
      {"pcap_header_12_of_24", head(pcap, 12),
       " is cut short inside its file header (truncated dump file; tried to read "},
      {"pcapng_shb_cut", head(pcapng, 20),
       " is cut short inside its file header (truncated pcapng dump file; tried to read "},
      {"pcapng_shb_10_bytes", head(pcapng, 10),
       " is cut short inside its file header (10 bytes of a pcapng section header)"},
      {"pcapng_idb_cut", head(pcapng, 28 + 10),
       " is cut short inside its file header (truncated pcapng dump file; tried to read "},
      {"pcapng_without_interface", Pcapng().bytes(), ": the capture file has no Interface Description Blocks"},
      {"pcapng_bad_byte_order_magic", bad_bom,
       " is not a readable pcapng file: bad byte-order magic in its section header"},
  };
}

INSTANTIATE_TEST_SUITE_P(Malformed, PcapReaderOpenError, ::testing::ValuesIn(open_error_cases()),
                         [](const auto& p) { return p.param.name; });

TEST(PcapReaderOpen, NullFile) {
  const auto r = PcapReader::open(nullptr, "memory");
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error(), "cannot open memory: no file given");
}

TEST(PcapReaderOpen, FromMemoryFile) {
  Bytes bytes = ClassicPcap().add(eth(2368, 1206), kT0).bytes();
  std::FILE* f = ::fmemopen(bytes.data(), bytes.size(), "rb");
  ASSERT_NE(f, nullptr);
  auto r = PcapReader::open(f, "memory");
  ASSERT_TRUE(r.has_value()) << r.error();
  EXPECT_EQ(drain(*r), (std::vector<Seen>{{2368, 1206, kT0 / 1000 * 1000}}));
}

// ---- classic pcap: byte orders and resolutions ----

struct ClassicCase {
  bool big_endian;
  bool nanosecond;
};
void PrintTo(const ClassicCase& c, std::ostream* os) {
  *os << (c.big_endian ? "big" : "little") << (c.nanosecond ? " ns" : " us");
}

class PcapReaderClassic : public ::testing::TestWithParam<ClassicCase> {};

TEST_P(PcapReaderClassic, DecodesEveryRecordWithItsTime) {
  const bool big_endian = GetParam().big_endian;
  const bool nanosecond = GetParam().nanosecond;
  ClassicPcap file(1, big_endian, nanosecond);
  file.add(eth(2368, 1206, 1), kT0).add(eth(8308, 512, 2), kT0 + 553'001).add(eth(2368, 1206, 3), kT0 + 1'106'999);
  TempDir dir;
  PcapReader r = open_ok(dir.write("f.pcap", file.bytes()));
  EXPECT_EQ(r.link_type(), kLinkEthernet);
  // µs files lose the sub-microsecond digits; ns files keep them exactly.
  const auto t = [&](std::int64_t ns) { return nanosecond ? ns : ns / 1000 * 1000; };
  EXPECT_EQ(drain(r),
            (std::vector<Seen>{{2368, 1206, t(kT0)}, {8308, 512, t(kT0 + 553'001)}, {2368, 1206, t(kT0 + 1'106'999)}}));
  EXPECT_EQ(r.stats().records, 3U);
  EXPECT_EQ(r.stats().datagrams, 3U);
  EXPECT_FALSE(r.stats().truncated);
  EXPECT_EQ(r.stats().read_error, "");
  EXPECT_FALSE(r.next().has_value());  // stays at the end
}

INSTANTIATE_TEST_SUITE_P(Formats, PcapReaderClassic,
                         ::testing::Values(ClassicCase{false, false}, ClassicCase{false, true},
                                           ClassicCase{true, false}, ClassicCase{true, true}),
                         [](const auto& p) {
                           return std::string(p.param.big_endian ? "big_endian" : "little_endian") +
                                  (p.param.nanosecond ? "_ns" : "_us");
                         });

TEST(PcapReaderClassic, BigEndianHeaderBytes) {
  // The writer's byte order is visible in the file: magic a1 b2 c3 d4 for big-endian.
  const Bytes b = ClassicPcap(1, true, false).bytes();
  EXPECT_EQ(head(b, 4), (Bytes{0xA1, 0xB2, 0xC3, 0xD4}));
}

// ---- link types through libpcap ----

struct LinkCase {
  std::string name;
  std::uint32_t file_link_type;
  Bytes frame;
};
void PrintTo(const LinkCase& c, std::ostream* os) { *os << c.name; }

class PcapReaderLink : public ::testing::TestWithParam<LinkCase> {};

TEST_P(PcapReaderLink, Decodes) {
  const LinkCase& c = GetParam();
  TempDir dir;
  PcapReader r = open_ok(dir.write("f.pcap", ClassicPcap(c.file_link_type).add(c.frame, kT0).bytes()));
  EXPECT_EQ(r.link_type(), static_cast<int>(c.file_link_type));
  EXPECT_EQ(drain(r), (std::vector<Seen>{{2368, 1206, kT0 / 1000 * 1000}}));
}

INSTANTIATE_TEST_SUITE_P(
    Links, PcapReaderLink,
    ::testing::Values(LinkCase{"ethernet", 1, eth(2368, 1206)},
                      LinkCase{"vlan", 1, testing::ethernet(datagram(2368, 1206), 0x0800, {0x8100})},
                      LinkCase{"qinq", 1, testing::ethernet(datagram(2368, 1206), 0x0800, {0x88A8, 0x8100})},
                      LinkCase{"linux_sll", 113, testing::linux_sll(datagram(2368, 1206))},
                      LinkCase{"linux_sll2", 276, testing::linux_sll2(datagram(2368, 1206))},
                      LinkCase{"raw", 101, datagram(2368, 1206)}),
    [](const auto& p) { return p.param.name; });

TEST(PcapReaderLink, UnsupportedLinkTypeIsCountedPerRecord) {
  TempDir dir;
  PcapReader r = open_ok(dir.write("can.pcap", ClassicPcap(227).add(Bytes(16, 0), kT0).add(Bytes(16, 0), kT0).bytes()));
  EXPECT_EQ(r.link_type(), 227);
  EXPECT_TRUE(drain(r).empty());
  EXPECT_EQ(drops(r, FrameDrop::UnsupportedLink), 2U);
}

// ---- bad records inside a good file ----

TEST(PcapReaderRecords, EveryDropKindIsCountedAndReadingGoesOn) {
  Ipv4Udp tcp;
  tcp.protocol = 6;
  Ipv4Udp fragment;
  fragment.flags_fragment = 0x2000;
  Ipv4Udp bad_udp;
  bad_udp.udp_length = 7;
  Ipv4Udp bad_ip;
  bad_ip.ihl = 4;
  ClassicPcap file;
  file.add(eth(2368, 1206), kT0)
      .add(testing::ethernet(Bytes(28, 0), 0x0806), kT0)        // ARP
      .add(testing::ethernet(datagram(2368, 10), 0x86DD), kT0)  // IPv6 EtherType
      .add(testing::ethernet(testing::build(tcp)), kT0)         // TCP
      .add(testing::ethernet(testing::build(fragment)), kT0)    // first fragment
      .add(testing::ethernet(testing::build(bad_udp)), kT0)     // UDP length 7
      .add(testing::ethernet(testing::build(bad_ip)), kT0)      // IHL 4
      .add(Bytes(10, 0), kT0)                                   // shorter than Ethernet
      .add(head(eth(2368, 1206), 100), kT0, 1248)               // snaplen cut
      .add(eth(8308, 512), kT0);
  TempDir dir;
  PcapReader r = open_ok(dir.write("mixed.pcap", file.bytes()));
  const auto seen = drain(r);
  ASSERT_EQ(seen.size(), 2U);
  EXPECT_EQ(seen[0].port, 2368);
  EXPECT_EQ(seen[1].port, 8308);
  const PcapStats& s = r.stats();
  EXPECT_EQ(s.records, 10U);
  EXPECT_EQ(s.datagrams, 2U);
  EXPECT_EQ(drops(r, FrameDrop::NotIpv4), 2U);
  EXPECT_EQ(drops(r, FrameDrop::NotUdp), 1U);
  EXPECT_EQ(drops(r, FrameDrop::IpFragment), 1U);
  EXPECT_EQ(drops(r, FrameDrop::BadUdpLength), 1U);
  EXPECT_EQ(drops(r, FrameDrop::BadIpHeader), 1U);
  EXPECT_EQ(drops(r, FrameDrop::ShortLinkHeader), 1U);
  EXPECT_EQ(drops(r, FrameDrop::TruncatedRecord), 1U);
  EXPECT_EQ(drops(r, FrameDrop::UnsupportedLink), 0U);
  EXPECT_FALSE(s.truncated);
}

TEST(PcapReaderRecords, SnaplenShorterThanThePacket) {
  // A capture taken with -s 100: libpcap hands out caplen 100, len 1248.
  ClassicPcap file(1, false, false, 100);
  file.add(head(eth(2368, 1206), 100), kT0, 1248).add(head(eth(2368, 1206), 100), kT0, 1248);
  TempDir dir;
  PcapReader r = open_ok(dir.write("snap.pcap", file.bytes()));
  EXPECT_TRUE(drain(r).empty());
  EXPECT_EQ(r.stats().records, 2U);
  EXPECT_EQ(drops(r, FrameDrop::TruncatedRecord), 2U);
}

// ---- files that end or break inside a record ----

class PcapReaderTruncated : public ::testing::TestWithParam<std::size_t> {};

TEST_P(PcapReaderTruncated, DeliversEverythingBeforeTheCut) {
  ClassicPcap file;
  file.add(eth(2368, 1206, 1), kT0).add(eth(8308, 512, 2), kT0 + 1000);
  const std::size_t good = file.bytes().size();
  file.add(eth(2368, 1206, 3), kT0 + 2000);
  TempDir dir;
  PcapReader r = open_ok(dir.write("cut.pcap", head(file.bytes(), good + GetParam())));
  EXPECT_EQ(drain(r), (std::vector<Seen>{{2368, 1206, kT0 / 1000 * 1000}, {8308, 512, kT0 / 1000 * 1000 + 1000}}));
  EXPECT_TRUE(r.stats().truncated);
  EXPECT_EQ(r.stats().read_error, "");
  EXPECT_EQ(r.stats().records, 2U);
  EXPECT_FALSE(r.next().has_value());
}

// Cut inside the last record header (1, 15 bytes of 16) and inside its data (16 + 1, 16 + 624).
INSTANTIATE_TEST_SUITE_P(CutAt, PcapReaderTruncated, ::testing::Values(1U, 15U, 17U, 640U));

TEST(PcapReaderReadError, CaptureLengthBeyondLibpcapsMaximum) {
  // A record header claiming 300000 captured bytes: libpcap refuses it (not a truncation).
  ClassicPcap file;
  file.add(eth(2368, 1206), kT0);
  Bytes bytes = file.bytes();
  testing::put_u32(bytes, 1, false);
  testing::put_u32(bytes, 0, false);
  testing::put_u32(bytes, 300000, false);
  testing::put_u32(bytes, 300000, false);
  bytes.resize(bytes.size() + 300000, 0);
  TempDir dir;
  PcapReader r = open_ok(dir.write("huge.pcap", bytes));
  EXPECT_EQ(drain(r).size(), 1U);
  EXPECT_FALSE(r.stats().truncated);
  EXPECT_NE(r.stats().read_error.find("invalid packet capture length 300000"), std::string::npos)
      << r.stats().read_error;
}

TEST(PcapReaderMove, MovedReaderGoesOn) {
  TempDir dir;
  PcapReader a = open_ok(dir.write("f.pcap", ClassicPcap().add(eth(2368, 1206), kT0).add(eth(8308, 512), kT0).bytes()));
  ASSERT_TRUE(a.next().has_value());
  PcapReader b = std::move(a);
  EXPECT_EQ(drain(b).size(), 1U);
  EXPECT_EQ(b.stats().datagrams, 2U);
}

// ---- the real capture ----

TEST(PcapReaderRealData, Hdl32eCapture) {
  // tests/data/velodyne_vlp32.pcap: an HDL-32E capture (see PROVENANCE.txt), 100 records.
  PcapReader r = open_ok(FIELDGUARD_TEST_DATA "/velodyne_vlp32.pcap");
  EXPECT_EQ(r.link_type(), kLinkEthernet);
  std::map<std::uint16_t, std::map<std::size_t, int>> by_port;  // port -> payload size -> count
  std::optional<Stamp> first;
  std::uint32_t src = 0;
  while (auto d = r.next()) {
    if (!first) first = d->host_time;
    src = d->src_ip;
    ++by_port[d->dst_port][d->payload.size()];
  }
  EXPECT_EQ(by_port, (std::map<std::uint16_t, std::map<std::size_t, int>>{{2368, {{1206, 91}}}, {8308, {{512, 9}}}}));
  // First record header: ts_sec 0x50c7a9a9, ts_usec 0x000ecb68.
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->ns, 1'355'262'377'969'576'000);
  EXPECT_EQ(src, testing::ipv4(192, 168, 1, 201));
  EXPECT_EQ(r.stats().records, 100U);
  EXPECT_FALSE(r.stats().truncated);
  EXPECT_EQ(r.stats().read_error, "");
}

TEST(PcapReaderRealData, Vlp16PositionPacketsWithImpossibleIpLength) {
  // tests/data/vlp16_veloview_300.pcap (PROVENANCE.txt): 253 data packets and 47 position packets whose
  // IP header claims 1234 bytes in a 554-byte frame. Every one is used; only the position packets are
  // counted as repaired.
  PcapReader r = open_ok(FIELDGUARD_TEST_DATA "/vlp16_veloview_300.pcap");
  std::map<std::uint16_t, std::map<std::size_t, int>> by_port;
  std::map<std::uint16_t, int> repaired;
  while (auto d = r.next()) {
    ++by_port[d->dst_port][d->payload.size()];
    if (d->ip_length_repaired) ++repaired[d->dst_port];
  }
  EXPECT_EQ(by_port, (std::map<std::uint16_t, std::map<std::size_t, int>>{{2368, {{1206, 253}}}, {8308, {{512, 47}}}}));
  EXPECT_EQ(repaired, (std::map<std::uint16_t, int>{{8308, 47}}));
  EXPECT_EQ(r.stats().ip_length_repaired, 47U);
  EXPECT_EQ(r.stats().drops[static_cast<std::size_t>(FrameDrop::BadIpHeader)], 0U);
}

}  // namespace
}  // namespace fieldguard::io
