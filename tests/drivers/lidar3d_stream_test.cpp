// The 3D LiDAR stream: which sensor the datagrams show (auto), routing by channel, other RoboSense models
// refused and named, the RS-32's nominal angles until its DIFOP, every datagram counted.
#include "fieldguard/drivers/lidar3d_stream.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "drivers/robosense_test_support.hpp"

namespace fieldguard::lidar3d {
namespace {

namespace rs = robosense;
using rs::test::DifopBuilder;
using rs::test::MsopBuilder;

// An RS-32 MSOP packet (model byte `model` at offset 30) at 600 rpm, packet k of a turn.
std::vector<std::uint8_t> msop(std::size_t k, std::uint8_t model = 0x02) {
  MsopBuilder m;
  m.azimuths(static_cast<int>(k) * 240, 20).all_channels(2000, 9);
  m.time_us(rs::test::kExampleUnixUs + static_cast<std::int64_t>(k) * 666);
  m.bytes()[30] = model;
  return m.bytes();
}

// An HDL-32E single-return data packet (protocols.md §1.2): 12 blocks FF EE, azimuths 0.16 deg apart, every
// return at 10 m, factory bytes 0x37 0x21.
std::vector<std::uint8_t> hdl32e(std::size_t k) {
  std::vector<std::uint8_t> b(velodyne::kDataPacketSize, 0);
  for (std::size_t blk = 0; blk < 12; ++blk) {
    const std::size_t o = 100 * blk;
    b[o] = 0xFF;
    b[o + 1] = 0xEE;
    const auto az = static_cast<std::uint16_t>((k * 12 + blk) * 16 % 36000);
    b[o + 2] = static_cast<std::uint8_t>(az & 0xFFU);
    b[o + 3] = static_cast<std::uint8_t>(az >> 8U);
    for (std::size_t j = 0; j < 32; ++j) {
      b[o + 4 + 3 * j] = 0x88;  // 5000 * 2 mm = 10 m
      b[o + 5 + 3 * j] = 0x13;
      b[o + 6 + 3 * j] = 50;
    }
  }
  const auto us = static_cast<std::uint32_t>(1000 + k * 553);
  for (std::size_t i = 0; i < 4; ++i) b[1200 + i] = static_cast<std::uint8_t>(us >> (8U * i));
  b[1204] = 0x37;
  b[1205] = 0x21;
  return b;
}

StreamOptions options(Model m = Model::Auto) {
  StreamOptions o;
  o.model = m;
  o.robosense.decoder.nominal_until_difop = true;
  return o;
}

TEST(Lidar3dStream, ChannelsByTheConfiguredPorts) {
  StreamOptions o = options();
  o.ports = {3000, 3001, 3002};
  const Stream s(o);
  EXPECT_EQ(s.channel_of(3000), Channel::VelodyneData);
  EXPECT_EQ(s.channel_of(3001), Channel::Msop);
  EXPECT_EQ(s.channel_of(3002), Channel::Difop);
  EXPECT_FALSE(s.channel_of(2368).has_value());
}

TEST(Lidar3dStream, AutoTellsAnRs32FromItsMsopAndSaysWhy) {
  Stream s(options());
  std::vector<LidarFrame> done;
  EXPECT_EQ(s.family(), Family::Undecided);
  EXPECT_FALSE(s.model().has_value());
  EXPECT_TRUE(s.ring_elevations_deg().empty());
  // The DIFOP first: kept for the MSOP to come, the sensor still undecided.
  EXPECT_EQ(s.push(Channel::Difop, DifopBuilder{}.span(), Stamp{1}, done), Outcome::Info);
  EXPECT_EQ(s.family(), Family::Undecided);
  EXPECT_EQ(s.push(Channel::Msop, msop(0), Stamp{2}, done), Outcome::Data);
  EXPECT_EQ(s.model(), Model::RS32);
  EXPECT_NE(s.reason().find("MSOP packets on port 6699"), std::string::npos) << s.reason();
  EXPECT_NE(s.reason().find("model byte 0x02"), std::string::npos) << s.reason();
  const Counters c = s.counters();
  EXPECT_EQ(c.data_packets, 1U);
  EXPECT_EQ(c.decoded, 1U);
  EXPECT_EQ(c.info_packets, 1U);
  EXPECT_EQ(c.points, 12U * 32U);
  // The rings' elevations are the DIFOP's table, lowest first.
  std::vector<double> want(rs::test::kExampleVertDeg.begin(), rs::test::kExampleVertDeg.end());
  std::sort(want.begin(), want.end());
  const std::vector<double> got = s.ring_elevations_deg();
  ASSERT_EQ(got.size(), 32U);
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], want[i], 1e-9) << i;
  // A Velodyne packet now is another family's: counted, dropped.
  EXPECT_EQ(s.push(Channel::VelodyneData, hdl32e(0), Stamp{3}, done), Outcome::OtherFamily);
  EXPECT_EQ(s.counters().other_family, 1U);
  EXPECT_EQ(s.counters().data_packets, 1U);
}

