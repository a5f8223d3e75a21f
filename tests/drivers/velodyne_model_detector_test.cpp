// ModelDetector, sensor time, and decoding of the real captures in tests/data (see tests/data/PROVENANCE.txt).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "drivers/velodyne_test_support.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"

namespace fieldguard::velodyne {
namespace {

using test::PacketBuilder;

std::optional<Model> detect(const std::string& file, std::string* reason = nullptr) {
  const auto packets = test::read_data_packets(test::test_data(file));
  EXPECT_GT(packets.size(), 20U) << file;
  ModelDetector d;
  std::size_t used = 0;
  for (const auto& r : packets) {
    const auto h = read_packet_header(r.payload);
    EXPECT_TRUE(h.has_value());
    if (!h) continue;
    d.observe(*h);
    ++used;
    if (d.decided()) break;
  }
  EXPECT_LE(used, 16U) << "the stream holds at most 16 packets while it waits for a decision";
  if (reason) *reason = d.reason();
  return d.decided();
}

TEST(VelodyneModelDetector, EarlyVlp16FirmwareWithHdl32ProductByteIsVlp16) {
  std::string reason;
  EXPECT_EQ(detect("velodyne_vlp16.pcap", &reason), Model::VLP16);
  EXPECT_NE(reason.find("1327"), std::string::npos) << reason;
  EXPECT_NE(reason.find("0x21"), std::string::npos) << reason;
}

TEST(VelodyneModelDetector, Vlp16WithItsOwnProductByte) {
  std::string reason;
  EXPECT_EQ(detect("velodyne_example.pcap", &reason), Model::VLP16);
  EXPECT_NE(reason.find("0x22"), std::string::npos) << reason;
}

TEST(VelodyneModelDetector, Hdl32eCapture) {
  std::string reason;
  EXPECT_EQ(detect("velodyne_vlp32.pcap", &reason), Model::HDL32E);  // mislabeled file: it is an HDL-32E
  EXPECT_NE(reason.find("553"), std::string::npos) << reason;
}

// Synthetic streams: headers with the given timestamps.
ModelDetector feed(const std::vector<std::uint32_t>& stamps, std::uint8_t return_byte, std::uint8_t product,
                   bool dual_layout = false) {
  ModelDetector d;
  for (const std::uint32_t t : stamps) {
    PacketBuilder p;
    p.azimuths(0, 40, dual_layout).factory(return_byte, product).timestamp(t);
    const auto h = read_packet_header(p.span());
    EXPECT_TRUE(h.has_value());
    if (h) d.observe(*h);
  }
  return d;
}

std::vector<std::uint32_t> stamps(std::uint32_t first, double spacing_us, int n, int skip_every = 0) {
  std::vector<std::uint32_t> out;
  for (int i = 0, k = 0; k < n; ++i) {
    if (skip_every > 0 && i % skip_every == skip_every - 1) continue;  // a lost packet
    const double t = static_cast<double>(first) + spacing_us * i;
    out.push_back(static_cast<std::uint32_t>(static_cast<std::uint64_t>(t) % 3'600'000'000ULL));
    ++k;
  }
  return out;
}

TEST(VelodyneModelDetector, NeedsSeveralSpacings) {
  const auto d = feed(stamps(1000, 552.96, 3), 0x37, 0x21);
  EXPECT_FALSE(d.decided().has_value());
}

TEST(VelodyneModelDetector, HourRollOverAndLostPackets) {
  const auto d = feed(stamps(3'599'996'000U, 1327.104, 20, 3), 0x37, 0x21);
  ASSERT_TRUE(d.decided().has_value()) << d.reason();
  EXPECT_EQ(*d.decided(), Model::VLP16);
  const auto h = feed(stamps(3'599'998'000U, 552.96, 12, 4), 0x00, 0x00);  // old HDL-32E firmware: bytes unset
  ASSERT_TRUE(h.decided().has_value()) << h.reason();
  EXPECT_EQ(*h.decided(), Model::HDL32E);
}

TEST(VelodyneModelDetector, DualReturnHalvesTheSpacing) {
  // A dual-return VLP-16 sends a packet every 663.6 us, which is not an HDL-32E's 553 us.
  const auto v = feed(stamps(5000, 663.552, 10), 0x39, 0x21, true);
  ASSERT_TRUE(v.decided().has_value()) << v.reason();
  EXPECT_EQ(*v.decided(), Model::VLP16);
  const auto h = feed(stamps(5000, 276.48, 10), 0x39, 0x21, true);
  ASSERT_TRUE(h.decided().has_value()) << h.reason();
  EXPECT_EQ(*h.decided(), Model::HDL32E);
}

TEST(VelodyneModelDetector, UndecidedOnContradictionOrUnsupportedModel) {
  const auto conflict = feed(stamps(0, 552.96, 12), 0x37, 0x22);
  EXPECT_FALSE(conflict.decided().has_value());
  EXPECT_NE(conflict.reason().find("configure"), std::string::npos) << conflict.reason();
  const auto vlp32c = feed(stamps(0, 1327.104, 12), 0x37, 0x28);
  EXPECT_FALSE(vlp32c.decided().has_value());
  EXPECT_NE(vlp32c.reason().find("VLP-32C"), std::string::npos) << vlp32c.reason();
  const auto odd = feed(stamps(0, 900.0, 12), 0x37, 0x21);
  EXPECT_FALSE(odd.decided().has_value());
  EXPECT_NE(odd.reason().find("neither"), std::string::npos) << odd.reason();
}

// ---- sensor time ----

TEST(VelodyneSensorTime, TakesTheHourFromTheHost) {
  constexpr std::int64_t kHour = 3'600'000'000'000LL;
  const std::int64_t hour = 1'700'000'000LL / 3600 * kHour;  // a top of the hour in 2023
  const Stamp host{hour + 20 * 60'000'000'000LL};            // 20 min past
  EXPECT_EQ(sensor_time_from_hour_offset(1'234'567'890U, host).ns, hour + 1'234'567'890'000LL);
  // Sensor at 59:59.9, host already at 00:00.2 of the next hour: the previous hour.
  EXPECT_EQ(sensor_time_from_hour_offset(3'599'900'000U, Stamp{hour + kHour + 200'000'000}).ns,
            hour + 3'599'900'000'000LL);
  // Sensor at 00:00.1, host still at 59:59.8: the next hour.
  EXPECT_EQ(sensor_time_from_hour_offset(100'000U, Stamp{hour + kHour - 200'000'000}).ns, hour + kHour + 100'000'000);
  // Exactly 30 minutes apart stays in the host's hour.
  EXPECT_EQ(sensor_time_from_hour_offset(0U, Stamp{hour + kHour / 2}).ns, hour);
}

TEST(VelodyneSensorTime, RealCaptureIsWithinASecondOrTwoOfThePcapTime) {
  const auto packets = test::read_data_packets(test::test_data("velodyne_vlp32.pcap"));
  ASSERT_FALSE(packets.empty());
  for (const auto& r : packets) {
    const auto h = read_packet_header(r.payload);
    ASSERT_TRUE(h.has_value());
    const Stamp s = sensor_time_from_hour_offset(h->timestamp_us, r.host);
    EXPECT_LT(std::llabs(s.ns - r.host.ns), 2'000'000'000LL);
  }
}

// ---- decoding the real captures ----

struct CaptureCase {
  const char* file;
  Model model;
  std::size_t packets;
};

class VelodyneRealCapture : public ::testing::TestWithParam<CaptureCase> {};

TEST_P(VelodyneRealCapture, EveryDataPacketDecodes) {
  const auto& c = GetParam();
  const auto packets = test::read_data_packets(test::test_data(c.file));
  ASSERT_EQ(packets.size(), c.packets);
  DecoderOptions o;
  o.model = c.model;
  const Decoder d(default_calibration(c.model), o);
  const std::uint16_t rings = c.model == Model::VLP16 ? 16 : 32;
  std::size_t total = 0;
  std::vector<LidarPoint> pts;
  for (const auto& r : packets) {
    pts.clear();
    const auto h = d.decode(r.payload, pts);
    ASSERT_TRUE(h.has_value()) << to_string(h.error());
    total += pts.size();
    for (const auto& q : pts) {
      ASSERT_LT(q.ring, rings);
      ASSERT_LT(q.azimuth_cdeg, 36000);
      ASSERT_GE(q.range_m, 0.5F);
      ASSERT_LE(q.range_m, 130.F);
      ASSERT_LE(q.time_s, 0.F);
      ASSERT_GT(q.time_s, -1.4e-3F);
      ASSERT_NEAR(std::hypot(q.x, q.y, q.z), q.range_m, 1e-3F);
    }
  }
  // Most firings see something in these (street and tunnel) scenes.
  const std::size_t firings = packets.size() * 12 * 32;
  EXPECT_GT(total, firings / 2);
}

INSTANTIATE_TEST_SUITE_P(Captures, VelodyneRealCapture,
                         ::testing::Values(CaptureCase{"velodyne_vlp32.pcap", Model::HDL32E, 91},
                                           CaptureCase{"velodyne_vlp16.pcap", Model::VLP16, 84},
                                           CaptureCase{"velodyne_example.pcap", Model::VLP16, 84}),
                         [](const auto& i) {
                           std::string n = i.param.file;
                           n = n.substr(0, n.find('.'));
                           return n;
                         });

}  // namespace
}  // namespace fieldguard::velodyne
