// fieldguard-nav-emulator, the live GNSS receiver and MTi of the load test: read back from its two ptys with
// the drivers' own stream parsers, at the rates asked, with clocks that only run forward, bytes at the baud
// rate, and no backlog for a late reader.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <thread>
#include <utility>
#include <variant>
#include <vector>

#include "fieldguard/drivers/nmea_stream.hpp"
#include "fieldguard/drivers/xsens_stream.hpp"
#include "support/child_process.hpp"

namespace fieldguard::io {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("fg-nav-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

int open_tty(const fs::path& p) { return ::open(p.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC); }

// The emulator's two link lines ("gnss PATH", "ahrs PATH", in that order) and both ttys opened: their fds, -1 for
// one that could not be opened or was not announced as expected.
std::pair<int, int> open_links(testing::ChildProcess& emu, const fs::path& dir) {
  const bool gnss_said = emu.line() == "gnss " + (dir / "gnss").string();
  const bool ahrs_said = emu.line() == "ahrs " + (dir / "ahrs").string();
  EXPECT_TRUE(gnss_said && ahrs_said) << "the emulator did not announce its links";
  return {gnss_said ? open_tty(dir / "gnss") : -1, ahrs_said ? open_tty(dir / "ahrs") : -1};
}

// Reads both devices for `seconds`, handing each read's bytes and its arrival time to the callbacks.
template <typename OnGnss, typename OnAhrs>
void read_for(int gnss, int ahrs, double seconds, OnGnss on_gnss, OnAhrs on_ahrs) {
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  std::vector<std::uint8_t> buf(4096);
  while (Clock::now() < end) {
    pollfd fds[2] = {{gnss, POLLIN, 0}, {ahrs, POLLIN, 0}};
    if (::poll(fds, 2, 20) <= 0) continue;
    for (int i = 0; i < 2; ++i) {
      if ((fds[i].revents & POLLIN) == 0) continue;
      const ssize_t n = ::read(fds[i].fd, buf.data(), buf.size());
      if (n <= 0) continue;
      const ByteSpan bytes(buf.data(), static_cast<std::size_t>(n));
      if (i == 0)
        on_gnss(bytes, Clock::now());
      else
        on_ahrs(bytes, Clock::now());
    }
  }
}

double wall_seconds_of_day() {
  const double s = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  return std::fmod(s, 86400.0);
}

TEST(NavEmulator, SendsGnssAndAhrsAtTheirRatesWithClocksThatRunForward) {
  const fs::path dir = temp_dir("rates");
  testing::ChildProcess emu({FIELDGUARD_NAV_EMULATOR, "--gnss-link", (dir / "gnss").string(), "--ahrs-link",
                             (dir / "ahrs").string(), "--lat", "48.2", "--lon", "11.5", "--heading", "90"});
  const auto links = open_links(emu, dir);
  ASSERT_TRUE(links.first >= 0 && links.second >= 0) << "gnss fd " << links.first << ", ahrs fd " << links.second;
  const int gnss = links.first;
  const int ahrs = links.second;
  nmea::StreamParser nmea_parser;
  xsens::StreamParser xsens_parser;
  std::vector<nmea::Sentence> sentences;
  std::vector<xsens::StreamItem> items;
  // What waited in the ptys before they were opened is decoded too (a pty's backlog starts on a message, even
  // after the emulator dropped unread bytes), but the rates count only what arrives while the test times.
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  std::vector<std::uint8_t> stale(65536);
  for (ssize_t n = 0; (n = ::read(gnss, stale.data(), stale.size())) > 0;) {
    nmea_parser.push(ByteSpan(stale.data(), static_cast<std::size_t>(n)), sentences);
  }
  for (ssize_t n = 0; (n = ::read(ahrs, stale.data(), stale.size())) > 0;) {
    xsens_parser.push(ByteSpan(stale.data(), static_cast<std::size_t>(n)), items);
  }
  const std::size_t sentences_before = sentences.size();
  const std::size_t items_before = items.size();
  constexpr double kSeconds = 1.5;
  const double wall_at_start = wall_seconds_of_day();
  read_for(
      gnss, ahrs, kSeconds, [&](ByteSpan b, Clock::time_point) { nmea_parser.push(b, sentences); },
      [&](ByteSpan b, Clock::time_point) { xsens_parser.push(b, items); });
  ::close(gnss);
  ::close(ahrs);

  // Every byte is part of a good sentence or frame.
  EXPECT_EQ(nmea_parser.counters().rejected(), 0U);
  EXPECT_EQ(nmea_parser.counters().noise_bytes, 0U);
  EXPECT_EQ(xsens_parser.counters().rejected(), 0U);
  EXPECT_EQ(xsens_parser.counters().garbage_bytes, 0U);
  EXPECT_EQ(xsens_parser.counters().unknown_data_ids, 0U);

  std::vector<nmea::Gga> gga;
  std::size_t gga_timed = 0;
  std::size_t rmc = 0;
  std::size_t hdt = 0;
  for (std::size_t i = 0; i < sentences.size(); ++i) {
    const nmea::Sentence& s = sentences[i];
    if (std::holds_alternative<nmea::Gga>(s) && i >= sentences_before) ++gga_timed;
    if (const auto* g = std::get_if<nmea::Gga>(&s)) gga.push_back(*g);
    if (const auto* r = std::get_if<nmea::Rmc>(&s)) {
      ++rmc;
      EXPECT_EQ(r->status, 'A');
      ASSERT_TRUE(r->speed_mps.has_value());
      EXPECT_EQ(*r->speed_mps, 0.0);
      EXPECT_FALSE(r->course_deg.has_value());  // standing: no course over ground
    }
    if (const auto* h = std::get_if<nmea::Hdt>(&s)) {
      ++hdt;
      ASSERT_TRUE(h->heading_deg.has_value());
      EXPECT_DOUBLE_EQ(*h->heading_deg, 90.0);
    }
  }
  // 10 Hz for 1.5 s: 15 epochs, give or take the load of a shared test machine.
  EXPECT_GE(gga_timed, 11U);
  EXPECT_LE(gga_timed, 17U);
  EXPECT_LE(rmc > gga.size() ? rmc - gga.size() : gga.size() - rmc, 1U);
  EXPECT_LE(hdt > gga.size() ? hdt - gga.size() : gga.size() - hdt, 1U);
  for (std::size_t i = 0; i < gga.size(); ++i) {
    const nmea::Gga& g = gga[i];
    ASSERT_TRUE(g.utc_seconds_of_day && g.quality && g.lat_deg && g.lon_deg && g.alt_m && g.geoid_sep_m);
    EXPECT_EQ(*g.quality, 4);  // RTK fixed
    EXPECT_NEAR(*g.lat_deg, 48.2, 1e-7);
    EXPECT_NEAR(*g.lon_deg, 11.5, 1e-7);
    EXPECT_NEAR(*g.alt_m + *g.geoid_sep_m, 520.0, 1e-3);
    // UTC from the wall clock, on the tenth, one tenth after the last.
    double behind = wall_at_start - *g.utc_seconds_of_day;
    if (behind > 43200.0) behind -= 86400.0;  // across midnight
    EXPECT_LT(std::abs(behind), 3.0) << i;
    const double tenths = *g.utc_seconds_of_day * 10.0;
    EXPECT_NEAR(tenths, std::round(tenths), 1e-6) << i;
    if (i > 0) {
      double step = *g.utc_seconds_of_day - *gga[i - 1].utc_seconds_of_day;
      if (step < -43200.0) step += 86400.0;
      EXPECT_NEAR(step, 0.1, 1e-6) << i;
    }
  }

  std::vector<xsens::MtData2> ahrs_samples;
  std::size_t ahrs_timed = 0;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (const auto* m = std::get_if<xsens::MtData2>(&items[i])) {
      ahrs_samples.push_back(*m);
      if (i >= items_before) ++ahrs_timed;
    }
  }
  // 100 Hz for 1.5 s.
  EXPECT_GE(ahrs_timed, 110U);
  EXPECT_LE(ahrs_timed, 170U);
  for (std::size_t i = 0; i < ahrs_samples.size(); ++i) {
    const xsens::MtData2& m = ahrs_samples[i];
    ASSERT_TRUE(m.packet_counter && m.sample_time_fine && m.euler_deg);
    EXPECT_LE(std::abs(m.euler_deg->x), 1.0 + 1e-5);
    EXPECT_LE(std::abs(m.euler_deg->y), 0.5 + 1e-5);
    EXPECT_NEAR(m.euler_deg->z, 0.0, 1e-5);  // heading 90 (east) is ENU yaw 0
    if (i > 0) {
      // Every sample, in order: the counter one up, the 10 kHz clock 100 ticks (10 ms) up, wrapping.
      EXPECT_EQ(static_cast<std::uint16_t>(*m.packet_counter - *ahrs_samples[i - 1].packet_counter), 1U) << i;
      EXPECT_EQ(static_cast<std::uint32_t>(*m.sample_time_fine - *ahrs_samples[i - 1].sample_time_fine), 100U) << i;
    }
  }
  emu.signal(SIGTERM);
  EXPECT_EQ(emu.wait(), 0);
  // The links go with it.
  EXPECT_FALSE(fs::exists(fs::symlink_status(dir / "gnss")));
  EXPECT_FALSE(fs::exists(fs::symlink_status(dir / "ahrs")));
  fs::remove_all(dir);
}

TEST(NavEmulator, BytesCrossTheLineAtTheBaudRate) {
  const fs::path dir = temp_dir("baud");
  // 4800 baud: 480 bytes a second; an epoch (GGA + RMC + HDT, about 190 bytes) takes about 0.4 s.
  testing::ChildProcess emu({FIELDGUARD_NAV_EMULATOR, "--gnss-link", (dir / "gnss").string(), "--ahrs-link",
                             (dir / "ahrs").string(), "--gnss-baud", "4800", "--gnss-rate", "1"});
  const auto links = open_links(emu, dir);
  ASSERT_TRUE(links.first >= 0 && links.second >= 0) << "gnss fd " << links.first << ", ahrs fd " << links.second;
  const int gnss = links.first;
  const int ahrs = links.second;
  // The second epoch is timed whole: from its first bytes to its HDT, the sentences' bytes over 480 per second.
  nmea::StreamParser parser;
  std::vector<nmea::Sentence> sentences;
  int epochs_done = 0;
  bool timing = false;
  Clock::time_point first_bytes{};
  Clock::time_point hdt_done{};
  std::size_t epoch_bytes = 0;
  std::size_t first_read = 0;
  read_for(
      gnss, ahrs, 3.2,
      [&](ByteSpan b, Clock::time_point at) {
        if (epochs_done == 1 && !timing) {
          timing = true;
          first_bytes = at;
          first_read = b.size();
        }
        if (timing && epochs_done == 1) epoch_bytes += b.size();
        const std::size_t before = sentences.size();
        parser.push(b, sentences);
        for (std::size_t i = before; i < sentences.size(); ++i) {
          if (std::holds_alternative<nmea::Hdt>(sentences[i]) && ++epochs_done == 2) hdt_done = at;
        }
      },
      [](ByteSpan, Clock::time_point) {});
  ::close(gnss);
  ::close(ahrs);
  ASSERT_GE(epochs_done, 2);
  ASSERT_GT(epoch_bytes, 150U);
  const double took = std::chrono::duration<double>(hdt_done - first_bytes).count();
  // Paced, the epoch trickles in; sent at once, the first read would hold all of it.
  EXPECT_LT(first_read, epoch_bytes / 2);
  // Bytes after the first read (less the 16-byte chunk that may just have missed it) came at the line rate.
  EXPECT_GE(took, static_cast<double>(epoch_bytes - first_read - 16) / 480.0 - 0.005);
  fs::remove_all(dir);
}

TEST(NavEmulator, AReaderThatOpensLateGetsLiveDataNotABacklog) {
  const fs::path dir = temp_dir("late");
  testing::ChildProcess emu({FIELDGUARD_NAV_EMULATOR, "--gnss-link", (dir / "gnss").string(), "--ahrs-link",
                             (dir / "ahrs").string(), "--fine-start", "4294967000"});
  ASSERT_EQ(emu.line(), "gnss " + (dir / "gnss").string());
  ASSERT_EQ(emu.line(), "ahrs " + (dir / "ahrs").string());
  // 100 messages of 32 bytes a second: after 2.5 s, 8000 bytes were sent; beyond 2048 unread they are dropped.
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  const int ahrs = open_tty(dir / "ahrs");
  ASSERT_GE(ahrs, 0);
  std::vector<std::uint8_t> buf(65536);
  const ssize_t n = ::read(ahrs, buf.data(), buf.size());
  ASSERT_GT(n, 0);
  EXPECT_LE(n, 2048 + 64);
  xsens::StreamParser parser;
  std::vector<xsens::StreamItem> items;
  parser.push(ByteSpan(buf.data(), static_cast<std::size_t>(n)), items);
  ASSERT_FALSE(items.empty());
  const auto* first = std::get_if<xsens::MtData2>(&items.front());
  ASSERT_NE(first, nullptr);
  ASSERT_TRUE(first->packet_counter && first->sample_time_fine);
  EXPECT_GT(*first->packet_counter, 0U);  // the oldest samples are gone
  // The counter started 296 ticks before its 32-bit wrap: wrapped long before this sample.
  EXPECT_LT(*first->sample_time_fine, 1'000'000U);
  ::close(ahrs);
  fs::remove_all(dir);
}

TEST(NavEmulator, DurationEndsItAndBadCommandLinesExitTwo) {
  {
    const fs::path dir = temp_dir("duration");
    const auto t0 = Clock::now();
    testing::ChildProcess emu({FIELDGUARD_NAV_EMULATOR, "--gnss-link", (dir / "gnss").string(), "--ahrs-link",
                               (dir / "ahrs").string(), "--duration", "0.5"});
    EXPECT_EQ(emu.line(), "gnss " + (dir / "gnss").string());
    EXPECT_EQ(emu.wait(), 0);
    EXPECT_GE(std::chrono::duration<double>(Clock::now() - t0).count(), 0.5);
    EXPECT_FALSE(fs::exists(fs::symlink_status(dir / "gnss")));
    fs::remove_all(dir);
  }
  for (const std::vector<std::string>& args :
       std::vector<std::vector<std::string>>{{"--ahrs-baud", "9600"},  // 100 x 32 bytes a second need 32000 baud
                                             {"--gnss-baud", "1200"},  // 10 epochs of ~190 bytes need 19000 baud
                                             {"--gnss-rate", "fast"},
                                             {"--lat", "95"},
                                             {"--bogus"}}) {
    std::vector<std::string> argv{FIELDGUARD_NAV_EMULATOR};
    argv.insert(argv.end(), args.begin(), args.end());
    testing::ChildProcess emu(argv);
    EXPECT_EQ(emu.wait(), 2) << args[0];
  }
}

}  // namespace
}  // namespace fieldguard::io
