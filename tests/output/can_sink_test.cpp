#include "fieldguard/output/can_sink.hpp"

#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "fieldguard/output/can_encoder.hpp"

extern char** environ;  // NOLINT: posix_spawn's environment

namespace fieldguard::output {
namespace {

namespace fs = std::filesystem;

CanFrame frame(std::uint32_t id, std::vector<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.len = static_cast<std::uint8_t>(bytes.size());
  std::copy(bytes.begin(), bytes.end(), f.data.begin());
  return f;
}

std::string read_text(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

fs::path temp_dir() {
  fs::path d = fs::temp_directory_path() / ("fieldguard_can_" + std::to_string(::getpid()) + "_" +
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// --- candump log ---

TEST(CandumpLine, IsWhatCandumpMinusLWrites) {
  // protocols.md §7.2's example line.
  EXPECT_EQ(candump_line(frame(0x18FF1080, {1, 0, 0, 0, 0, 0, 5, 0x3E}), Stamp{1700000000123456000}, "can0"),
            "(1700000000.123456) can0 18FF1080#010000000000053E\n");
  // Seconds zero-padded to 10 digits, microseconds truncated, ids always 8 digits, uppercase hex.
  EXPECT_EQ(candump_line(frame(0xABC, {0xAB, 0xCD}), Stamp{5'000'999'999}, "vcan1"),
            "(0000000005.000999) vcan1 00000ABC#ABCD\n");
  EXPECT_EQ(candump_line(frame(0x1FFFFFFF, {}), Stamp{-7}, "can0"), "(0000000000.000000) can0 1FFFFFFF#\n");
}

TEST(CandumpLogSink, WritesOneLinePerFrameAndFlushesEachBatch) {
  const fs::path dir = temp_dir();
  const fs::path log = dir / "out.log";
  CandumpLogSink sink(log.string(), "can0");
  const std::vector<CanFrame> batch{frame(0x18FF1080, {1, 2}), frame(0x0CEF2680, {3})};
  sink.write(batch, Stamp{1'000'000'000});
  // Flushed: readable while the sink is still open.
  EXPECT_EQ(read_text(log), "(0000000001.000000) can0 18FF1080#0102\n(0000000001.000000) can0 0CEF2680#03\n");
  EXPECT_EQ(sink.stats().sent, 2U);
  EXPECT_EQ(sink.stats().write_errors, 0U);
  fs::remove_all(dir);
}

TEST(CandumpLogSink, BadPathOrInterfaceIsAClearError) {
  try {
    CandumpLogSink sink("/nonexistent-dir/x.log", "can0");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.log"), std::string::npos);
  }
  EXPECT_THROW(CandumpLogSink("/tmp/x.log", "can 0"), std::invalid_argument);
  EXPECT_THROW(CandumpLogSink("/tmp/x.log", ""), std::invalid_argument);
  EXPECT_THROW(CandumpLogSink("/tmp/x.log", "a_name_that_is_too_long"), std::invalid_argument);
}

TEST(CandumpLogSink, AFullDiskIsCountedNotFatal) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  CandumpLogSink sink("/dev/full", "can0");
  const std::vector<CanFrame> batch{frame(0x18FF1080, {1, 2})};
  sink.write(batch, Stamp{1});
  EXPECT_GE(sink.stats().write_errors, 1U);
  EXPECT_EQ(sink.stats().last_errno, ENOSPC);
}

// can-utils' log2asc (Debian can-utils, installed by tools/install-deps) must accept our log and show our
// ids and data in its ASC output.
TEST(CandumpLogSink, Log2ascAcceptsOurLog) {
  const char* kLog2asc = "/usr/bin/log2asc";
  ASSERT_TRUE(fs::exists(kLog2asc)) << "log2asc is missing: install can-utils (tools/install-deps)";
  const fs::path dir = temp_dir();
  const fs::path log = dir / "fg.log";
  const fs::path asc = dir / "fg.asc";
  CanEncoder enc(CanParams{});
  std::vector<CanFrame> frames;
  std::vector<perception::Obstacle> obs(2);
  obs[0].min = {4, -1, 0};
  obs[0].max = {5, 1, 1};
  obs[0].distance_m = 4;
  obs[1].min = {12, 2, 0};
  obs[1].max = {13, 3, 1};
  obs[1].distance_m = 12;
  enc.encode_frame(FrameReport{9, FrameStatus::Ok, obs}, frames);
  frames.push_back(enc.encode_stop(StopRequest{StopCommand::Stop, {true}}));
  frames.push_back(enc.encode_heartbeat(Heartbeat{}));
  {
    CandumpLogSink sink(log.string(), "can0");
    sink.write(std::span(frames).first(3), Stamp{1'718'449'170'200'000'000});
    sink.write(std::span(frames).subspan(3), Stamp{1'718'449'170'300'000'000});
  }
  const std::vector<std::string> args{kLog2asc, "-I", log.string(), "-O", asc.string(), "can0"};
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));  // NOLINT: posix_spawn's signature
  argv.push_back(nullptr);
  pid_t pid = 0;
  ASSERT_EQ(::posix_spawn(&pid, kLog2asc, nullptr, nullptr, argv.data(), environ), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  // ASC data lines: "   <time> <channel>  <ID>x       Rx   d <dlc> <bytes>" (x = extended id).
  const std::regex line_re(R"(^\s*(\d+\.\d+)\s+1\s+([0-9A-F]+)x\s+Rx\s+d\s+(\d)\s*((?:\s[0-9A-F]{2})*)\s*$)");
  std::istringstream asc_text(read_text(asc));
  std::string l;
  std::vector<CanFrame> got;
  std::vector<double> times;
  while (std::getline(asc_text, l)) {
    std::smatch m;
    if (!std::regex_match(l, m, line_re)) continue;
    CanFrame f;
    f.id = static_cast<std::uint32_t>(std::stoul(m[2], nullptr, 16));
    f.len = static_cast<std::uint8_t>(std::stoul(m[3]));
    std::istringstream bytes(m[4]);
    std::string b;
    std::size_t n = 0;
    while (bytes >> b && n < 8) f.data[n++] = static_cast<std::uint8_t>(std::stoul(b, nullptr, 16));
    EXPECT_EQ(n, f.len) << l;
    got.push_back(f);
    times.push_back(std::stod(m[1]));
  }
  ASSERT_EQ(got.size(), frames.size()) << read_text(asc);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(got[i], frames[i]) << "frame " << i;
  }
  EXPECT_NEAR(times.back() - times.front(), 0.1, 1e-6);  // relative to the first frame
  fs::remove_all(dir);
}

// --- SocketCAN, through a socketpair standing in for the CAN_RAW socket ---

struct Pair {
  int ours = -1;
  int theirs = -1;
  explicit Pair(int type) {
    int sv[2];
    if (::socketpair(AF_UNIX, type, 0, sv) == 0) {
      ours = sv[0];
      theirs = sv[1];
    }
  }
  ~Pair() {
    if (theirs >= 0) ::close(theirs);
  }
};

can_frame read_frame(int fd) {
  can_frame cf{};
  EXPECT_EQ(::recv(fd, &cf, sizeof cf, MSG_DONTWAIT), static_cast<ssize_t>(sizeof cf));
  return cf;
}

TEST(SocketCanSink, WritesExtendedCanFrames) {
  for (const int type : {SOCK_SEQPACKET, SOCK_DGRAM}) {
    Pair p(type);
    ASSERT_GE(p.ours, 0);
    SocketCanSink sink(p.ours);
    const CanFrame f = frame(0x0CEF2680, {1, 0, 0, 0, 0, 0, 5, 0x3E});
    EXPECT_EQ(sink.send(f), SocketCanSink::SendResult::Sent);
    const CanFrame short_frame = frame(0x18FF1280, {0xAA, 0xBB});
    CanSink& as_sink = sink;
    as_sink.write(std::span(&short_frame, 1), Stamp{});
    const can_frame a = read_frame(p.theirs);
    EXPECT_EQ(a.can_id, 0x0CEF2680U | CAN_EFF_FLAG);
    EXPECT_EQ(a.len, 8);
    EXPECT_EQ(std::memcmp(a.data, f.data.data(), 8), 0);
    const can_frame b = read_frame(p.theirs);
    EXPECT_EQ(b.can_id, 0x18FF1280U | CAN_EFF_FLAG);
    EXPECT_EQ(b.len, 2);
    EXPECT_EQ(b.data[0], 0xAA);
    EXPECT_EQ(b.data[2], 0);  // never leaks stale bytes past len
    EXPECT_EQ(sink.stats().sent, 2U);
  }
}

TEST(SocketCanSink, AFullSocketBufferDropsAndCountsWithoutBlocking) {
  for (const int type : {SOCK_SEQPACKET, SOCK_DGRAM}) {
    Pair p(type);
    ASSERT_GE(p.ours, 0);
    const int small = 4096;
    ASSERT_EQ(::setsockopt(p.ours, SOL_SOCKET, SO_SNDBUF, &small, sizeof small), 0);
    SocketCanSink sink(p.ours);
    constexpr int kFrames = 20000;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < kFrames; ++i) {
      CanFrame f = frame(0x18FF1080, {0, 0, 0, 0});
      f.data[0] = static_cast<std::uint8_t>(i);
      f.data[1] = static_cast<std::uint8_t>(i >> 8);
      (void)sink.send(f);
    }
    const auto elapsed = std::chrono::steady_clock::now() - t0;
    EXPECT_LT(elapsed, std::chrono::seconds(5));  // a blocking write would hang here forever
    EXPECT_GT(sink.stats().dropped, 0U);
    EXPECT_GT(sink.stats().sent, 0U);
    EXPECT_EQ(sink.stats().sent + sink.stats().dropped, static_cast<std::uint64_t>(kFrames));
    EXPECT_EQ(sink.stats().write_errors, 0U);
    EXPECT_TRUE(sink.stats().last_errno == EAGAIN || sink.stats().last_errno == ENOBUFS);
    // What got through is whole frames, in order, and the queue takes frames again once drained.
    std::uint64_t received = 0;
    int last = -1;
    can_frame cf{};
    while (::recv(p.theirs, &cf, sizeof cf, MSG_DONTWAIT) == static_cast<ssize_t>(sizeof cf)) {
      const int n = cf.data[0] | cf.data[1] << 8;
      EXPECT_GT(n, last);
      last = n;
      ++received;
    }
    EXPECT_EQ(received, sink.stats().sent);
    EXPECT_EQ(sink.send(frame(0x18FF1080, {1})), SocketCanSink::SendResult::Sent);
  }
}

TEST(SocketCanSink, APeerThatIsGoneIsAWriteErrorNotASignal) {
  Pair p(SOCK_SEQPACKET);
  ASSERT_GE(p.ours, 0);
  SocketCanSink sink(p.ours);
  ::close(p.theirs);
  p.theirs = -1;
  EXPECT_EQ(sink.send(frame(0x18FF1080, {1})), SocketCanSink::SendResult::Failed);  // EPIPE, no SIGPIPE
  EXPECT_EQ(sink.stats().write_errors, 1U);
  EXPECT_EQ(sink.stats().last_errno, EPIPE);
}

TEST(SocketCanSink, BusOffFromErrorFramesIsReported) {
  Pair p(SOCK_SEQPACKET);
  ASSERT_GE(p.ours, 0);
  SocketCanSink sink(p.ours);
  sink.poll();  // nothing waiting: returns at once
  EXPECT_FALSE(sink.stats().bus_off);
  can_frame err{};
  err.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
  err.len = CAN_ERR_DLC;
  ASSERT_EQ(::send(p.theirs, &err, sizeof err, 0), static_cast<ssize_t>(sizeof err));
  can_frame data{};
  data.can_id = 0x123;
  ASSERT_EQ(::send(p.theirs, &data, sizeof data, 0), static_cast<ssize_t>(sizeof data));
  ASSERT_EQ(::send(p.theirs, "xyz", 3, 0), 3);
  sink.poll();
  EXPECT_TRUE(sink.stats().bus_off);
  EXPECT_EQ(sink.stats().bus_off_events, 1U);
  EXPECT_EQ(sink.stats().error_frames, 1U);
  EXPECT_EQ(sink.stats().unexpected_reads, 2U);
  err.can_id = CAN_ERR_FLAG | CAN_ERR_RESTARTED;
  ASSERT_EQ(::send(p.theirs, &err, sizeof err, 0), static_cast<ssize_t>(sizeof err));
  sink.poll();
  EXPECT_FALSE(sink.stats().bus_off);
  EXPECT_EQ(sink.stats().restarts, 1U);
  EXPECT_EQ(sink.stats().error_frames, 2U);
}

TEST(SocketCanSink, ExtendedDataFramesAreKeptForTheNodeBoundedAndInOrder) {
  Pair p(SOCK_SEQPACKET);
  ASSERT_GE(p.ours, 0);
  SocketCanSink sink(p.ours);
  EXPECT_FALSE(sink.listen(0x80)) << "a socketpair takes no CAN filter: refused, not fatal";
  can_frame request{};
  request.can_id = CAN_EFF_FLAG | 0x18EA8026U;  // a Request to 0x80 from 0x26
  request.len = 3;
  request.data[0] = 0xDA;
  request.data[1] = 0xFE;
  ASSERT_EQ(::send(p.theirs, &request, sizeof request, 0), static_cast<ssize_t>(sizeof request));
  can_frame remote{};
  remote.can_id = CAN_EFF_FLAG | CAN_RTR_FLAG | 0x18EA8026U;
  ASSERT_EQ(::send(p.theirs, &remote, sizeof remote, 0), static_cast<ssize_t>(sizeof remote));
  // Received between our writes: write() polls, and keeps the frame for the node.
  const CanFrame ours = frame(0x18FF1280, {1});
  sink.write(std::span(&ours, 1), Stamp{});
  std::vector<CanFrame> got;
  sink.take_received(got);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_EQ(got[0].id, 0x18EA8026U);
  EXPECT_EQ(got[0].len, 3);
  EXPECT_EQ(got[0].data[1], 0xFE);
  EXPECT_EQ(sink.stats().unexpected_reads, 1U) << "the remote frame";
  sink.take_received(got);
  EXPECT_TRUE(got.empty());
  for (std::size_t i = 0; i < SocketCanSink::kMaxReceived + 10; ++i) {
    request.data[2] = static_cast<std::uint8_t>(i);
    ASSERT_EQ(::send(p.theirs, &request, sizeof request, 0), static_cast<ssize_t>(sizeof request));
    if (i % 50 == 49) sink.poll();  // the socket buffer is smaller than the backlog
  }
  sink.poll();
  sink.take_received(got);
  ASSERT_EQ(got.size(), SocketCanSink::kMaxReceived);
  EXPECT_EQ(got.front().data[2], 0) << "the oldest kept";
  EXPECT_EQ(sink.stats().received_dropped, 10U);
  EXPECT_EQ(sink.stats().received, SocketCanSink::kMaxReceived + 1);
}

TEST(SocketCanSink, MovesKeepOneOwner) {
  Pair p(SOCK_DGRAM);
  ASSERT_GE(p.ours, 0);
  SocketCanSink a(p.ours);
  SocketCanSink b(std::move(a));
  EXPECT_EQ(a.fd(), -1);  // NOLINT(bugprone-use-after-move): checking the moved-from state
  EXPECT_EQ(b.send(frame(1, {})), SocketCanSink::SendResult::Sent);
  EXPECT_THROW(SocketCanSink(-1), std::invalid_argument);
}

// This kernel has no SocketCAN: opening a real CAN_RAW socket must fail with a clear message.
TEST(SocketCanSink, OpeningARealInterfaceFailsClearly) {
  auto r = SocketCanSink::open("fgcan9");
  if (r) GTEST_SKIP() << "this machine has a CAN interface named fgcan9";
  const std::string& e = r.error();
  EXPECT_NE(e.find("fgcan9"), std::string::npos) << e;
  const bool no_family = e.find("Address family not supported") != std::string::npos;
  const bool no_device = e.find("No such device") != std::string::npos;
  EXPECT_TRUE(no_family || no_device) << e;
  if (no_family) {
    EXPECT_NE(e.find("modprobe can_raw"), std::string::npos) << e;
  }
  EXPECT_FALSE(SocketCanSink::open("").has_value());
  EXPECT_NE(SocketCanSink::open("bad/name").error().find("bad/name"), std::string::npos);
}

}  // namespace
}  // namespace fieldguard::output
