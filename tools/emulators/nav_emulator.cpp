// fieldguard-nav-emulator: the tractor's navigation sensors, live, each on its own pseudo-terminal: an RTK
// GNSS receiver (NMEA GGA, RMC, HDT on the UTC grid of its rate, UTC from the host's wall clock) and an Xsens
// MTi (MTData2: PacketCounter, SampleTimeFine from a free-running 10 kHz counter, EulerAngles ENU). Unlike
// fieldguard-serial-emulator playing a recording, its clocks run on for as long as it runs, so a long
// bench test sees no clock jump. Bytes leave at the line rate of the configured baud (8N1: baud / 10 bytes a
// second), each byte readable when its transmission would be over.
//
// Prints "gnss PATH" and "ahrs PATH" (the --link, or the slave device) on stdout, then sends until killed
// (SIGTERM, SIGINT) or --duration is over, and prints a summary on stderr. Like a real serial line, bytes
// that nobody reads are lost: when kUnreadLimit bytes or more wait unread on a pty they are discarded
// (counted), so the daemon opening the device late gets live data, not a backlog.

#include <fcntl.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "emulator_cli.hpp"
#include "nav_encode.hpp"

namespace {

namespace cli = fieldguard::tools::cli;

constexpr const char* kSynopsis =
    "fieldguard-nav-emulator [--gnss-link PATH] [--ahrs-link PATH] [--gnss-rate HZ] [--ahrs-rate HZ]\n"
    "                               [--gnss-baud N] [--ahrs-baud N] [--lat DEG] [--lon DEG] [--height M]\n"
    "                               [--geoid M] [--heading DEG] [--speed MPS] [--fine-start TICKS]\n"
    "                               [--duration S]";

constexpr const char* kAbout =
    "The tractor's navigation sensors, live, each on its own pseudo-terminal: an RTK GNSS receiver (NMEA GGA,\n"
    "RMC, HDT on the UTC grid of its rate) and an Xsens MTi (MTData2: PacketCounter, SampleTimeFine, Euler\n"
    "angles ENU), at the line rate of their baud. Prints \"gnss PATH\" and \"ahrs PATH\" on stdout, then sends\n"
    "until killed or --duration is over; bytes nobody reads are lost, as on a real serial line.";

constexpr const char* kFooter = "Exit codes: 0 stopped, 1 a pty failed, 2 bad command line.";

// Bytes waiting unread on a pty before they count as lost: under the line discipline's 4096-byte buffer, which
// FIONREAD cannot see past (beyond it a write would block).
constexpr int kUnreadLimit = 2048;
constexpr double kEarthRadiusM = 6'371'000.0;
constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr std::int64_t kGnssLatencyNs = 20'000'000;  // a receiver prints its solution some 20 ms after the epoch

std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int /*signal*/) { g_stop.store(true); }

struct Settings {
  std::string gnss_link;
  std::string ahrs_link;
  double gnss_rate_hz = 10.0;
  double ahrs_rate_hz = 100.0;
  long gnss_baud = 115200;
  long ahrs_baud = 115200;
  double lat_deg = 48.1;
  double lon_deg = 11.6;
  double h_m = 520.0;
  double geoid_m = 47.0;
  double heading_deg = 60.0;
  double speed_mps = 0.0;
  std::uint32_t fine_start = 3'600'000'000U;
  double duration_s = 0.0;
};

struct Counts {
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;
  std::uint64_t discarded = 0;  // unread bytes thrown away (nobody reading)
  // How late the emulator itself started a message (a starved emulator is not the daemon's fault).
  std::int64_t max_late_ns = 0;
  std::uint64_t late_over_50ms = 0;
  void started_late(std::int64_t ns) {
    max_late_ns = std::max(max_late_ns, ns);
    if (ns > 50'000'000) ++late_over_50ms;
  }
  std::string error;
};

