// The 2D LiDAR source against the SCIP 2.0 emulator over real TCP: start-up, streaming, a connection dropped
// in the middle of a scan, garbage on the line, a laser that will not light.

#include "fieldguard/io/scip_source.hpp"

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

namespace fieldguard::io {
namespace {

using namespace std::chrono_literals;

// Runs the emulator as a process; its first line of output is its port. Killed when the test ends.
class Emulator {
 public:
  explicit Emulator(const std::vector<std::string>& args) {
    int out[2];
    if (::pipe(out) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], STDOUT_FILENO);
      ::close(out[0]);
      ::close(out[1]);
      std::vector<char*> argv{const_cast<char*>(FIELDGUARD_SCIP_EMULATOR)};
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(FIELDGUARD_SCIP_EMULATOR, argv.data());
      ::_exit(127);
    }
    ::close(out[1]);
    FILE* f = ::fdopen(out[0], "r");
    char line[64] = {};
    if (f != nullptr && std::fgets(line, sizeof line, f) != nullptr) port_ = static_cast<std::uint16_t>(std::atoi(line));
    if (f != nullptr) std::fclose(f);
  }
  ~Emulator() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  Emulator(const Emulator&) = delete;
  Emulator& operator=(const Emulator&) = delete;
  [[nodiscard]] std::uint16_t port() const { return port_; }

 private:
  pid_t pid_ = -1;
  std::uint16_t port_ = 0;
};

template <typename Pred>
bool run_until(boost::asio::io_context& io, Pred done, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (!done() && std::chrono::steady_clock::now() < end) {
    io.restart();
    io.run_for(5ms);
  }
  return done();
}

ScipSourceOptions options(std::uint16_t port) {
  ScipSourceOptions o;
  o.tcp.host = "127.0.0.1";
  o.tcp.port = port;
  o.tcp.backoff_initial_s = 0.05;
  o.tcp.backoff_max_s = 0.2;
  o.tcp.silence_timeout_s = 0.5;
  return o;
}

struct Collected {
  std::vector<scip::Scan> scans;
  std::vector<std::string> states;
};

TEST(ScipSource, StartsUpAndStreamsTheObstacleInFront) {
  Emulator emu({"--scene", "obstacle"});
  ASSERT_NE(emu.port(), 0);
  boost::asio::io_context io;
  Collected c;
  scip::Geometry geometry;
  ScipSource src(io, options(emu.port()), [&](const scip::Scan& s, const scip::Geometry& g, Stamp) {
    c.scans.push_back(s);
    geometry = g;
  });
  src.start();
  ASSERT_TRUE(run_until(io, [&] { return c.scans.size() >= 20; }, 5000ms));
  EXPECT_EQ(src.protocol_state(), scip::ClientState::Streaming);
  const scip::Scan& s = c.scans.back();
  ASSERT_EQ(s.ranges_mm.size(), 1081U);
  // Straight ahead (step 540) the box face 1.0 m away; 90 degrees left (step 900) the open field.
  EXPECT_NEAR(static_cast<double>(s.ranges_mm[540]), 1000.0, 3.0);
  std::vector<scip::Point2> pts;
  scip::scan_to_points(s, geometry, pts);
  int in_front = 0;
  for (const auto& p : pts) in_front += (p.x_m > 0.95F && p.x_m < 1.05F && std::abs(p.y_m) < 0.31F) ? 1 : 0;
  EXPECT_GT(in_front, 20);
  EXPECT_EQ(src.stats().refusals.load(), 0U);
  EXPECT_EQ(src.link().connects.load(), 1U);
  src.stop();
}

TEST(ScipSource, ConnectionDroppedMidScanIsMadeAgain) {
  Emulator emu({"--drop-after", "5"});
  ASSERT_NE(emu.port(), 0);
  boost::asio::io_context io;
  Collected c;
  ScipSource src(io, options(emu.port()), [&](const scip::Scan& s, const scip::Geometry&, Stamp) { c.scans.push_back(s); },
                 [&](const std::string& w) { c.states.push_back(w); });
  src.start();
  ASSERT_TRUE(run_until(io, [&] { return src.link().connects.load() >= 2 && c.scans.size() >= 7; }, 8000ms));
  EXPECT_GE(src.link().disconnects.load(), 1U);
  for (const auto& s : c.scans) EXPECT_EQ(s.ranges_mm.size(), 1081U);  // the half scan never came out
  bool said_closed = false;
  for (const auto& w : c.states) said_closed = said_closed || w.find("closed the connection") != std::string::npos;
  EXPECT_TRUE(said_closed);
  src.stop();
}

TEST(ScipSource, GarbageIsCountedAndScansGoOn) {
  Emulator emu({"--garbage-after", "3"});
  ASSERT_NE(emu.port(), 0);
  boost::asio::io_context io;
  Collected c;
  ScipSource src(io, options(emu.port()), [&](const scip::Scan& s, const scip::Geometry&, Stamp) { c.scans.push_back(s); });
  src.start();
  ASSERT_TRUE(run_until(io, [&] { return c.scans.size() >= 15; }, 8000ms));
  EXPECT_GT(src.stats().parser_errors.load(), 0U);
  for (const auto& s : c.scans) EXPECT_EQ(s.ranges_mm.size(), 1081U);
  src.stop();
}

TEST(ScipSource, LaserThatWillNotLightIsReportedAndRetried) {
  Emulator emu({"--refuse-laser"});
  ASSERT_NE(emu.port(), 0);
  boost::asio::io_context io;
  Collected c;
  ScipSource src(io, options(emu.port()), [&](const scip::Scan& s, const scip::Geometry&, Stamp) { c.scans.push_back(s); },
                 [&](const std::string& w) { c.states.push_back(w); });
  src.start();
  ASSERT_TRUE(run_until(io, [&] { return src.stats().refusals.load() >= 2; }, 5000ms));
  EXPECT_TRUE(c.scans.empty());
  bool said = false;
  for (const auto& w : c.states) said = said || w.find("refused BM with status 01") != std::string::npos;
  EXPECT_TRUE(said);
  src.stop();
}

}  // namespace
}  // namespace fieldguard::io
