#include "fieldguard/output/can_speed.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

namespace fieldguard::output {
namespace {

// The bytes of a candump line's data field: hex pairs from `from` to the end.
std::vector<std::uint8_t> hex_bytes(const std::string& line, std::size_t from) {
  std::vector<std::uint8_t> data;
  for (std::size_t i = from; i + 1 < line.size(); i += 2) {
    data.push_back(static_cast<std::uint8_t>(std::stoul(line.substr(i, 2), nullptr, 16)));
  }
  return data;
}

std::vector<std::uint8_t> bytes(std::initializer_list<int> v) {
  std::vector<std::uint8_t> out;
  for (const int b : v) out.push_back(static_cast<std::uint8_t>(b));
  return out;
}

TEST(CanSpeed, Ccvs1IsBytes2And3InUnitsOf1Over256KmH) {
  // 0x1900 = 6400 -> 25 km/h, priority 6 from SA 0x00.
  const auto r = decode_speed(0x18FEF100, bytes({0xF7, 0x00, 0x19, 0, 0, 0, 0, 0xFF}));
  ASSERT_TRUE(r);
  EXPECT_NEAR(r->speed_mps, 25.0 / 3.6, 1e-12);
  EXPECT_EQ(r->source, SpeedSource::Ccvs1);
  EXPECT_EQ(r->source_address, 0x00);
  // Byte order matters: 00 19 would be 0x1900; 19 00 is 0x0019 = 25/256 km/h.
  EXPECT_NEAR(decode_speed(0x0CFEF117, bytes({0, 0x19, 0x00}))->speed_mps, 25.0 / 256.0 / 3.6, 1e-12);
}

TEST(CanSpeed, IsoWheelBasedSpeedIsBytes1And2InMmPerSecond) {
  const auto r = decode_speed(0x0CFE4880, bytes({0x88, 0x13, 0, 0, 0, 0, 0xFF, 0xFF}));  // 5000 mm/s
  ASSERT_TRUE(r);
  EXPECT_DOUBLE_EQ(r->speed_mps, 5.0);
  EXPECT_EQ(r->source, SpeedSource::IsoWheelBased);
  EXPECT_EQ(r->source_address, 0x80);
  EXPECT_DOUBLE_EQ(decode_speed(0x0CFE4880, bytes({0xFF, 0xFA}))->speed_mps, 64.255);  // the largest valid
}

TEST(CanSpeed, SpecialValuesAndBadFramesAreErrors) {
  EXPECT_EQ(decode_speed(0x18FEF100, bytes({0xFF, 0xFF, 0xFF})).error(), SpeedError::NotAvailable);
  EXPECT_EQ(decode_speed(0x18FEF100, bytes({0xFF, 0x00, 0xFE})).error(), SpeedError::SenderError);
  EXPECT_EQ(decode_speed(0x18FEF100, bytes({0xFF, 0x00, 0xFB})).error(), SpeedError::Reserved);
  EXPECT_EQ(decode_speed(0x18FEF100, bytes({0xFF, 0x00})).error(), SpeedError::TooShort);
  EXPECT_EQ(decode_speed(0x0CFE4880, bytes({0x88})).error(), SpeedError::TooShort);
  EXPECT_EQ(decode_speed(0x0CF00400, bytes({0, 0, 0, 0, 0, 0, 0, 0})).error(), SpeedError::OtherPgn);  // EEC1
  // Data page 1 makes a different PGN (0x1FEF1), not CCVS1.
  EXPECT_EQ(decode_speed(0x19FEF100, bytes({0, 0, 0})).error(), SpeedError::OtherPgn);
  EXPECT_EQ(to_string(SpeedError::SenderError), "sender_error");
}

// The real truck capture (tests/data/can, parked with the engine idling): every CCVS1 frame says 0 km/h.
TEST(CanSpeed, RealTruckCaptureReadsZeroWhileParked) {
  std::ifstream log(std::string(FIELDGUARD_TEST_DATA) + "/can/j1939_truck_idle_first300.log");
  ASSERT_TRUE(log);
  std::string line;
  int speeds = 0;
  int others = 0;
  while (std::getline(log, line)) {
    const auto hash = line.find('#');
    ASSERT_NE(hash, std::string::npos);
    const auto id = static_cast<std::uint32_t>(std::stoul(line.substr(hash - 8, 8), nullptr, 16));
    const std::vector<std::uint8_t> data = hex_bytes(line, hash + 1);
    const auto r = decode_speed(id, data);
    if (r) {
      ++speeds;
      EXPECT_EQ(r->speed_mps, 0.0);
      EXPECT_EQ(r->source_address, 0x00);
    } else {
      EXPECT_EQ(r.error(), SpeedError::OtherPgn) << line;
      ++others;
    }
  }
  EXPECT_EQ(speeds, 9);  // the slice's CCVS1 frames (0CFEF100)
  EXPECT_EQ(speeds + others, 300);
}

// The whole capture, when ../shared/realdata is there: 127 s parked, 1272 CCVS1 frames, all 0 km/h.
TEST(CanSpeed, WholeRealTruckCaptureWhenPresent) {
  const std::string path =
      std::string(FIELDGUARD_SOURCE_DIR) +
      "/../shared/realdata/j1939-css-electronics-canedge/j1939_truck_idle_11111111_00000012_00000001.log";
  std::ifstream log(path);
  if (!log) GTEST_SKIP() << "not present: " << path;
  std::string line;
  int speeds = 0;
  while (std::getline(log, line)) {
    const auto hash = line.find('#');
    const auto space = line.rfind(' ', hash);
    ASSERT_TRUE(hash != std::string::npos && space != std::string::npos) << line;
    if (hash - space - 1 != 8) continue;  // 11-bit ids are not J1939
    const auto id = static_cast<std::uint32_t>(std::stoul(line.substr(space + 1, 8), nullptr, 16));
    const std::vector<std::uint8_t> data = hex_bytes(line, hash + 1);
    const auto r = decode_speed(id, data);
    if (r) {
      ++speeds;
      EXPECT_EQ(r->speed_mps, 0.0) << line;
    } else {
      EXPECT_EQ(r.error(), SpeedError::OtherPgn) << line;
    }
  }
  EXPECT_EQ(speeds, 1272);
}

}  // namespace
}  // namespace fieldguard::output