// A pseudo-terminal in raw mode whose slave side stays open here, so the device exists until we exit.
class Pty {
 public:
  bool open(const std::string& link, std::string& error) {
    master_ = ::posix_openpt(O_RDWR | O_NOCTTY);
    if (master_ < 0 || ::grantpt(master_) != 0 || ::unlockpt(master_) != 0) {
      error = std::string("no pty: ") + std::strerror(errno);
      return false;
    }
    path_ = ::ptsname(master_);
    slave_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY);
    if (slave_ < 0) {
      error = "cannot open " + path_ + ": " + std::strerror(errno);
      return false;
    }
    termios t{};
    ::tcgetattr(slave_, &t);
    ::cfmakeraw(&t);
    ::tcsetattr(slave_, TCSANOW, &t);
    if (!link.empty()) {
      std::error_code ec;
      std::filesystem::remove(link, ec);
      std::filesystem::create_symlink(path_, link, ec);
      if (ec) {
        error = "cannot link " + link + ": " + ec.message();
        return false;
      }
      link_ = link;
    }
    return true;
  }
  ~Pty() {
    if (!link_.empty()) {
      std::error_code ec;
      std::filesystem::remove(link_, ec);
    }
    if (slave_ >= 0) ::close(slave_);
    if (master_ >= 0) ::close(master_);
  }
  [[nodiscard]] std::string name() const { return link_.empty() ? path_ : link_; }

  // Before a message: a backlog nobody reads is gone, as on a serial line without a listener.
  void drop_unread(Counts& c) const {
    int waiting = 0;
    if (::ioctl(slave_, FIONREAD, &waiting) == 0 && waiting >= kUnreadLimit) {
      ::tcflush(slave_, TCIFLUSH);
      c.discarded += static_cast<std::uint64_t>(waiting);
    }
  }

  // Sends `bytes` at `bytes_per_s` from `start` on: each chunk is written when its last byte would have
  // crossed the line. Returns when the last byte is written; false when the pty fails.
  bool send(const std::uint8_t* bytes, std::size_t n, double bytes_per_s, Counts& c) const {
    constexpr std::size_t kChunk = 16;
    using Clock = std::chrono::steady_clock;
    const Clock::time_point start = Clock::now();
    for (std::size_t off = 0; off < n; off += kChunk) {
      const std::size_t len = std::min(kChunk, n - off);
      std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                                static_cast<double>(off + len) / bytes_per_s)));
      std::size_t done = 0;
      while (done < len) {
        const ssize_t w = ::write(master_, bytes + off + done, len - done);
        if (w < 0) {
          if (errno == EINTR && !g_stop.load()) continue;
          if (errno == EINTR) return true;  // stopping
          c.error = "write to " + path_ + " failed: " + std::strerror(errno);
          return false;
        }
        done += static_cast<std::size_t>(w);
      }
    }
    c.bytes += n;
    return true;
  }

 private:
  int master_ = -1;
  int slave_ = -1;
  std::string path_;
  std::string link_;
};

std::int64_t utc_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

double wrap_deg(double a) {
  a = std::fmod(a, 360.0);
  if (a <= -180.0) a += 360.0;
  if (a > 180.0) a -= 360.0;
  return a;
}

// The receiver's epoch at UTC `utc_ns`, `t_s` seconds after the emulator started: the antenna driven
// straight along the heading from the start point (a local flat-earth step: metres over a 10-minute run).
fieldguard::tools::GnssEpoch gnss_epoch(const Settings& s, std::int64_t utc_ns, double t_s) {
  const double d = s.speed_mps * t_s;
  const double north = d * std::cos(s.heading_deg * kDegToRad);
  const double east = d * std::sin(s.heading_deg * kDegToRad);
  fieldguard::tools::GnssEpoch e;
  e.utc_ns = utc_ns;
  e.lat_deg = s.lat_deg + north / kEarthRadiusM / kDegToRad;
  e.lon_deg = s.lon_deg + east / (kEarthRadiusM * std::cos(s.lat_deg * kDegToRad)) / kDegToRad;
  e.h_m = s.h_m;
  e.geoid_separation_m = s.geoid_m;
  e.satellites = 18;
  e.speed_mps = s.speed_mps;
  if (s.speed_mps > 0.1) e.course_deg = std::fmod(s.heading_deg + 360.0, 360.0);
  e.heading_deg = std::fmod(s.heading_deg + 360.0, 360.0);
  return e;
}

std::vector<std::uint8_t> epoch_bytes(const fieldguard::tools::GnssEpoch& e) {
  std::vector<std::uint8_t> out;
  for (const std::string& line : fieldguard::tools::nmea_epoch(e)) out.insert(out.end(), line.begin(), line.end());
  return out;
}

// Sample k: a gentle rocking (roll +-1 deg over 10 s, pitch +-0.5 deg over 7 s); yaw is the heading in ENU.
fieldguard::tools::AhrsSample ahrs_sample(const Settings& s, std::uint64_t k) {
  const double t = static_cast<double>(k) / s.ahrs_rate_hz;
  fieldguard::tools::AhrsSample a;
  a.packet_counter = static_cast<std::uint16_t>(k & 0xFFFFU);
  // The counter is the sensor's own clock: whole ticks of 10 kHz, wrapping at 32 bits.
  a.sample_time_fine = static_cast<std::uint32_t>(
      (static_cast<std::uint64_t>(s.fine_start) + static_cast<std::uint64_t>(std::llround(t * 10000.0))) &
      0xFFFFFFFFULL);
  a.roll_deg = 1.0 * std::sin(2.0 * std::numbers::pi * t / 10.0);
  a.pitch_deg = 0.5 * std::sin(2.0 * std::numbers::pi * t / 7.0);
  a.yaw_deg = wrap_deg(90.0 - s.heading_deg);
  return a;
}

