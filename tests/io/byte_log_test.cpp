#include "fieldguard/io/byte_log.hpp"

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>

#include "io/pcap_builder.hpp"

namespace fieldguard::io {
namespace {

TEST(ByteLog, RoundTripsRecordsInOrder) {
  testing::TempDir dir;
  const auto path = (dir.path() / "gnss.log").string();
  {
    auto w = ByteLogWriter::create(path, "gnss /dev/ttyUSB0 115200");
    ASSERT_TRUE(w.has_value()) << w.error();
    const std::vector<std::uint8_t> a{'$', 'G', 'P'};
    const std::vector<std::uint8_t> b{};
    const std::vector<std::uint8_t> c(70000, 0xFA);
    EXPECT_TRUE(w->write(Stamp{1'700'000'000'123'456'789}, Direction::FromSensor, a));
    EXPECT_TRUE(w->write(Stamp{1'700'000'000'223'456'789}, Direction::ToSensor, b));
    EXPECT_TRUE(w->write(Stamp{-5}, Direction::FromSensor, c));
  }
  auto r = ByteLogReader::open(path);
  ASSERT_TRUE(r.has_value()) << r.error();
  EXPECT_EQ(r->source(), "gnss /dev/ttyUSB0 115200");
  auto r1 = r->next();
  ASSERT_TRUE(r1);
  EXPECT_EQ(r1->host_time.ns, 1'700'000'000'123'456'789);
  EXPECT_EQ(r1->direction, Direction::FromSensor);
  EXPECT_EQ(r1->bytes, (std::vector<std::uint8_t>{'$', 'G', 'P'}));
  auto r2 = r->next();
  ASSERT_TRUE(r2);
  EXPECT_EQ(r2->direction, Direction::ToSensor);
  EXPECT_TRUE(r2->bytes.empty());
  auto r3 = r->next();
  ASSERT_TRUE(r3);
  EXPECT_EQ(r3->host_time.ns, -5);
  EXPECT_EQ(r3->bytes.size(), 70000U);
  EXPECT_FALSE(r->next());
  EXPECT_FALSE(r->truncated());
  EXPECT_TRUE(r->error().empty());
}

TEST(ByteLog, CutInsideARecordKeepsTheWholeOnes) {
  testing::TempDir dir;
  const auto path = (dir.path() / "cut.log").string();
  {
    auto w = ByteLogWriter::create(path, "ahrs");
    ASSERT_TRUE(w.has_value());
    const std::vector<std::uint8_t> a(100, 1);
    EXPECT_TRUE(w->write(Stamp{1}, Direction::FromSensor, a));
    EXPECT_TRUE(w->write(Stamp{2}, Direction::FromSensor, a));
  }
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 30);
  auto r = ByteLogReader::open(path);
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(r->next());
  EXPECT_FALSE(r->next());
  EXPECT_TRUE(r->truncated());
}

TEST(ByteLog, BadFilesSayWhy) {
  testing::TempDir dir;
  EXPECT_NE(ByteLogReader::open((dir.path() / "none.log").string()).error().find("cannot open"), std::string::npos);
  const auto junk = dir.write("junk.log", testing::Bytes{'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd', '!'});
  EXPECT_NE(ByteLogReader::open(junk).error().find("not a fieldguard byte log"), std::string::npos);
  // The header, a source line, and a record header claiming a 4 GiB record.
  const std::string text = std::string(kByteLogMagic) + "x\n";
  testing::Bytes corrupt(text.begin(), text.end());
  const std::array<std::uint8_t, 13> record{1, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0xFF, 0xFF, 0xFF, 0};
  testing::append(corrupt, testing::Bytes(record.begin(), record.end()));
  auto r = ByteLogReader::open(dir.write("corrupt.log", corrupt));
  ASSERT_TRUE(r.has_value());
  EXPECT_FALSE(r->next());
  EXPECT_NE(r->error().find("corrupt record"), std::string::npos);
  EXPECT_FALSE(ByteLogWriter::create((dir.path() / "no" / "dir.log").string(), "x").has_value());
}

}  // namespace
}  // namespace fieldguard::io
