// SystemdNotifier against a real AF_UNIX datagram socket standing where systemd's notify socket would be
// (NOTIFY_SOCKET), reading exactly what libsystemd's sd_pid_notify sends.
#include "daemon/systemd_notify.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>

namespace fieldguard::app {
namespace {

using namespace std::chrono_literals;
using Clock = SystemdNotifier::Clock;

// A bound datagram socket plus the environment a Type=notify service with WatchdogSec=2s gets.
class NotifySocket : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (std::filesystem::temp_directory_path() / ("fg-notify-" + std::to_string(::getpid()))).string();
    std::filesystem::remove(path_);
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    ASSERT_GE(fd_, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    ASSERT_LT(path_.size(), sizeof(addr.sun_path));
    std::memcpy(addr.sun_path, path_.c_str(), path_.size() + 1);
    ASSERT_EQ(::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0) << std::strerror(errno);
    ::setenv("NOTIFY_SOCKET", path_.c_str(), 1);
    ::setenv("WATCHDOG_USEC", "2000000", 1);
    ::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1);
  }
  void TearDown() override {
    ::unsetenv("NOTIFY_SOCKET");
    ::unsetenv("WATCHDOG_USEC");
    ::unsetenv("WATCHDOG_PID");
    if (fd_ >= 0) {
      ::close(fd_);
    }
    std::filesystem::remove(path_);
  }
  // The next datagram, or nothing if none is waiting.
  std::optional<std::string> next() {
    char buf[4096];
    const ssize_t n = ::recv(fd_, buf, sizeof(buf), MSG_DONTWAIT);
    if (n < 0) {
      EXPECT_TRUE(errno == EAGAIN || errno == EWOULDBLOCK) << std::strerror(errno);
      return std::nullopt;
    }
    return std::string(buf, static_cast<std::size_t>(n));
  }

  std::string path_;
  int fd_ = -1;
};

TEST_F(NotifySocket, ReadyThenWatchdogWhileDecisionsFlowAndNoneWhileStalled) {
  SystemdNotifier n = SystemdNotifier::from_environment();
  ASSERT_TRUE(n.active());
  ASSERT_TRUE(n.watchdog_timeout().has_value());
  EXPECT_EQ(*n.watchdog_timeout(), 2s);

  n.ready("lidar ok, scan2d ok, gnss ok, ahrs ok");
  EXPECT_EQ(next(), "READY=1\nSTATUS=lidar ok, scan2d ok, gnss ok, ahrs ok");
  EXPECT_EQ(next(), std::nullopt);

  // Healthy: a decision every 200 ms for 2 s. Pings at most every 0.5 s (a quarter of WatchdogSec).
  const Clock::time_point t0{};
  int pings = 0;
  for (int frame = 0; frame <= 10; ++frame) {
    n.progress(t0 + frame * 200ms);
    while (auto m = next()) {
      EXPECT_EQ(*m, "WATCHDOG=1");
      ++pings;
    }
  }
  // Frames at 0, 600, 1200, 1800 ms are the first >= 500 ms after the previous ping.
  EXPECT_EQ(pings, 4);
  EXPECT_EQ(n.watchdog_pings(), 4u);

  // Stalled: no decision for 3 s (longer than WatchdogSec). Nothing may reach systemd.
  EXPECT_EQ(next(), std::nullopt);

  // The pipeline resumes: the first decision pings at once.
  n.progress(t0 + 5s);
  EXPECT_EQ(next(), "WATCHDOG=1");
  EXPECT_EQ(n.send_errors(), 0u);
}

TEST_F(NotifySocket, StatusIsOneLineAndSentOnlyWhenItChanges) {
  SystemdNotifier n = SystemdNotifier::from_environment();
  n.status("waiting for lidar\n(silent 1.2 s)");
  EXPECT_EQ(next(), "STATUS=waiting for lidar (silent 1.2 s)");
  n.status("waiting for lidar\n(silent 1.2 s)");
  EXPECT_EQ(next(), std::nullopt);
  n.status("all sensors ok");
  EXPECT_EQ(next(), "STATUS=all sensors ok");
}

TEST_F(NotifySocket, ReloadAndStop) {
  SystemdNotifier n = SystemdNotifier::from_environment();
  n.reloading();
  EXPECT_EQ(next(), "RELOADING=1");
  n.reloaded("config reloaded");
  EXPECT_EQ(next(), "READY=1\nSTATUS=config reloaded");
  n.stopping();
  EXPECT_EQ(next(), "STOPPING=1");
}

TEST_F(NotifySocket, WatchdogMeantForAnotherProcessIsNotOurs) {
  // systemd sets WATCHDOG_PID to the main process; a child (or a forked test helper) must not ping.
  ::setenv("WATCHDOG_PID", std::to_string(::getpid() + 1).c_str(), 1);
  SystemdNotifier n = SystemdNotifier::from_environment();
  EXPECT_TRUE(n.active());
  EXPECT_FALSE(n.watchdog_timeout().has_value());
  n.progress(Clock::time_point{});
  EXPECT_EQ(next(), std::nullopt);
}

TEST_F(NotifySocket, VanishedSocketIsCountedNotFatal) {
  SystemdNotifier n = SystemdNotifier::from_environment();
  ::close(fd_);
  fd_ = -1;
  std::filesystem::remove(path_);
  n.ready("up");
  n.progress(Clock::time_point{});
  EXPECT_EQ(n.send_errors(), 2u);
}

TEST(SystemdNotifierOutsideSystemd, EverythingIsANoOp) {
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");
  SystemdNotifier n = SystemdNotifier::from_environment();
  EXPECT_FALSE(n.active());
  EXPECT_FALSE(n.watchdog_timeout().has_value());
  n.ready("up");
  n.progress(SystemdNotifier::Clock::time_point{});
  EXPECT_EQ(n.watchdog_pings(), 0u);
  EXPECT_EQ(n.send_errors(), 0u);
}

TEST(OneLine, ControlCharactersBecomeSpaces) {
  EXPECT_EQ(one_line("a\nb\tc\x7f"
                     "d"),
            "a b c d");
  EXPECT_EQ(one_line("plain"), "plain");
}

}  // namespace
}  // namespace fieldguard::app
