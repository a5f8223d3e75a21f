#include "fieldguard/drivers/velodyne_position.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace fieldguard::velodyne {
namespace {

// The sentence the HDL-32E in ../shared/realdata/velodyne-hdl32e-veloview/monterey-first-100-packets.pcap sends.
constexpr std::string_view kMontereyRmc =
    "$GPRMC,220632,A,3707.8324,N,12139.2864,W,000.0,144.7,111212,013.8,E,D*09\r\n";

struct Packet {
  std::vector<std::uint8_t> bytes = std::vector<std::uint8_t>(kPositionPacketSize, 0);

  void le16(std::size_t off, std::uint16_t v) {
    bytes[off] = static_cast<std::uint8_t>(v & 0xFF);
    bytes[off + 1] = static_cast<std::uint8_t>(v >> 8);
  }
  void le32(std::size_t off, std::uint32_t v) {
    for (std::size_t i = 0; i < 4; ++i) bytes[off + i] = static_cast<std::uint8_t>(v >> (8 * i));
  }
  void text(std::size_t off, std::string_view s) {
    for (std::size_t i = 0; i < s.size(); ++i) bytes[off + i] = static_cast<std::uint8_t>(s[i]);
  }
  [[nodiscard]] ByteSpan span() const { return bytes; }
};

TEST(VelodynePosition, DecodesEveryField) {
  Packet p;
  // 12-bit two's complement in the low bits; the top nibble is not part of the value.
  p.le16(14, 0x0FBB);  // gyro 0: -69
  p.le16(16, 0x1044);  // temperature 0: 68
  p.le16(18, 0x22FC);  // accel X 0: 764
  p.le16(20, 0x3FFF);  // accel Y 0: -1
  p.le16(22, 0xF7FF);  // gyro 1: +2047, the largest
  p.le16(24, 0x0800);  // temperature 1: -2048, the smallest
  p.le16(26, 0x0000);
  p.le16(28, 0x0001);
  p.le16(30, 0x0FFF);  // gyro 2: -1
  p.le16(32, 0x0000);  // temperature 2: 0 -> 25 degC
  p.le16(34, 0x07FF);
  p.le16(36, 0x0800);
  p.le32(198, 0x499602D2);  // 1 234 567 890 us
  p.bytes[202] = 2;
  p.text(206, kMontereyRmc);

  const auto d = decode_position_packet(p.span());
  ASSERT_TRUE(d) << to_string(d.error());
  EXPECT_EQ(d->timestamp_us, 1234567890U);
  EXPECT_EQ(d->pps, PpsStatus::Locked);
  EXPECT_NEAR(d->gyro_dps[0], -69 * 0.09766, 1e-12);
  EXPECT_NEAR(d->temperature_c[0], 68 * 0.1453 + 25, 1e-12);
  EXPECT_NEAR(d->accel_x_g[0], 764 * 0.001221, 1e-12);
  EXPECT_NEAR(d->accel_y_g[0], -0.001221, 1e-12);
  EXPECT_NEAR(d->gyro_dps[1], 2047 * 0.09766, 1e-12);
  EXPECT_NEAR(d->temperature_c[1], -2048 * 0.1453 + 25, 1e-12);
  EXPECT_EQ(d->accel_x_g[1], 0.0);
  EXPECT_NEAR(d->accel_y_g[1], 0.001221, 1e-12);
  EXPECT_NEAR(d->gyro_dps[2], -0.09766, 1e-12);
  EXPECT_EQ(d->temperature_c[2], 25.0);
  EXPECT_NEAR(d->accel_x_g[2], 2047 * 0.001221, 1e-12);
  EXPECT_NEAR(d->accel_y_g[2], -2048 * 0.001221, 1e-12);

  EXPECT_EQ(d->nmea, kMontereyRmc.substr(0, kMontereyRmc.size() - 2));  // NUL padding and CR LF removed
  EXPECT_FALSE(d->nmea_error);
  ASSERT_TRUE(d->rmc);
  EXPECT_TRUE(d->rmc->valid);
  EXPECT_EQ(d->rmc->utc_seconds_of_day, 22 * 3600 + 6 * 60 + 32.0);
  EXPECT_NEAR(*d->rmc->lat_deg, 37 + 7.8324 / 60, 1e-12);
  EXPECT_NEAR(*d->rmc->lon_deg, -(121 + 39.2864 / 60), 1e-12);
  EXPECT_EQ(d->rmc->day, 11);
  EXPECT_EQ(d->rmc->month, 12);
  EXPECT_EQ(d->rmc->year, 2012);
}

TEST(VelodynePosition, OnlyFiveHundredTwelveBytes) {
  for (const std::size_t n : {std::size_t{0}, std::size_t{511}, std::size_t{513}, std::size_t{1206}}) {
    const std::vector<std::uint8_t> b(n, 0);
    const auto d = decode_position_packet(b);
    ASSERT_FALSE(d) << n;
    EXPECT_EQ(d.error(), DecodeError::BadLength);
  }
}

TEST(VelodynePosition, NoSentence) {
  const Packet p;  // a VLP-16 without GPS: all zero
  const auto d = decode_position_packet(p.span());
  ASSERT_TRUE(d);
  EXPECT_EQ(d->pps, PpsStatus::Absent);
  EXPECT_EQ(d->nmea, "");
  EXPECT_FALSE(d->rmc);
  EXPECT_FALSE(d->nmea_error);
  EXPECT_EQ(d->temperature_c[0], 25.0);
}

TEST(VelodynePosition, SentencesThatAreNotAnRmc) {
  Packet gga;  // newer VLP firmware may forward a GGA: kept as text, not decoded
  gga.text(206, "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n");
  const auto g = decode_position_packet(gga.span());
  ASSERT_TRUE(g);
  EXPECT_FALSE(g->rmc);
  EXPECT_EQ(g->nmea_error, nmea::Error::Unsupported);
  EXPECT_EQ(g->nmea.substr(0, 6), "$GPGGA");

  Packet damaged;
  std::string s(kMontereyRmc);
  s[10] = '9';
  damaged.text(206, s);
  const auto d = decode_position_packet(damaged.span());
  ASSERT_TRUE(d);
  EXPECT_FALSE(d->rmc);
  EXPECT_EQ(d->nmea_error, nmea::Error::BadChecksum);
}

TEST(VelodynePosition, SentenceRunsToTheEndOfThePacket) {
  Packet p;
  p.text(206, kMontereyRmc.substr(0, kMontereyRmc.size() - 2));
  for (std::size_t i = 206 + kMontereyRmc.size() - 2; i < kPositionPacketSize; ++i) p.bytes[i] = 'x';
  const auto d = decode_position_packet(p.span());
  ASSERT_TRUE(d);
  EXPECT_EQ(d->nmea.size(), kPositionPacketSize - 206);
  EXPECT_EQ(d->nmea_error, nmea::Error::TooLong);
}

TEST(VelodynePosition, PpsStatus) {
  const auto pps_of = [](std::uint8_t b) {
    Packet p;
    p.bytes[202] = b;
    return decode_position_packet(p.span())->pps;
  };
  EXPECT_EQ(pps_of(0), PpsStatus::Absent);
  EXPECT_EQ(pps_of(1), PpsStatus::Synchronizing);
  EXPECT_EQ(pps_of(2), PpsStatus::Locked);
  EXPECT_EQ(pps_of(3), PpsStatus::Error);
  EXPECT_EQ(pps_of(4), PpsStatus::Unknown);
  EXPECT_EQ(to_string(PpsStatus::Locked), "locked");
  EXPECT_EQ(to_string(PpsStatus::Unknown), "unknown");
}

// Three real payloads from the Monterey HDL-32E capture (tests/data/PROVENANCE.txt).
TEST(VelodynePosition, RealHdl32ePackets) {
  std::ifstream in(std::string(FIELDGUARD_TEST_DATA) + "/hdl32e_position_packets.bin", std::ios::binary);
  ASSERT_TRUE(in);
  const std::vector<std::uint8_t> all{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  ASSERT_EQ(all.size(), 3 * kPositionPacketSize);

  struct Expect {
    std::uint32_t timestamp_us;
    double utc_s;
  };
  const std::array<Expect, 3> expect = {{{393210381, 22 * 3600 + 6 * 60 + 32.0},
                                         {393840242, 22 * 3600 + 6 * 60 + 32.0},
                                         {393847563, 22 * 3600 + 6 * 60 + 33.0}}};
  for (std::size_t i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    const auto d = decode_position_packet(ByteSpan(all).subspan(i * kPositionPacketSize, kPositionPacketSize));
    ASSERT_TRUE(d);
    EXPECT_EQ(d->timestamp_us, expect[i].timestamp_us);
    EXPECT_EQ(d->pps, PpsStatus::Absent);  // the HDL-32E leaves byte 202 at 0
    ASSERT_TRUE(d->rmc) << d->nmea << " " << (d->nmea_error ? to_string(*d->nmea_error) : "");
    EXPECT_EQ(d->rmc->talker, "GP");
    EXPECT_TRUE(d->rmc->valid);
    EXPECT_EQ(d->rmc->utc_seconds_of_day, expect[i].utc_s);
    EXPECT_EQ(d->rmc->day, 11);
    EXPECT_EQ(d->rmc->month, 12);
    EXPECT_EQ(d->rmc->year, 2012);
    EXPECT_NEAR(*d->rmc->lat_deg, 37.13054, 1e-6);  // Morgan Hill, CA
    EXPECT_NEAR(*d->rmc->lon_deg, -121.654773, 1e-6);
    EXPECT_EQ(d->rmc->speed_mps, 0.0);
    EXPECT_EQ(d->rmc->course_deg, 144.7);
    EXPECT_EQ(d->rmc->mode, 'D');
    // The sensor's clock (us past the hour) is within two seconds after the GPS second it last received.
    const double sensor_s_of_hour = d->timestamp_us * 1e-6;
    const double gps_s_of_hour = std::fmod(*d->rmc->utc_seconds_of_day, 3600.0);
    EXPECT_GE(sensor_s_of_hour, gps_s_of_hour);
    EXPECT_LT(sensor_s_of_hour, gps_s_of_hour + 2.0);
    // The IMU words are live: temperatures of a running sensor, and the first packet's known raw values.
    for (const double t : d->temperature_c) {
      EXPECT_GT(t, 20.0);
      EXPECT_LT(t, 60.0);
    }
  }
  const auto first = decode_position_packet(ByteSpan(all).first(kPositionPacketSize));
  ASSERT_TRUE(first);
  EXPECT_NEAR(first->gyro_dps[0], -69 * 0.09766, 1e-12);          // word 0x0FBB
  EXPECT_NEAR(first->temperature_c[0], 68 * 0.1453 + 25, 1e-12);  // word 0x1044
  EXPECT_NEAR(first->accel_x_g[0], 764 * 0.001221, 1e-12);        // word 0x22FC
  EXPECT_NEAR(first->accel_y_g[1], -43 * 0.001221, 1e-12);        // word 0x3FD5
}

}  // namespace
}  // namespace fieldguard::velodyne
