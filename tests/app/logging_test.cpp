// Log lines under systemd: the journal stream is recognised by JOURNAL_STREAM's device and inode, and each
// level gets the syslog priority journald files it under; safety reasons map to levels by what they mean.

#include "fieldguard/engine/logging.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <string>

#include "io/pcap_builder.hpp"

namespace fieldguard::app {
namespace {

namespace safety = output::safety;

std::string dev_ino(int fd) {
  struct stat st {};
  EXPECT_EQ(::fstat(fd, &st), 0);
  return std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
}

TEST(Logging, TheJournalStreamIsTheFileJournalStreamNames) {
  testing::TempDir dir;
  const int a = ::open((dir.path() / "a").c_str(), O_WRONLY | O_CREAT, 0644);
  const int b = ::open((dir.path() / "b").c_str(), O_WRONLY | O_CREAT, 0644);
  ASSERT_GE(a, 0);
  ASSERT_GE(b, 0);
  const std::string id = dev_ino(a);
  EXPECT_TRUE(is_journal_stream(a, id.c_str()));
  EXPECT_FALSE(is_journal_stream(b, id.c_str())) << "another file: stderr redirected away from the journal";
  EXPECT_FALSE(is_journal_stream(a, nullptr));
  for (const char* bad : {"", ":", "1:", ":2", "1:2:3", "x:1", "1:y", " 1:2", "1:2 ", "-1:2", "1;2"}) {
    EXPECT_FALSE(is_journal_stream(a, bad)) << bad;
  }
  EXPECT_FALSE(is_journal_stream(-1, id.c_str())) << "a closed descriptor";
  ::close(a);
  ::close(b);
}

TEST(Logging, LevelsBecomeSyslogPriorities) {
  EXPECT_EQ(syslog_priority(spdlog::level::critical), 2);
  EXPECT_EQ(syslog_priority(spdlog::level::err), 3);
  EXPECT_EQ(syslog_priority(spdlog::level::warn), 4);
  EXPECT_EQ(syslog_priority(spdlog::level::info), 6);
  EXPECT_EQ(syslog_priority(spdlog::level::debug), 7);
  EXPECT_EQ(syslog_priority(spdlog::level::trace), 7);
}

TEST(Logging, SafetyReasonsAreLoggedAtTheirSeverity) {
  EXPECT_EQ(level_of(safety::severity(safety::Reason::None)), spdlog::level::info);
  EXPECT_EQ(level_of(safety::severity(safety::Reason::ObstacleInZone)), spdlog::level::info);
  EXPECT_EQ(level_of(safety::severity(safety::Reason::StartingUp)), spdlog::level::info);
  EXPECT_EQ(level_of(safety::severity(safety::Reason::SensorFault)), spdlog::level::warn);
  EXPECT_EQ(level_of(safety::severity(safety::Reason::ImplausibleData)), spdlog::level::warn);
  EXPECT_EQ(level_of(safety::severity(safety::Reason::PipelineLate)), spdlog::level::warn);
  EXPECT_EQ(level_of(safety::severity(safety::Reason::NoAddress)), spdlog::level::err);
}

}  // namespace
}  // namespace fieldguard::app
