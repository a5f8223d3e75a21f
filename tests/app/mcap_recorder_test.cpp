// The recorder's bounded series of files: a new whole file once one is max_bytes large, only the newest
// max_files kept, each one a complete MCAP (its closing magic written), every frame in exactly one.

#include "fieldguard/writers/mcap_recorder.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace fieldguard::app {
namespace {

namespace fs = std::filesystem;

bool ends_with_magic(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  const std::string f{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return f.size() > 16 && f.compare(0, 8, std::string("\x89MCAP0\r\n", 8)) == 0 &&
         f.compare(f.size() - 8, 8, std::string("\x89MCAP0\r\n", 8)) == 0;
}

LidarFrame frame_with_points(std::uint64_t index, std::size_t n) {
  LidarFrame f;
  f.index = index;
  f.host_stamp.ns = 1'000'000'000 + static_cast<std::int64_t>(index) * 100'000'000;
  f.points.resize(n);
  for (std::size_t i = 0; i < n; ++i) f.points[i].x = static_cast<float>(i);
  return f;
}

class McapRecorderTest : public ::testing::Test {
 protected:
  fs::path dir_ = fs::temp_directory_path() /
                  ("fg_mcaprec_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  void SetUp() override {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  Config cfg_;
};

TEST_F(McapRecorderTest, NumberedNamesKeepTheExtension) {
  EXPECT_EQ(McapRecorder::numbered("/var/lib/fieldguard/run.mcap", 3), "/var/lib/fieldguard/run_0003.mcap");
  EXPECT_EQ(McapRecorder::numbered("run.mcap", 12345), "run_12345.mcap");
}

TEST_F(McapRecorderTest, BoundedSeriesKeepsTheNewestFiles) {
  McapRecorder r(cfg_);
  McapRecording rec;
  rec.path = (dir_ / "live.mcap").string();
  rec.max_bytes = 20'000;  // a frame of 2000 points is ~43 kB of JSON: each frame starts a file
  rec.max_files = 2;
  ASSERT_TRUE(r.open(rec)) << r.error();
  perception::FrameResult result;
  for (std::uint64_t i = 0; i < 5; ++i) ASSERT_TRUE(r.frame(frame_with_points(i, 2000), result, {}, nullptr, nullptr));
  ASSERT_TRUE(r.close()) << r.error();
  const auto s = r.stats();
  EXPECT_EQ(s.frames, 5U);
  EXPECT_EQ(s.files, 5U);
  EXPECT_EQ(s.removed, 3U);
  EXPECT_EQ(s.messages, 5U * 4U);  // raw and labelled points, obstacles, zones (no decision, no pose)
  for (std::uint64_t i = 1; i <= 3; ++i) EXPECT_FALSE(fs::exists(McapRecorder::numbered(rec.path, i))) << i;
  for (std::uint64_t i = 4; i <= 5; ++i) {
    EXPECT_TRUE(fs::exists(McapRecorder::numbered(rec.path, i))) << i;
    EXPECT_TRUE(ends_with_magic(McapRecorder::numbered(rec.path, i))) << i;
  }
  EXPECT_FALSE(fs::exists(rec.path));  // a bounded series never writes the unnumbered name
  EXPECT_EQ(r.current_path(), McapRecorder::numbered(rec.path, 5));
}

TEST_F(McapRecorderTest, UnboundedIsOneFileAtThePath) {
  McapRecorder r(cfg_);
  McapRecording rec;
  rec.path = (dir_ / "one.mcap").string();
  ASSERT_TRUE(r.open(rec)) << r.error();
  perception::FrameResult result;
  for (std::uint64_t i = 0; i < 3; ++i) ASSERT_TRUE(r.frame(frame_with_points(i, 2000), result, {}, nullptr, nullptr));
  ASSERT_TRUE(r.close());
  EXPECT_EQ(r.stats().files, 1U);
  EXPECT_TRUE(ends_with_magic(rec.path));
}

TEST_F(McapRecorderTest, AFailedWriteStopsTheRecordingAndSaysWhy) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  McapRecorder r(cfg_);
  McapRecording rec;
  rec.path = "/dev/full";
  rec.options.chunk_bytes = 1024;
  // It fails wherever the disk first refuses (the schemas already fill stdio's buffer): never silently.
  bool ok = r.open(rec);
  perception::FrameResult result;
  for (std::uint64_t i = 0; i < 20 && ok; ++i) ok = r.frame(frame_with_points(i, 2000), result, {}, nullptr, nullptr);
  ok = r.close() && ok;
  EXPECT_FALSE(ok);
  EXPECT_NE(r.error().find("No space left"), std::string::npos) << r.error();
  EXPECT_FALSE(r.frame(frame_with_points(99, 10), result, {}, nullptr, nullptr));
}

}  // namespace
}  // namespace fieldguard::app