void run_gnss(const Settings& s, const Pty& pty, std::int64_t start_utc_ns, Counts& c) {
  const auto period_ns = static_cast<std::int64_t>(std::llround(1e9 / s.gnss_rate_hz));
  const double bytes_per_s = static_cast<double>(s.gnss_baud) / 10.0;
  // Epochs on the UTC grid of the rate (10 Hz: every tenth), the first one after the start.
  for (std::int64_t epoch = (start_utc_ns / period_ns + 1) * period_ns; !g_stop.load(); epoch += period_ns) {
    const std::int64_t print_at = epoch + kGnssLatencyNs;
    while (!g_stop.load()) {
      const std::int64_t wait = print_at - utc_now_ns();
      if (wait <= 0) break;
      std::this_thread::sleep_for(std::chrono::nanoseconds(std::min<std::int64_t>(wait, 50'000'000)));
    }
    if (g_stop.load()) return;
    c.started_late(utc_now_ns() - print_at);
    const std::vector<std::uint8_t> bytes =
        epoch_bytes(gnss_epoch(s, epoch, static_cast<double>(epoch - start_utc_ns) * 1e-9));
    pty.drop_unread(c);
    if (!pty.send(bytes.data(), bytes.size(), bytes_per_s, c)) {
      g_stop.store(true);
      return;
    }
    ++c.messages;
  }
}

void run_ahrs(const Settings& s, const Pty& pty, Counts& c) {
  using Clock = std::chrono::steady_clock;
  const double bytes_per_s = static_cast<double>(s.ahrs_baud) / 10.0;
  const Clock::time_point start = Clock::now();
  for (std::uint64_t k = 0; !g_stop.load(); ++k) {
    // Sampled at start + k / rate; late (a busy host) means sent late, never skipped: the counters run on.
    const auto at = start + std::chrono::duration_cast<Clock::duration>(
                                std::chrono::duration<double>(static_cast<double>(k) / s.ahrs_rate_hz));
    while (!g_stop.load() && Clock::now() < at) {
      std::this_thread::sleep_until(std::min(at, Clock::now() + std::chrono::milliseconds(50)));
    }
    if (g_stop.load()) return;
    c.started_late(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - at).count());
    const std::vector<std::uint8_t> frame = fieldguard::tools::mtdata2_frame(ahrs_sample(s, k));
    pty.drop_unread(c);
    if (!pty.send(frame.data(), frame.size(), bytes_per_s, c)) {
      g_stop.store(true);
      return;
    }
    ++c.messages;
  }
}

}  // namespace

