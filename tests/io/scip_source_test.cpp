// The 2D LiDAR source against the SCIP 2.0 emulator over real TCP: start-up, streaming, a connection dropped
// in the middle of a scan, garbage on the line, a laser that will not light.

#include "fieldguard/io/scip_source.hpp"

#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <chrono>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "support/child_process.hpp"

namespace fieldguard::io {
namespace {

using namespace std::chrono_literals;

// The emulator as a process; its first line of output is its port. Ended with the test.
class Emulator {
 public:
  explicit Emulator(std::vector<std::string> args)
      : child_([&] {
          args.insert(args.begin(), FIELDGUARD_SCIP_EMULATOR);
          return args;
        }()) {
    port_ = static_cast<std::uint16_t>(std::atoi(child_.line().c_str()));
  }
  [[nodiscard]] std::uint16_t port() const { return port_; }

 private:
  testing::ChildProcess child_;
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
  std::vector<std::pair<bool, std::string>> states;  // trouble, what
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
  ASSERT_TRUE(run_until(
      io, [&] { return c.scans.size() >= 20; }, 5000ms));
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
  ScipSource src(
      io, options(emu.port()), [&](const scip::Scan& s, const scip::Geometry&, Stamp) { c.scans.push_back(s); },
      [&](bool trouble, const std::string& w) {
        c.states.push_back({trouble, w});
      });
  src.start();
  ASSERT_TRUE(run_until(
      io, [&] { return src.link().connects.load() >= 2 && c.scans.size() >= 7; }, 8000ms));
  EXPECT_GE(src.link().disconnects.load(), 1U);
  for (const auto& s : c.scans) EXPECT_EQ(s.ranges_mm.size(), 1081U);  // the half scan never came out
  // The loss is trouble (a warning in the daemon's log), connecting again is not.
  bool said_closed = false, said_connected = false;
  for (const auto& [trouble, w] : c.states) {
    if (w.find("closed the connection") != std::string::npos) {
      said_closed = true;
      EXPECT_TRUE(trouble) << w;
    }
    if (w.find("connected") == 0) {
      said_connected = true;
      EXPECT_FALSE(trouble) << w;
    }
  }
  EXPECT_TRUE(said_closed);
  EXPECT_TRUE(said_connected);
  src.stop();
}

TEST(ScipSource, GarbageIsCountedAndScansGoOn) {
  Emulator emu({"--garbage-after", "3"});
  ASSERT_NE(emu.port(), 0);
  boost::asio::io_context io;
  Collected c;
  ScipSource src(io, options(emu.port()),
                 [&](const scip::Scan& s, const scip::Geometry&, Stamp) { c.scans.push_back(s); });
  src.start();
  ASSERT_TRUE(run_until(
      io, [&] { return c.scans.size() >= 15; }, 8000ms));
  EXPECT_GT(src.stats().parser_errors.load(), 0U);
  for (const auto& s : c.scans) EXPECT_EQ(s.ranges_mm.size(), 1081U);
  src.stop();
}

TEST(ScipSource, LaserThatWillNotLightIsReportedAndRetried) {
  Emulator emu({"--refuse-laser"});
  ASSERT_NE(emu.port(), 0);
  boost::asio::io_context io;
  Collected c;
  ScipSource src(
      io, options(emu.port()), [&](const scip::Scan& s, const scip::Geometry&, Stamp) { c.scans.push_back(s); },
      [&](bool trouble, const std::string& w) {
        c.states.push_back({trouble, w});
      });
  src.start();
  ASSERT_TRUE(run_until(
      io, [&] { return src.stats().refusals.load() >= 2; }, 5000ms));
  EXPECT_TRUE(c.scans.empty());
  bool said = false;
  for (const auto& [trouble, w] : c.states)
    said = said || (trouble && w.find("refused BM with status 01") != std::string::npos);
  EXPECT_TRUE(said);
  src.stop();
}

}  // namespace
}  // namespace fieldguard::io