TEST(Lidar3dStream, Rs32DecodesWithNominalAnglesUntilItsDifop) {
  Stream s(options());
  std::vector<LidarFrame> done;
  EXPECT_EQ(s.push(Channel::Msop, msop(0), Stamp{1}, done), Outcome::Data);
  EXPECT_EQ(s.counters().decoded, 1U);
  EXPECT_TRUE(s.robosense().decoder().nominal());
  rs::Calibration unit = rs::test::example_calibration();
  unit.vert_deg[0] += 0.4;  // this unit's own table differs from the nominal one
  s.push(Channel::Difop, DifopBuilder{unit}.span(), Stamp{2}, done);
  EXPECT_FALSE(s.robosense().decoder().nominal());
  EXPECT_EQ(s.robosense().decoder().calibration()->vert_deg[0], unit.vert_deg[0]);
  EXPECT_EQ(s.robosense().counters().difop_angle_changes, 0U);  // the nominal table gave way: no change counted
}

TEST(Lidar3dStream, OtherRoboSenseModelsAreRefusedAndNamed) {
  struct Case {
    std::uint8_t model_byte;
    const char* name;
  };
  for (const Case c : {Case{0x01, "RS-LiDAR-16"}, Case{0x03, "RS-Bpearl"}, Case{0x04, "RS-Ruby"},
                       Case{0x06, "RS-Helios"}, Case{0x00, ""}, Case{0x7F, ""}}) {
    Stream s(options());
    std::vector<LidarFrame> done;
    EXPECT_EQ(s.push(Channel::Msop, msop(0, c.model_byte), Stamp{1}, done), Outcome::Refused) << c.name;
    EXPECT_EQ(s.family(), Family::Undecided);
    EXPECT_EQ(s.counters().refused, 1U);
    EXPECT_EQ(s.counters().data_packets, 0U);
    ASSERT_TRUE(s.refused_as().has_value());
    EXPECT_EQ(s.refused_as()->name, c.name);
    EXPECT_FALSE(s.refused_as()->rs32);
  }
  // The Helios family's own header.
  std::vector<std::uint8_t> helios = msop(0);
  helios[3] = 0x5A;
  EXPECT_EQ(identify_msop(helios).name, "RS-Helios");
  EXPECT_FALSE(identify_msop(helios).msop_header);
  // Not a RoboSense header at all.
  EXPECT_FALSE(identify_msop(hdl32e(0)).msop_header);
  EXPECT_EQ(identify_msop(hdl32e(0)).name, "");
}

TEST(Lidar3dStream, ConfiguredRs32TakesAnUnsetModelByteButNeverAnotherModel) {
  Stream s(options(Model::RS32));
  EXPECT_EQ(s.model(), Model::RS32);
  std::vector<LidarFrame> done;
  EXPECT_EQ(s.push(Channel::Msop, msop(0, 0x00), Stamp{1}, done), Outcome::Data);
  EXPECT_EQ(s.push(Channel::Msop, msop(1, 0x01), Stamp{2}, done), Outcome::Refused);
  EXPECT_EQ(s.push(Channel::VelodyneData, hdl32e(0), Stamp{3}, done), Outcome::OtherFamily);
  EXPECT_EQ(s.counters().decoded, 1U);
  EXPECT_EQ(s.counters().refused, 1U);
  EXPECT_EQ(s.counters().other_family, 1U);
}

TEST(Lidar3dStream, AutoTellsAVelodyneAndDropsRoboSenseAfter) {
  Stream s(options());
  std::vector<LidarFrame> done;
  for (std::size_t k = 0; k < 40; ++k)
    EXPECT_EQ(s.push(Channel::VelodyneData, hdl32e(k), Stamp{1}, done), Outcome::Data);
  EXPECT_EQ(s.family(), Family::Velodyne);
  EXPECT_EQ(s.model(), Model::HDL32E);
  EXPECT_NE(s.reason().find("port 2368"), std::string::npos) << s.reason();
  EXPECT_EQ(s.ring_elevations_deg().size(), 32U);
  EXPECT_EQ(s.push(Channel::Msop, msop(0), Stamp{2}, done), Outcome::OtherFamily);
  EXPECT_EQ(s.push(Channel::Difop, DifopBuilder{}.span(), Stamp{2}, done), Outcome::OtherFamily);
  EXPECT_EQ(s.counters().other_family, 2U);
  EXPECT_EQ(s.counters().info_packets, 0U);
}

TEST(Lidar3dStream, WrongLengthOnEveryPortIsCounted) {
  Stream s(options());
  std::vector<LidarFrame> done;
  const std::vector<std::uint8_t> short_packet(100, 0xFF);
  EXPECT_EQ(s.push(Channel::VelodyneData, short_packet, Stamp{1}, done), Outcome::BadLength);
  EXPECT_EQ(s.push(Channel::Msop, short_packet, Stamp{1}, done), Outcome::BadLength);
  EXPECT_EQ(s.push(Channel::Difop, short_packet, Stamp{1}, done), Outcome::BadLength);
  EXPECT_EQ(s.counters().bad_length, 3U);
  EXPECT_EQ(s.family(), Family::Undecided);
}

TEST(Lidar3dStream, ModelNames) {
  EXPECT_EQ(to_string(Model::Auto), "auto");
  EXPECT_EQ(to_string(Model::HDL32E), "HDL-32E");
  EXPECT_EQ(to_string(Model::VLP16), "VLP-16");
  EXPECT_EQ(to_string(Model::RS32), "RS-32");
}

}  // namespace
}  // namespace fieldguard::lidar3d