int main(int argc, char** argv) {
  Settings s;
  cli::Tool tool("fieldguard-nav-emulator", kSynopsis, kAbout, kFooter);
  CLI::App& app = tool.app();
  fieldguard::tools::add_link(app, "--gnss-link", s.gnss_link, "the GNSS pty's slave device");
  fieldguard::tools::add_link(app, "--ahrs-link", s.ahrs_link, "the AHRS pty's slave device");
  cli::number(app, "--gnss-rate", s.gnss_rate_hz, cli::Between<double>{0.1, 100.0},
              "NMEA epochs (GGA, RMC, HDT) a second, on the UTC grid (default 10)")
      ->type_name("HZ");
  cli::number(app, "--ahrs-rate", s.ahrs_rate_hz, cli::Between<double>{1.0, 2000.0},
              "MTData2 messages a second (default 100)")
      ->type_name("HZ");
  const cli::Between<long> baud{300, fieldguard::tools::kMaxBaud};
  cli::number(app, "--gnss-baud", s.gnss_baud, baud,
              "line rate of the GNSS (default 115200); the epochs must fit in it")
      ->type_name("N");
  cli::number(app, "--ahrs-baud", s.ahrs_baud, baud, "line rate of the AHRS (default 115200)")->type_name("N");
  cli::number(app, "--lat", s.lat_deg, cli::Between<double>{-89.0, 89.0},
              "latitude where the antenna starts (default 48.1 N: a field north of Munich)")
      ->type_name("DEG");
  cli::number(app, "--lon", s.lon_deg, cli::Between<double>{-180.0, 180.0}, "its longitude (default 11.6 E)")
      ->type_name("DEG");
  cli::number(app, "--height", s.h_m, cli::Between<double>{-1000.0, 10000.0}, "its ellipsoidal height (default 520)")
      ->type_name("M");
  cli::number(app, "--geoid", s.geoid_m, cli::Between<double>{-150.0, 150.0},
              "geoid separation GGA reports (default 47)")
      ->type_name("M");
  cli::number(app, "--heading", s.heading_deg, cli::Between<double>{0.0, 360.0},
              "the tractor's compass heading (default 60)")
      ->type_name("DEG");
  cli::number(app, "--speed", s.speed_mps, cli::Between<double>{0.0, 20.0},
              "it drives straight along the heading at this speed (default 0: standing)")
      ->type_name("MPS");
  cli::number(app, "--fine-start", s.fine_start, cli::Between<std::uint32_t>{0, 4'294'967'295U},
              "the AHRS's SampleTimeFine at start (default 3600000000: wraps after about 7 min)")
      ->type_name("TICKS");
  cli::number(app, "--duration", s.duration_s, cli::Between<double>{0.0, 1e7},
              "stop after S seconds (default 0: run until killed)")
      ->type_name("S");
  if (const auto exit_code = tool.parse(argc, argv)) return *exit_code;

  // A sensor configured for more than its line carries would fall ever further behind: refuse it.
  const double gnss_load = static_cast<double>(epoch_bytes(gnss_epoch(s, utc_now_ns(), 0.0)).size()) * s.gnss_rate_hz;
  const double ahrs_load =
      static_cast<double>(fieldguard::tools::mtdata2_frame(ahrs_sample(s, 0)).size()) * s.ahrs_rate_hz;
  if (gnss_load > 0.9 * static_cast<double>(s.gnss_baud) / 10.0) {
    return tool.fail("the GNSS epochs need " + std::to_string(static_cast<long>(gnss_load * 10.0)) +
                     " baud, more than 90 % of --gnss-baud " + std::to_string(s.gnss_baud));
  }
  if (ahrs_load > 0.9 * static_cast<double>(s.ahrs_baud) / 10.0) {
    return tool.fail("the AHRS messages need " + std::to_string(static_cast<long>(ahrs_load * 10.0)) +
                     " baud, more than 90 % of --ahrs-baud " + std::to_string(s.ahrs_baud));
  }

  Pty gnss;
  Pty ahrs;
  std::string error;
  if (!gnss.open(s.gnss_link, error) || !ahrs.open(s.ahrs_link, error)) {
    std::fprintf(stderr, "fieldguard-nav-emulator: %s\n", error.c_str());
    return 1;
  }
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  ::sigaction(SIGTERM, &sa, nullptr);
  ::sigaction(SIGINT, &sa, nullptr);
  std::printf("gnss %s\nahrs %s\n", gnss.name().c_str(), ahrs.name().c_str());
  std::fflush(stdout);

  const auto start = std::chrono::steady_clock::now();
  Counts gc;
  Counts ac;
  std::thread gnss_thread(run_gnss, std::cref(s), std::cref(gnss), utc_now_ns(), std::ref(gc));
  std::thread ahrs_thread(run_ahrs, std::cref(s), std::cref(ahrs), std::ref(ac));
  while (!g_stop.load()) {
    if (s.duration_s > 0.0 && std::chrono::steady_clock::now() - start >= std::chrono::duration<double>(s.duration_s))
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  g_stop.store(true);
  gnss_thread.join();
  ahrs_thread.join();
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::fprintf(stderr,
               "fieldguard-nav-emulator: %.3f s: gnss %llu epochs (%llu bytes, %llu discarded unread; started late by "
               "up to %.1f ms, %llu over 50 ms), ahrs %llu messages (%llu bytes, %llu discarded unread; started late "
               "by up to %.1f ms, %llu over 50 ms)\n",
               took, static_cast<unsigned long long>(gc.messages), static_cast<unsigned long long>(gc.bytes),
               static_cast<unsigned long long>(gc.discarded), static_cast<double>(gc.max_late_ns) * 1e-6,
               static_cast<unsigned long long>(gc.late_over_50ms), static_cast<unsigned long long>(ac.messages),
               static_cast<unsigned long long>(ac.bytes), static_cast<unsigned long long>(ac.discarded),
               static_cast<double>(ac.max_late_ns) * 1e-6, static_cast<unsigned long long>(ac.late_over_50ms));
  for (const Counts* c : {&gc, &ac}) {
    if (!c->error.empty()) {
      std::fprintf(stderr, "fieldguard-nav-emulator: %s\n", c->error.c_str());
      return 1;
    }
  }
  return 0;
}
