// RoboSense RS-32 DIFOP parsing (protocols.md §2.3) and the firmware rule for the distance unit.
#include <gtest/gtest.h>

#include "drivers/robosense_test_support.hpp"
#include "fieldguard/drivers/robosense.hpp"

namespace fieldguard::robosense {
namespace {

using test::DifopBuilder;

TEST(RoboSenseDifop, ParsesTheDocumentedFields) {
  const auto d = parse_difop(DifopBuilder{}.span());
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->rpm, 600);
  EXPECT_EQ(d->fov_start_cdeg, 0);
  EXPECT_EQ(d->fov_end_cdeg, 36000);
  EXPECT_EQ(d->top_firmware, (std::array<std::uint8_t, 5>{0x09, 0x23, 0x09, 0x06, 0xA1}));
  EXPECT_EQ(d->serial, (std::array<std::uint8_t, 6>{0x10, 0x11, 0x12, 0x13, 0x14, 0x15}));
  EXPECT_EQ(d->return_mode_byte, 1);
  EXPECT_EQ(d->return_mode, ReturnMode::Strongest);
  ASSERT_TRUE(d->utc_time.has_value());
  EXPECT_EQ(d->utc_time->ns, test::kExampleUnixUs * 1000);
  EXPECT_EQ(d->distance_unit, DistanceUnit::HalfCm);
  ASSERT_TRUE(d->calibration.has_value());
  const Calibration want = test::example_calibration();
  for (std::size_t c = 0; c < kChannels; ++c) {
    EXPECT_NEAR(d->calibration->vert_deg[c], want.vert_deg[c], 1e-9) << c;
    EXPECT_NEAR(d->calibration->horiz_deg[c], want.horiz_deg[c], 1e-9) << c;
  }
}

TEST(RoboSenseDifop, ManualAngleExample) {
  DifopBuilder b;
  b.triplet(468, 0, 0x01, 0x2829);  // 01 28 29: -10.281 deg (manual B.13)
  b.triplet(564, 9, 0x01, 0x0A70);  // 01 0A 70: -2.672 deg (manual B.14)
  const auto d = parse_difop(b.span());
  ASSERT_TRUE(d.has_value() && d->calibration.has_value());
  EXPECT_DOUBLE_EQ(d->calibration->vert_deg[0], -10.281);
  EXPECT_DOUBLE_EQ(d->calibration->horiz_deg[9], -2.672);
}

TEST(RoboSenseDifop, ReturnModes) {
  const auto mode = [](std::uint8_t byte) { return parse_difop(DifopBuilder{}.return_mode(byte).span())->return_mode; };
  EXPECT_EQ(mode(0), ReturnMode::Dual);
  EXPECT_EQ(mode(1), ReturnMode::Strongest);
  EXPECT_EQ(mode(2), ReturnMode::Last);
  EXPECT_EQ(mode(7), ReturnMode::Strongest);  // unknown: single return, as rs_driver
}

TEST(RoboSenseDifop, FirmwareDecidesTheDistanceUnit) {
  const auto unit = [](std::array<std::uint8_t, 5> top) {
    return parse_difop(DifopBuilder{}.firmware(top).span())->distance_unit;
  };
  EXPECT_EQ(unit({0x00, 0x00, 0x00, 0x00, 0x00}), DistanceUnit::OneCmGrouped);
  EXPECT_EQ(unit({0x12, 0xFF, 0xFF, 0xFF, 0x34}), DistanceUnit::OneCmGrouped);
  EXPECT_EQ(unit({0x00, 0x55, 0xAA, 0x5A, 0x00}), DistanceUnit::OneCmGrouped);
  EXPECT_EQ(unit({0x00, 0xE9, 0x01, 0x00, 0x00}), DistanceUnit::OneCmGrouped);
  EXPECT_EQ(unit({0x00, 0x00, 0x00, 0x01, 0x00}), DistanceUnit::HalfCm);
  EXPECT_EQ(unit({0x09, 0x23, 0x09, 0x06, 0xA1}), DistanceUnit::HalfCm);
  EXPECT_EQ(distance_unit_from_firmware(0xE9, 0x01, 0x00), DistanceUnit::OneCmGrouped);
  EXPECT_EQ(distance_unit_from_firmware(0xE9, 0x01, 0x01), DistanceUnit::HalfCm);
}

TEST(RoboSenseDifop, UnwrittenTableMeansNoCalibration) {
  for (std::uint8_t fill : {std::uint8_t{0x00}, std::uint8_t{0xFF}}) {
    const auto d = parse_difop(DifopBuilder{}.fill_table(468, fill).span());
    ASSERT_TRUE(d.has_value());
    EXPECT_FALSE(d->calibration.has_value());
  }
}

TEST(RoboSenseDifop, OutOfRangeTimeIsNotAnError) {
  DifopBuilder b;
  b.bytes()[304] = 13;  // month 13
  const auto d = parse_difop(b.span());
  ASSERT_TRUE(d.has_value());
  EXPECT_FALSE(d->utc_time.has_value());
}

TEST(RoboSenseDifop, AMsopPacketIsNotADifop) {
  const test::MsopBuilder m;
  const auto d = parse_difop(m.span());
  ASSERT_FALSE(d.has_value());
  EXPECT_EQ(d.error(), DecodeError::BadMagic);
  const auto h = read_msop_header(DifopBuilder{}.span());
  ASSERT_FALSE(h.has_value());
  EXPECT_EQ(h.error(), DecodeError::BadMagic);
}

}  // namespace
}  // namespace fieldguard::robosense
