// RoboSense RS-32 MSOP decoding: the worked examples of protocols.md §2.6 and packets built from §2.2.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "drivers/robosense_test_support.hpp"
#include "fieldguard/drivers/robosense.hpp"

namespace fieldguard::robosense {
namespace {

using test::DifopBuilder;
using test::MsopBuilder;

constexpr double kRad = std::numbers::pi / 180.0;

// A decoder that needs no DIFOP: configured table and unit.
Decoder configured(const Calibration& cal, DistanceUnitOption unit = DistanceUnitOption::HalfCm,
                   std::optional<ReturnMode> mode = ReturnMode::Strongest, double offset = kOpticalCentreOffsetM) {
  DecoderOptions o;
  o.calibration = cal;
  o.distance_unit = unit;
  o.return_mode = mode;
  o.optical_centre_offset_m = offset;
  return Decoder(o);
}

Calibration flat() { return Calibration{}; }  // every angle 0

TEST(RoboSenseTime, WorkedExampleIsUtc) {
  const std::vector<std::uint8_t> b = {0x18, 0x03, 0x15, 0x08, 0x1E, 0x0F, 0x00, 0x7B, 0x01, 0xC8};
  const auto t = decode_ymd_time(b);
  ASSERT_TRUE(t.has_value());
  // 2024-03-21 08:30:15 UTC = 1711009815 s (Python calendar.timegm), + 123 ms + 456 us.
  EXPECT_EQ(t->ns, 1'711'009'815'123'456'000LL);
}

TEST(RoboSenseTime, LeapYearsAndRanges) {
  auto at = [](std::uint8_t y, std::uint8_t mo, std::uint8_t d, std::uint8_t h = 0, std::uint8_t mi = 0,
               std::uint8_t s = 0, std::uint16_t ms = 0, std::uint16_t us = 0) {
    const std::vector<std::uint8_t> b = {y,
                                         mo,
                                         d,
                                         h,
                                         mi,
                                         s,
                                         static_cast<std::uint8_t>(ms >> 8),
                                         static_cast<std::uint8_t>(ms),
                                         static_cast<std::uint8_t>(us >> 8),
                                         static_cast<std::uint8_t>(us)};
    return decode_ymd_time(b);
  };
  EXPECT_EQ(at(0, 1, 1)->ns, 946'684'800'000'000'000LL);      // 2000-01-01, a leap year divisible by 400
  EXPECT_EQ(at(24, 2, 29)->ns, 1'709'164'800'000'000'000LL);  // 2024-02-29
  EXPECT_EQ(at(23, 12, 31, 23, 59, 59, 999, 999)->ns, 1'704'067'199'999'999'000LL);
  EXPECT_FALSE(at(23, 2, 29).has_value());
  EXPECT_FALSE(at(24, 0, 1).has_value());
  EXPECT_FALSE(at(24, 13, 1).has_value());
  EXPECT_FALSE(at(24, 4, 31).has_value());
  EXPECT_FALSE(at(24, 1, 0).has_value());
  EXPECT_FALSE(at(24, 1, 1, 24).has_value());
  EXPECT_FALSE(at(24, 1, 1, 0, 60).has_value());
  EXPECT_FALSE(at(24, 1, 1, 0, 0, 61).has_value());
  EXPECT_FALSE(at(24, 1, 1, 0, 0, 0, 1000).has_value());
  EXPECT_FALSE(at(24, 1, 1, 0, 0, 0, 0, 1000).has_value());
}

TEST(RoboSenseAngle, ManualTriplets) {
  EXPECT_EQ(decode_angle_millideg(std::vector<std::uint8_t>{0x01, 0x28, 0x29}), -10281);  // -10.281 deg
  EXPECT_EQ(decode_angle_millideg(std::vector<std::uint8_t>{0x01, 0x0A, 0x70}), -2672);   // manual B.14
  EXPECT_EQ(decode_angle_millideg(std::vector<std::uint8_t>{0x00, 0x3A, 0xAE}), 15022);
  EXPECT_FALSE(decode_angle_millideg(std::vector<std::uint8_t>{0xFF, 0xFF, 0xFF}).has_value());
  EXPECT_FALSE(decode_angle_millideg(std::vector<std::uint8_t>{0x02, 0x00, 0x01}).has_value());
}

TEST(RoboSenseMsop, HeaderFields) {
  MsopBuilder m;
  m.azimuths(100, 20);
  m.bytes()[30] = 0x04;
  m.bytes()[38] = 0x18;
  m.bytes()[39] = 0x81;  // rs_driver's parseTemp example: -35 LSB
  const auto h = read_msop_header(m.span());
  ASSERT_TRUE(h.has_value());
  EXPECT_EQ(h->sensor_time.ns, test::kExampleUnixUs * 1000);
  EXPECT_EQ(h->model_byte, 0x04);
  EXPECT_FLOAT_EQ(h->temperature_c, -35.F * 0.0625F);
  EXPECT_EQ(h->azimuth_cdeg[11], 100 + 11 * 20);
  EXPECT_FALSE(h->dual_layout);
}

TEST(RoboSenseMsop, WorkedExampleDistanceNewFirmware) {
  const Decoder d = configured(flat(), DistanceUnitOption::HalfCm, ReturnMode::Strongest, 0.0);
  MsopBuilder m;
  m.azimuths(21469, 20).channel(0, 0, 0x8348, 77);
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(d.decode(m.span(), pts).has_value());
  ASSERT_EQ(pts.size(), 1U);
  EXPECT_NEAR(pts[0].range_m, 168.04, 1e-4);  // 33608 x 0.5 cm
  EXPECT_EQ(pts[0].azimuth_cdeg, 21469);      // channel 0 fires first: no interpolation
  EXPECT_NEAR(pts[0].x, 168.04 * std::cos(214.69 * kRad), 1e-3);
  EXPECT_NEAR(pts[0].y, -168.04 * std::sin(214.69 * kRad), 1e-3);
  EXPECT_FLOAT_EQ(pts[0].intensity, 77.F);
}

TEST(RoboSenseMsop, WorkedExampleDistanceOldFirmware) {
  // 83 48 in slot 0: group flag 1 (B) and 0x0348 = 840 cm; in a B block slot 0 carries channel 16.
  const Decoder d = configured(flat(), DistanceUnitOption::OneCmGrouped, ReturnMode::Strongest, 0.0);
  MsopBuilder m;
  m.azimuths(21469, 20).channel(0, 0, 0x8348, 10).channel(0, 16, 0x8000 | 500, 20);
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(d.decode(m.span(), pts).has_value());
  ASSERT_EQ(pts.size(), 2U);
  // Channel order: channel 0 (from slot 16, 5.00 m) then channel 16 (from slot 0, 8.40 m).
  EXPECT_NEAR(pts[0].range_m, 5.00, 1e-5);
  EXPECT_FLOAT_EQ(pts[0].intensity, 20.F);
  EXPECT_NEAR(pts[1].range_m, 8.40, 1e-5);
  EXPECT_FLOAT_EQ(pts[1].intensity, 10.F);
  EXPECT_NEAR(pts[1].time_s, 1.44e-6, 1e-9);  // channel 16's firing offset
}

TEST(RoboSenseMsop, GroupABlockIsNotSwapped) {
  const Decoder d = configured(flat(), DistanceUnitOption::OneCmGrouped, ReturnMode::Strongest, 0.0);
  MsopBuilder m;
  m.azimuths(0, 20).channel(0, 0, 0x0348, 10);
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(d.decode(m.span(), pts).has_value());
  ASSERT_EQ(pts.size(), 1U);
  EXPECT_NEAR(pts[0].range_m, 8.40, 1e-5);
  EXPECT_FLOAT_EQ(pts[0].time_s, 0.F);  // channel 0
}

// A whole packet with three returns, checked against the point formula of protocols.md §2.2 computed here.
TEST(RoboSenseMsop, FullPacketToKnownCoordinates) {
  Calibration cal = test::example_calibration();
  cal.vert_deg[0] = 0.0;
  cal.horiz_deg[0] = 0.0;
  cal.vert_deg[16] = -10.281;
  cal.horiz_deg[16] = 1.5;
  const Decoder d = configured(cal);
  MsopBuilder m;
  m.azimuths(9000, 20).channel(0, 0, 2000, 5).channel(1, 16, 0x8348, 6).channel(11, 31, 1000, 7);
  std::vector<LidarPoint> pts;
  const auto h = d.decode(m.span(), pts);
  ASSERT_TRUE(h.has_value());
  ASSERT_EQ(pts.size(), 3U);
  constexpr double kR = 0.03997;

  // Block 0 channel 0: 10 m at 90 deg clockwise = to the right: y negative, plus the optical-centre offset.
  EXPECT_NEAR(pts[0].x, 0.0, 1e-5);
  EXPECT_NEAR(pts[0].y, -10.0 - kR, 1e-5);
  EXPECT_NEAR(pts[0].z, 0.0, 1e-6);
  EXPECT_EQ(pts[0].azimuth_cdeg, 9000);
  EXPECT_FLOAT_EQ(pts[0].time_s, 0.F);
  EXPECT_EQ(pts[0].return_type, ReturnType::Strongest);

  // Block 1 channel 16: fires 55.52 + 1.44 us after the packet time; azimuth interpolated, then corrected.
  {
    const double a0 = (9020.0 + 20.0 * 1.44 / 55.52) / 100.0;
    const double a = a0 + 1.5;
    const double w = -10.281;
    const double dist = 168.04;
    EXPECT_NEAR(pts[1].x, dist * std::cos(w * kRad) * std::cos(a * kRad) + kR * std::cos(a0 * kRad), 1e-3);
    EXPECT_NEAR(pts[1].y, -dist * std::cos(w * kRad) * std::sin(a * kRad) - kR * std::sin(a0 * kRad), 1e-3);
    EXPECT_NEAR(pts[1].z, dist * std::sin(w * kRad), 1e-3);
    EXPECT_EQ(pts[1].azimuth_cdeg, static_cast<std::uint16_t>(std::lround(a * 100.0)));
    EXPECT_NEAR(pts[1].time_s, (55.52 + 1.44) * 1e-6, 1e-10);
    EXPECT_NEAR(pts[1].range_m, 168.04, 1e-4);
    EXPECT_FLOAT_EQ(pts[1].intensity, 6.F);
  }
  // Block 11 channel 31: the last firing of the packet; the last block reuses the previous azimuth step.
  {
    const double a0 = (9000.0 + 11 * 20.0 + 20.0 * 46.08 / 55.52) / 100.0;
    const double a = a0 + cal.horiz_deg[31];
    const double w = cal.vert_deg[31];
    EXPECT_NEAR(pts[2].x, 5.0 * std::cos(w * kRad) * std::cos(a * kRad) + kR * std::cos(a0 * kRad), 1e-4);
    EXPECT_NEAR(pts[2].y, -5.0 * std::cos(w * kRad) * std::sin(a * kRad) - kR * std::sin(a0 * kRad), 1e-4);
    EXPECT_NEAR(pts[2].z, 5.0 * std::sin(w * kRad), 1e-4);
    EXPECT_NEAR(pts[2].time_s, (11 * 55.52 + 46.08) * 1e-6, 1e-10);
  }
  EXPECT_EQ(h->sensor_time.ns, test::kExampleUnixUs * 1000);
}

TEST(RoboSenseMsop, RingsRankChannelsByElevation) {
  const Decoder d = configured(test::example_calibration());
  MsopBuilder m;
  m.azimuths(0, 20).all_channels(2000, 1);
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(d.decode(m.span(), pts).has_value());
  ASSERT_EQ(pts.size(), kBlocksPerPacket * kChannels);
  EXPECT_EQ(pts[16].ring, 0);   // -25.00 deg, the lowest beam
  EXPECT_EQ(pts[18].ring, 1);   // -14.64
  EXPECT_EQ(pts[14].ring, 31);  // +15.02, the highest
  std::vector<bool> seen(kChannels, false);
  for (std::size_t c = 0; c < kChannels; ++c) seen[pts[c].ring] = true;
  EXPECT_EQ(std::count(seen.begin(), seen.end(), true), 32);
}

TEST(RoboSenseMsop, DualReturnPairsAndLabels) {
  const Decoder d = configured(flat(), DistanceUnitOption::HalfCm, ReturnMode::Dual, 0.0);
  MsopBuilder m;
  m.azimuths(1000, 20, true);
  m.channel(0, 0, 2000, 1).channel(1, 0, 3000, 2);  // last return farther than the strongest
  m.channel(0, 1, 3000, 3).channel(1, 1, 2000, 4);  // nearer second: the strongest was also the last
  m.channel(0, 2, 2500, 5).channel(1, 2, 2500, 5);  // one return only
  m.channel(2, 0, 1000, 6);                         // second pair, strongest only
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(d.decode(m.span(), pts).has_value());
  ASSERT_EQ(pts.size(), 6U);
  EXPECT_EQ(pts[0].return_type, ReturnType::Strongest);
  EXPECT_EQ(pts[1].return_type, ReturnType::Last);
  EXPECT_NEAR(pts[1].range_m, 15.0, 1e-5);
  EXPECT_EQ(pts[2].return_type, ReturnType::Strongest);
  EXPECT_EQ(pts[3].return_type, ReturnType::SecondStrongest);
  EXPECT_EQ(pts[4].return_type, ReturnType::StrongestAndLast);
  EXPECT_EQ(pts[5].return_type, ReturnType::Strongest);
  EXPECT_NEAR(pts[5].time_s, 55.52e-6, 1e-10);  // pair 1 fires one block duration after pair 0
  EXPECT_EQ(pts[5].azimuth_cdeg, 1020);
  EXPECT_EQ(pts[0].time_s, pts[1].time_s);
}

TEST(RoboSenseMsop, ReturnModeFromLayoutWhenUnknown) {
  const Decoder d = configured(flat(), DistanceUnitOption::HalfCm, std::nullopt, 0.0);
  MsopBuilder m;
  m.azimuths(1000, 20, true).channel(0, 0, 2000, 1).channel(1, 0, 3000, 2);
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(d.decode(m.span(), pts).has_value());
  ASSERT_EQ(pts.size(), 2U);
  EXPECT_EQ(pts[1].return_type, ReturnType::Last);
}

TEST(RoboSenseMsop, RangeLimits) {
  const Decoder d = configured(flat());
  MsopBuilder m;
  m.azimuths(0, 20).channel(0, 0, 0, 1).channel(0, 1, 79, 1).channel(0, 2, 81, 1).channel(0, 3, 45999, 1);
  m.channel(0, 4, 46001, 1);
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(d.decode(m.span(), pts).has_value());
  ASSERT_EQ(pts.size(), 2U);  // 0.405 m and 229.995 m kept; 0 (no return), 0.395 m and 230.005 m dropped
  EXPECT_NEAR(pts[0].range_m, 0.405, 1e-6);
  EXPECT_NEAR(pts[1].range_m, 229.995, 1e-4);
}

TEST(RoboSenseMsop, AzimuthWrapsAndBlindZoneKeepsTheStep) {
  const Decoder d = configured(flat(), DistanceUnitOption::HalfCm, ReturnMode::Strongest, 0.0);
  MsopBuilder m;
  m.azimuths(35960, 20).all_channels(2000, 1);
  m.azimuth(6, 5000).azimuth(7, 5020);  // a jump (FOV blind zone): block 5 keeps the 20 cdeg step
  for (std::size_t k = 8; k < kBlocksPerPacket; ++k) m.azimuth(k, static_cast<std::uint16_t>(5020 + 20 * (k - 7)));
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(d.decode(m.span(), pts).has_value());
  ASSERT_EQ(pts.size(), kBlocksPerPacket * kChannels);
  const auto at = [&](std::size_t block, std::size_t ch) { return pts[block * kChannels + ch]; };
  EXPECT_EQ(at(0, 0).azimuth_cdeg, 35960);
  EXPECT_EQ(at(1, 31).azimuth_cdeg, static_cast<std::uint16_t>(std::lround(35980 + 20 * 46.08 / 55.52)));
  EXPECT_EQ(at(2, 0).azimuth_cdeg, 0);
  EXPECT_EQ(at(5, 31).azimuth_cdeg, static_cast<std::uint16_t>(std::lround(60 + 20 * 46.08 / 55.52)));
  for (const auto& p : pts) EXPECT_LT(p.azimuth_cdeg, 36000);
}

TEST(RoboSenseDecoder, WaitsForDifop) {
  Decoder d;
  EXPECT_FALSE(d.ready());
  MsopBuilder m;
  m.azimuths(0, 20).all_channels(2000, 1);
  std::vector<LidarPoint> pts;
  const auto r = d.decode(m.span(), pts);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error(), DecodeError::NoCalibration);
  EXPECT_TRUE(pts.empty());

  const auto difop = parse_difop(DifopBuilder{}.span());
  ASSERT_TRUE(difop.has_value());
  EXPECT_FALSE(d.apply(*difop));
  EXPECT_TRUE(d.ready());
  EXPECT_EQ(d.distance_unit(), DistanceUnit::HalfCm);
  EXPECT_EQ(d.return_mode(), ReturnMode::Strongest);
  ASSERT_TRUE(d.decode(m.span(), pts).has_value());
  EXPECT_EQ(pts.size(), kBlocksPerPacket * kChannels);
}

TEST(RoboSenseDecoder, AutoUnitWaitsForDifopEvenWithConfiguredAngles) {
  DecoderOptions o;
  o.calibration = test::example_calibration();
  Decoder d(o);
  EXPECT_FALSE(d.ready());
  DifopBuilder old;
  old.firmware({0x00, 0x00, 0x00, 0x00, 0x00});  // bytes 41..43 all zero: old firmware (ros_rslidar)
  Calibration other = test::example_calibration();
  other.vert_deg[3] = 1.0;
  old.angles(other);
  const auto difop = parse_difop(old.span());
  ASSERT_TRUE(difop.has_value());
  EXPECT_TRUE(d.apply(*difop));  // its table differs from the configured one, which stays
  EXPECT_TRUE(d.ready());
  EXPECT_EQ(d.distance_unit(), DistanceUnit::OneCmGrouped);
  EXPECT_EQ(*d.calibration(), test::example_calibration());
}

TEST(RoboSenseDecoder, ImpossibleConfigurationThrows) {
  DecoderOptions o;
  o.calibration = flat();
  o.calibration->vert_deg[5] = 95.0;
  EXPECT_THROW(Decoder{o}, std::invalid_argument);
  o.calibration->vert_deg[5] = std::nan("");
  EXPECT_THROW(Decoder{o}, std::invalid_argument);
  DecoderOptions r;
  r.min_range_m = 10.0;
  r.max_range_m = 5.0;
  EXPECT_THROW(Decoder{r}, std::invalid_argument);
}

}  // namespace
}  // namespace fieldguard::robosense
