// PcapReader on pcapng files (protocols.md §9.2), written with the test builder and read through libpcap.

#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "fieldguard/io/pcap_reader.hpp"
#include "io/pcap_builder.hpp"
#include "io/pcap_reader_support.hpp"

namespace fieldguard::io {
namespace {

using namespace reader_test;  // NOLINT(google-build-using-namespace): test helpers
using testing::Pcapng;
using testing::TempDir;

struct PcapngCase {
  std::string name;
  std::optional<std::uint8_t> tsresol;
  std::uint64_t units;    // timestamp in the interface's units
  std::int64_t expected;  // ns
};
void PrintTo(const PcapngCase& c, std::ostream* os) { *os << c.name; }

class PcapReaderPcapng : public ::testing::TestWithParam<PcapngCase> {};

TEST_P(PcapReaderPcapng, TimestampResolution) {
  const PcapngCase& c = GetParam();
  for (const bool big_endian : {false, true}) {
    Pcapng file(big_endian);
    file.interface(1, c.tsresol).enhanced(0, c.units, eth(2368, 1206));
    TempDir dir;
    PcapReader r = open_ok(dir.write("f.pcapng", file.bytes()));
    EXPECT_EQ(r.link_type(), kLinkEthernet);
    EXPECT_EQ(drain(r), (std::vector<Seen>{{2368, 1206, c.expected}})) << "big endian " << big_endian;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Resolutions, PcapReaderPcapng,
    ::testing::Values(PcapngCase{"default_us", std::nullopt, 1'700'000'000'123'456, 1'700'000'000'123'456'000},
                      PcapngCase{"ns", 9, 1'700'000'000'123'456'789, 1'700'000'000'123'456'789},
                      PcapngCase{"ms", 3, 1'700'000'000'123, 1'700'000'000'123'000'000},
                      PcapngCase{"two_to_minus_10", 0x8A, 1'000ULL * 1024 + 512, 1'000'500'000'000},
                      // 10^10 s (year 2286) does not fit int64 ns: saturated, not overflowed.
                      PcapngCase{"seconds_past_int64_ns", 0, 10'000'000'000, INT64_MAX}),
    [](const auto& p) { return p.param.name; });

TEST(PcapReaderPcapngBlocks, SimplePacketBlockHasNoTime) {
  Pcapng file;
  file.interface(1, std::nullopt, 65535).simple(eth(2368, 1206)).enhanced(0, 5, eth(8308, 512));
  TempDir dir;
  PcapReader r = open_ok(dir.write("spb.pcapng", file.bytes()));
  EXPECT_EQ(drain(r), (std::vector<Seen>{{2368, 1206, 0}, {8308, 512, 5000}}));
}

TEST(PcapReaderPcapngBlocks, SecondInterfaceOfTheSameType) {
  Pcapng file;
  file.interface(1).interface(1, 9).enhanced(1, 7, eth(2368, 1206)).enhanced(0, 7, eth(8308, 512));
  TempDir dir;
  PcapReader r = open_ok(dir.write("two.pcapng", file.bytes()));
  EXPECT_EQ(drain(r), (std::vector<Seen>{{2368, 1206, 7}, {8308, 512, 7000}}));
}

TEST(PcapReaderPcapngBlocks, InterfaceOfAnotherLinkTypeStopsLibpcap) {
  // libpcap gives one link type per file and refuses an interface of another: what came before the
  // second IDB is delivered, then reading stops with libpcap's message.
  Pcapng file;
  file.interface(1).enhanced(0, 1, eth(2368, 1206));
  file.interface(113).enhanced(1, 2, testing::linux_sll(datagram(8308, 512)));
  TempDir dir;
  PcapReader r = open_ok(dir.write("mixed.pcapng", file.bytes()));
  EXPECT_EQ(r.link_type(), kLinkEthernet);
  EXPECT_EQ(drain(r), (std::vector<Seen>{{2368, 1206, 1000}}));
  EXPECT_FALSE(r.stats().truncated);
  EXPECT_EQ(r.stats().read_error, "an interface has a type 113 different from the type of the first interface");
}

TEST(PcapReaderTruncatedPcapng, LastBlockCut) {
  Pcapng file;
  file.interface(1).enhanced(0, 1'700'000'000'000'000, eth(2368, 1206));
  const std::size_t good = file.bytes().size();
  file.enhanced(0, 1'700'000'000'000'001, eth(8308, 512));
  TempDir dir;
  PcapReader r = open_ok(dir.write("cut.pcapng", head(file.bytes(), good + 300)));
  EXPECT_EQ(drain(r).size(), 1U);
  EXPECT_TRUE(r.stats().truncated);
  EXPECT_EQ(r.stats().read_error, "");
}

}  // namespace
}  // namespace fieldguard::io
