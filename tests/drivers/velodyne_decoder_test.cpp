#include "fieldguard/drivers/velodyne_decoder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <stdexcept>

#include "drivers/velodyne_test_support.hpp"

namespace fieldguard::velodyne {
namespace {

using test::PacketBuilder;

Decoder make_decoder(Model m, TimestampReference ref = TimestampReference::FirstFiring) {
  DecoderOptions o;
  o.model = m;
  o.timestamp_reference = ref;
  return Decoder(default_calibration(m), o);
}

double deg2rad(double d) { return d * std::numbers::pi / 180.0; }

// protocols.md §1.11: the worked example, built byte by byte.
PacketBuilder worked_example() {
  PacketBuilder p;
  p.azimuths(23165, 16).slot(0, 3, 0x2710, 100).timestamp(0x499602D2).factory(0x37, 0x21);
  return p;
}

TEST(VelodyneDecoder, WorkedExampleHeader) {
  const auto p = worked_example();
  EXPECT_EQ(p.span()[0], 0xFF);
  EXPECT_EQ(p.span()[2], 0x7D);
  EXPECT_EQ(p.span()[3], 0x5A);
  EXPECT_EQ(p.span()[13], 0x10);
  EXPECT_EQ(p.span()[14], 0x27);
  EXPECT_EQ(p.span()[15], 0x64);
  const auto h = read_packet_header(p.span());
  ASSERT_TRUE(h.has_value());
  EXPECT_EQ(h->timestamp_us, 1'234'567'890U);
  EXPECT_EQ(h->return_mode, ReturnMode::Strongest);
  EXPECT_EQ(h->product_byte, 0x21);
  EXPECT_FALSE(h->dual_layout);
  EXPECT_EQ(h->first_azimuth_cdeg, 23165);
  EXPECT_EQ(h->last_azimuth_cdeg, 23165 + 11 * 16);
}

TEST(VelodyneDecoder, WorkedExamplePoint) {
  const auto p = worked_example();
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(make_decoder(Model::HDL32E).decode(p.span(), pts).has_value());
  ASSERT_EQ(pts.size(), 1U);
  const LidarPoint& q = pts[0];
  EXPECT_NEAR(q.range_m, 20.000, 1e-5);
  EXPECT_EQ(q.intensity, 100.F);
  EXPECT_EQ(q.ring, 17);  // -8.00 deg is the 18th angle from the bottom
  EXPECT_EQ(q.return_type, ReturnType::Strongest);
  // Slot 3 fires 3.456 us after slot 0; the azimuth moves 16 * 3.456 / 46.08 = 1.2 cdeg in that time (231.662 deg).
  EXPECT_NEAR(q.time_s, 3.456e-6, 1e-9);
  EXPECT_EQ(q.azimuth_cdeg, 23166);
  const double a = deg2rad(231.662);
  const double w = deg2rad(-8.0);
  EXPECT_NEAR(q.x, 20.0 * std::cos(w) * std::cos(a), 2e-4);
  EXPECT_NEAR(q.y, -20.0 * std::cos(w) * std::sin(a), 2e-4);
  // The worked example rounds at the block azimuth 231.65 deg; the interpolation moves the point < 4 mm.
  EXPECT_NEAR(q.x, -12.289, 4e-3);
  EXPECT_NEAR(q.y, 15.532, 4e-3);
  EXPECT_NEAR(q.z, -2.784, 1e-3);
}

TEST(VelodyneDecoder, WorkedExampleLastFiringReference) {
  const auto p = worked_example();
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(make_decoder(Model::HDL32E, TimestampReference::LastFiring).decode(p.span(), pts).has_value());
  ASSERT_EQ(pts.size(), 1U);
  EXPECT_NEAR(pts[0].time_s, (3.456 - 542.592) * 1e-6, 1e-9);
}

// ---- malformed input: each error kind ----

struct BadCase {
  const char* name;
  std::function<void(PacketBuilder&)> mutate;
  Model model;
  DecodeError expected;
  bool header_fails;  // read_packet_header reports it too (else only Decoder::decode does)
};

class VelodyneDecodeErrors : public ::testing::TestWithParam<BadCase> {};

TEST_P(VelodyneDecodeErrors, ReportsTheSpecificError) {
  const BadCase& c = GetParam();
  PacketBuilder p;
  p.azimuths(1000, 20).slot(0, 0, 5000, 7);
  c.mutate(p);
  const auto h = read_packet_header(p.span());
  if (c.header_fails) {
    ASSERT_FALSE(h.has_value());
    EXPECT_EQ(h.error(), c.expected);
  } else {
    EXPECT_TRUE(h.has_value());
  }
  DecoderOptions o;
  o.model = c.model;
  const Decoder d(default_calibration(c.model == Model::Unknown ? Model::HDL32E : c.model), o);
  std::vector<LidarPoint> pts;
  const auto r = d.decode(p.span(), pts);
  ASSERT_FALSE(r.has_value());
  EXPECT_EQ(r.error(), c.expected);
  EXPECT_TRUE(pts.empty());
}

void set_flag(PacketBuilder& p, std::size_t block, std::uint8_t a, std::uint8_t b) {
  p.bytes()[block * kBlockSize] = a;
  p.bytes()[block * kBlockSize + 1] = b;
}

INSTANTIATE_TEST_SUITE_P(
    Malformed, VelodyneDecodeErrors,
    ::testing::Values(BadCase{"Empty", [](PacketBuilder& p) { p.bytes().clear(); }, Model::HDL32E,
                              DecodeError::BadLength, true},
                      BadCase{"OneShort", [](PacketBuilder& p) { p.bytes().pop_back(); }, Model::HDL32E,
                              DecodeError::BadLength, true},
                      BadCase{"OneLong", [](PacketBuilder& p) { p.bytes().push_back(0); }, Model::HDL32E,
                              DecodeError::BadLength, true},
                      BadCase{"PositionPacketSize", [](PacketBuilder& p) { p.bytes().resize(kPositionPacketSize); },
                              Model::HDL32E, DecodeError::BadLength, true},
                      BadCase{"FlagBytesSwapped", [](PacketBuilder& p) { set_flag(p, 0, 0xEE, 0xFF); }, Model::HDL32E,
                              DecodeError::BadBlockFlag, true},
                      BadCase{"LowerBankFlagInLastBlock", [](PacketBuilder& p) { set_flag(p, 11, 0xFF, 0xDD); },
                              Model::HDL32E, DecodeError::BadBlockFlag, true},
                      BadCase{"Azimuth36000", [](PacketBuilder& p) { p.azimuth(5, 36000); }, Model::HDL32E,
                              DecodeError::BadAzimuth, true},
                      BadCase{"AzimuthFFFF", [](PacketBuilder& p) { p.azimuth(11, 0xFFFF); }, Model::VLP16,
                              DecodeError::BadAzimuth, true},
                      BadCase{"UnknownReturnByte", [](PacketBuilder& p) { p.factory(0x40, 0x21); }, Model::HDL32E,
                              DecodeError::BadReturnMode, true},
                      BadCase{"Vlp16ProductOnHdl32", [](PacketBuilder& p) { p.factory(0x37, 0x22); }, Model::HDL32E,
                              DecodeError::ModelMismatch, false},
                      BadCase{"Vlp32cProductOnVlp16", [](PacketBuilder& p) { p.factory(0x37, 0x28); }, Model::VLP16,
                              DecodeError::ModelMismatch, false},
                      BadCase{"ModelNotKnown", [](PacketBuilder&) {}, Model::Unknown, DecodeError::NoModel, false}),
    [](const ::testing::TestParamInfo<BadCase>& i) { return std::string(i.param.name); });

TEST(VelodyneDecoder, ReturnModeFromLayoutWhenByteUnsetOrUnknown) {
  PacketBuilder single;
  single.azimuths(1000, 20).factory(0x00, 0x00);
  ASSERT_TRUE(read_packet_header(single.span()).has_value());
  EXPECT_EQ(read_packet_header(single.span())->return_mode, ReturnMode::Strongest);
  PacketBuilder dual;
  dual.azimuths(1000, 20, true).factory(0x55, 0x21);
  ASSERT_TRUE(read_packet_header(dual.span()).has_value());
  EXPECT_EQ(read_packet_header(dual.span())->return_mode, ReturnMode::Dual);
  EXPECT_TRUE(read_packet_header(dual.span())->dual_layout);
}

TEST(VelodyneDecoder, ConstructorRejectsCalibrationOfTheWrongSize) {
  DecoderOptions o;
  o.model = Model::HDL32E;
  EXPECT_THROW(Decoder(default_calibration(Model::VLP16), o), std::invalid_argument);
  o.model = Model::VLP16;
  EXPECT_THROW(Decoder(default_calibration(Model::HDL32E), o), std::invalid_argument);
}

TEST(VelodyneDecoder, LastReturnModeAndRangeLimits) {
  PacketBuilder p;
  p.azimuths(0, 20).factory(0x38, 0x21);
  p.slot(0, 0, 200, 1);    // 0.4 m < min 0.5: dropped
  p.slot(0, 1, 250, 2);    // 0.5 m: kept
  p.slot(0, 2, 65000, 3);  // 130 m: kept
  p.slot(0, 3, 65001, 4);  // 130.002 m: dropped
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(make_decoder(Model::HDL32E).decode(p.span(), pts).has_value());
  ASSERT_EQ(pts.size(), 2U);
  EXPECT_EQ(pts[0].intensity, 2.F);
  EXPECT_EQ(pts[1].intensity, 3.F);
  EXPECT_EQ(pts[0].return_type, ReturnType::Last);
}

TEST(VelodyneDecoder, AppliesCalibrationCorrections) {
  Calibration cal = default_calibration(Model::HDL32E);
  LaserCorrection& c = cal.lasers[1];  // -9.33 deg
  c.rot_deg = -1.5;                    // the files' sign: subtracted, so -1.5 turns the firing 1.5 degrees clockwise
  c.dist_m = 0.25;
  c.vert_offset_m = 0.02;
  c.horiz_offset_m = -0.03;
  DecoderOptions o;
  o.timestamp_reference = TimestampReference::FirstFiring;
  const Decoder d(cal, o);
  PacketBuilder p;
  p.azimuths(35900, 40).slot(0, 1, 5000, 9);  // 10 m raw
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(d.decode(p.span(), pts).has_value());
  ASSERT_EQ(pts.size(), 1U);
  const LidarPoint& q = pts[0];
  EXPECT_NEAR(q.range_m, 10.25, 1e-5);
  // 359.00 deg + 40 cdeg * 1.152/46.08 - (-1.5 deg) = 0.51 deg, wrapped past 0
  const double az_deg = 359.0 + 0.4 * (1.152 / 46.08) - (-1.5) - 360.0;
  EXPECT_EQ(q.azimuth_cdeg, static_cast<std::uint16_t>(std::lround(az_deg * 100.0)));
  const double a = deg2rad(az_deg);
  const double w = deg2rad(-9.33);
  const double xy = 10.25 * std::cos(w) - 0.02 * std::sin(w);
  EXPECT_NEAR(q.x, xy * std::cos(a) + -0.03 * std::sin(a), 1e-4);
  EXPECT_NEAR(q.y, -xy * std::sin(a) + -0.03 * std::cos(a), 1e-4);
  EXPECT_NEAR(q.z, 10.25 * std::sin(w) + 0.02 * std::cos(w), 1e-4);
}

// ---- dual return ----

TEST(VelodyneDecoder, DualReturnPairs) {
  PacketBuilder p;
  p.azimuths(1000, 40, true).factory(0x39, 0x21);
  p.slot(0, 0, 5000, 50).slot(1, 0, 5000, 50);    // one echo: both blocks equal -> once, StrongestAndLast
  p.slot(0, 1, 6000, 10).slot(1, 1, 4000, 200);   // last 12 m, strongest 8 m
  p.slot(0, 2, 0, 0).slot(1, 2, 3000, 90);        // only the odd block has one
  p.slot(0, 3, 5000, 50).slot(1, 3, 5000, 51);    // same distance, other intensity: two points
  p.slot(10, 31, 7000, 1).slot(11, 31, 7500, 2);  // last pair, last slot
  std::vector<LidarPoint> pts;
  const auto d = make_decoder(Model::HDL32E, TimestampReference::LastFiring);
  const auto h = d.decode(p.span(), pts);
  ASSERT_TRUE(h.has_value());
  EXPECT_EQ(h->return_mode, ReturnMode::Dual);
  ASSERT_EQ(pts.size(), 8U);
  EXPECT_EQ(pts[0].return_type, ReturnType::StrongestAndLast);
  EXPECT_EQ(pts[1].return_type, ReturnType::Last);
  EXPECT_NEAR(pts[1].range_m, 12.0, 1e-5);
  EXPECT_EQ(pts[2].return_type, ReturnType::Strongest);
  EXPECT_NEAR(pts[2].range_m, 8.0, 1e-5);
  EXPECT_EQ(pts[1].time_s, pts[2].time_s);
  EXPECT_EQ(pts[1].azimuth_cdeg, pts[2].azimuth_cdeg);
  EXPECT_EQ(pts[3].return_type, ReturnType::Strongest);
  EXPECT_EQ(pts[4].return_type, ReturnType::Last);
  EXPECT_EQ(pts[5].return_type, ReturnType::Strongest);
  // Dual: 6 firing groups of 46.08 us; the last firing is 5 * 46.08 + 31 * 1.152 = 266.112 us after the first.
  EXPECT_NEAR(pts[0].time_s, -266.112e-6, 1e-9);
  EXPECT_NEAR(pts[1].time_s, (1.152 - 266.112) * 1e-6, 1e-9);
  EXPECT_NEAR(pts[6].time_s, 0.0, 1e-9);
  EXPECT_EQ(pts[6].return_type, ReturnType::Last);
  EXPECT_EQ(pts[7].return_type, ReturnType::Strongest);
  // Azimuth step from block 0 to block 2 (40 cdeg per 46.08 us); the last pair reuses it.
  EXPECT_EQ(pts[1].azimuth_cdeg, 1001);
  EXPECT_EQ(pts[6].azimuth_cdeg, static_cast<std::uint16_t>(std::lround(1000 + 5 * 40 + 40 * 31 * 1.152 / 46.08)));

  // The layout alone (blocks 0 and 1 equal) also means dual, whatever byte 1204 says.
  p.factory(0x37, 0x21);
  std::vector<LidarPoint> again;
  ASSERT_TRUE(d.decode(p.span(), again).has_value());
  EXPECT_EQ(again.size(), pts.size());
}

// ---- VLP-16 ----

TEST(VelodyneDecoder, Vlp16TimingAndAzimuthInterpolation) {
  PacketBuilder p;
  p.azimuths(35900, 80).factory(0x37, 0x22).timestamp(1000);
  p.slot(1, 5, 2500, 11);       // block 1, sequence 0, laser 5 (+5 deg)
  p.slot(1, 16 + 5, 2500, 12);  // block 1, sequence 1, laser 5
  p.slot(11, 31, 2500, 13);     // block 11, sequence 1, laser 15: the last firing
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(make_decoder(Model::VLP16).decode(p.span(), pts).has_value());
  ASSERT_EQ(pts.size(), 3U);
  EXPECT_NEAR(pts[0].time_s, (110.592 + 5 * 2.304) * 1e-6, 1e-9);
  EXPECT_NEAR(pts[1].time_s, (110.592 + 55.296 + 5 * 2.304) * 1e-6, 1e-9);
  EXPECT_NEAR(pts[2].time_s, (11 * 110.592 + 55.296 + 15 * 2.304) * 1e-6, 1e-9);
  // Block 1 is at 359.80 deg and block 2 at 0.60 deg: 80 cdeg per 110.592 us, across the wrap.
  EXPECT_EQ(pts[0].azimuth_cdeg, 35988);  // 35980 + 80 * 11.52 / 110.592 = 35988.3
  EXPECT_EQ(pts[1].azimuth_cdeg, 28);     // 35980 + 80 * 66.816 / 110.592 = 36028.3
  EXPECT_EQ(pts[2].azimuth_cdeg,
            static_cast<std::uint16_t>(std::lround((35900 + 11 * 80 + 80 * 89.856 / 110.592) - 36000)));
  EXPECT_EQ(pts[0].ring, 10);
  EXPECT_EQ(pts[2].ring, 15);
  EXPECT_NEAR(pts[0].z, 5.0 * std::sin(deg2rad(5.0)), 1e-5);
  EXPECT_NEAR(pts[1].x, 5.0 * std::cos(deg2rad(5.0)) * std::cos(deg2rad(0.283)), 1e-3);
}

// The firing the timestamp marks under LastFiring, for each model and return mode: the last point is at 0.
struct LastFiringCase {
  Model model;
  bool dual;
  double last_us;
};

class VelodyneLastFiring : public ::testing::TestWithParam<LastFiringCase> {};

TEST_P(VelodyneLastFiring, LastFiringIsTimeZero) {
  const auto& c = GetParam();
  PacketBuilder p;
  p.azimuths(100, 30, c.dual).factory(c.dual ? 0x39 : 0x37, c.model == Model::VLP16 ? 0x22 : 0x21);
  p.slot(0, 0, 1000, 1).slot(11, 31, 1000, 2);
  std::vector<LidarPoint> pts;
  ASSERT_TRUE(make_decoder(c.model, TimestampReference::LastFiring).decode(p.span(), pts).has_value());
  ASSERT_EQ(pts.size(), 2U);  // dual: block 0 Last (block 1 empty), block 11 Strongest (block 10 empty)
  EXPECT_NEAR(pts.front().time_s, -c.last_us * 1e-6, 1e-9);
  EXPECT_NEAR(pts.back().time_s, 0.0, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Layouts, VelodyneLastFiring,
                         ::testing::Values(LastFiringCase{Model::HDL32E, false, 542.592},
                                           LastFiringCase{Model::HDL32E, true, 266.112},
                                           LastFiringCase{Model::VLP16, false, 1306.368},
                                           LastFiringCase{Model::VLP16, true, 642.816}));

}  // namespace
}  // namespace fieldguard::velodyne
