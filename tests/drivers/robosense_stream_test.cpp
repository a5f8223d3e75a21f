// RoboSense RS-32 stream: waiting for DIFOP, rotations cut from synthetic packets, counters.
#include "fieldguard/drivers/robosense_stream.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "drivers/robosense_test_support.hpp"

namespace fieldguard::robosense {
namespace {

using test::DifopBuilder;
using test::MsopBuilder;

constexpr double kPacketUs = 12 * kBlockDurationUs;  // 666.24 us at any rpm in single return
constexpr std::int64_t kT0Us = test::kExampleUnixUs;

// Packet k of a sensor turning at 600 rpm (20 cdeg a block), first block at first_cdeg.
std::vector<std::uint8_t> packet(std::size_t k, int first_cdeg) {
  MsopBuilder m;
  m.azimuths(first_cdeg + static_cast<int>(k) * 240, 20).all_channels(2000, 9);
  m.time_us(kT0Us + std::llround(static_cast<double>(k) * kPacketUs));
  return m.bytes();
}

TEST(RoboSenseStream, RefusesDataUntilTheFirstDifop) {
  Stream s;
  std::vector<LidarFrame> frames;
  for (std::size_t k = 0; k < 3; ++k) s.push_msop(packet(k, 0), Stamp{1}, frames);
  EXPECT_EQ(s.counters().msop_errors[static_cast<std::size_t>(DecodeError::NoCalibration)], 3U);
  s.push_difop(DifopBuilder{}.span());
  EXPECT_EQ(s.counters().difop_accepted, 1U);
  ASSERT_TRUE(s.last_difop().has_value());
  s.push_msop(packet(3, 0), Stamp{2}, frames);
  EXPECT_EQ(s.counters().msop_decoded, 1U);
  EXPECT_EQ(s.counters().points, kBlocksPerPacket * kChannels);
  EXPECT_EQ(s.counters().msop_rejected(), 3U);
}

TEST(RoboSenseStream, RotationsFromSyntheticPackets) {
  Stream s;
  // No horizontal corrections, so that every packet falls wholly on one side of the cut and the counts are exact.
  Calibration cal = test::example_calibration();
  cal.horiz_deg = {};
  s.push_difop(DifopBuilder{cal}.span());
  std::vector<LidarFrame> frames;
  // Starting at 300 deg: 25 packets to the cut at 0 deg, 150 packets a turn; 365 packets = partial, 2 full, partial.
  constexpr std::size_t kPackets = 365;
  for (std::size_t k = 0; k < kPackets; ++k) {
    s.push_msop(packet(k, 30000), Stamp{static_cast<std::int64_t>(k) * 1000 + 5}, frames);
  }
  s.finish(frames);
  ASSERT_EQ(frames.size(), 4U);
  const std::size_t per_packet = kBlocksPerPacket * kChannels;
  EXPECT_TRUE(frames[0].partial);
  EXPECT_EQ(frames[0].packets, 25U);
  for (std::size_t f = 1; f <= 2; ++f) {
    EXPECT_FALSE(frames[f].partial);
    EXPECT_EQ(frames[f].index, f);
    EXPECT_EQ(frames[f].packets, 150U);
    EXPECT_EQ(frames[f].points.size(), 150 * per_packet);
    const std::size_t first = 25 + (f - 1) * 150;
    EXPECT_EQ(frames[f].sensor_stamp.ns, (kT0Us + std::llround(static_cast<double>(first) * kPacketUs)) * 1000);
    EXPECT_EQ(frames[f].host_stamp.ns, static_cast<std::int64_t>(first) * 1000 + 5);
    // A turn at 600 rpm lasts 0.1 s: the last firing is about 99.9 ms after the first.
    EXPECT_NEAR(frames[f].points.back().time_s, 150 * kPacketUs * 1e-6, 1e-4);
    EXPECT_GE(frames[f].points.front().time_s, 0.F);
  }
  EXPECT_TRUE(frames[3].partial);
  EXPECT_EQ(frames[3].packets, 40U);
  s.recycle(std::move(frames[1]));  // accepted back; the next rotation may reuse its buffer
  const auto& c = s.counters();
  EXPECT_EQ(c.msop_decoded, kPackets);
  EXPECT_EQ(c.points, kPackets * per_packet);
  EXPECT_EQ(c.full_rotations, 2U);
  EXPECT_EQ(c.partial_rotations, 2U);
  EXPECT_EQ(c.msop_rejected(), 0U);
}

TEST(RoboSenseStream, DifopCounters) {
  Stream s;
  std::vector<std::uint8_t> bad = DifopBuilder{}.bytes();
  bad[0] = 0x00;
  s.push_difop(bad);
  s.push_difop(DifopBuilder{}.fill_table(468, 0xFF).span());
  EXPECT_FALSE(s.decoder().ready());
  s.push_difop(DifopBuilder{}.span());
  EXPECT_TRUE(s.decoder().ready());
  Calibration other = test::example_calibration();
  other.horiz_deg[7] = 0.5;
  s.push_difop(DifopBuilder{other}.span());
  const auto& c = s.counters();
  EXPECT_EQ(c.difop_packets, 4U);
  EXPECT_EQ(c.difop_accepted, 3U);
  EXPECT_EQ(c.difop_errors[static_cast<std::size_t>(DecodeError::BadMagic)], 1U);
  EXPECT_EQ(c.difop_rejected(), 1U);
  EXPECT_EQ(c.difop_without_angles, 1U);
  EXPECT_EQ(c.difop_angle_changes, 1U);
  EXPECT_EQ(*s.decoder().calibration(), *parse_difop(DifopBuilder{}.span())->calibration);  // the first table stays
}

TEST(RoboSenseStream, DualReturnFromDifop) {
  Stream s;
  s.push_difop(DifopBuilder{}.return_mode(0).span());
  MsopBuilder m;
  m.azimuths(1000, 20, true).channel(0, 0, 2000, 1).channel(1, 0, 2400, 1);
  std::vector<LidarFrame> frames;
  s.push_msop(m.span(), Stamp{1}, frames);
  s.finish(frames);
  ASSERT_EQ(frames.size(), 1U);
  ASSERT_EQ(frames[0].points.size(), 2U);
  EXPECT_EQ(frames[0].points[0].return_type, ReturnType::Strongest);
  EXPECT_EQ(frames[0].points[1].return_type, ReturnType::Last);
}

}  // namespace
}  // namespace fieldguard::robosense
