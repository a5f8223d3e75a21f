// fieldguard-scip-emulator: a TCP server that answers like a Hokuyo UTM-30LX-EW speaking SCIP 2.0, so the
// daemon's 2D LiDAR client can be tested without the sensor. It streams MD/ME scans at 40 Hz of a simple
// scene (a wall ahead and, optionally, a box in front of the bumper), and can misbehave on request: drop the
// connection in the middle of a scan, send garbage, refuse to light the laser. Prints the listening port on
// stdout, one line. Serves one client at a time, any number in turn, until --max-clients or a signal.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string>
#include <string_view>
#include <vector>

#include "cli/cli.hpp"
#include "fieldguard/drivers/scip.hpp"
#include "scip_sensor.hpp"

namespace {

namespace scip = fieldguard::scip;
using Clock = std::chrono::steady_clock;

namespace cli = fieldguard::tools::cli;

constexpr const char* kSynopsis =
    "fieldguard-scip-emulator [--port N] [--scene wall|obstacle] [--drop-after N] [--garbage-after N]\n"
    "                                [--refuse-laser] [--max-clients N]";

constexpr const char* kAbout =
    "A TCP server that answers like a Hokuyo UTM-30LX-EW speaking SCIP 2.0: MD/ME scans at 40 Hz of a simple\n"
    "scene, and misbehaviour on request. Prints the listening port on stdout, one line. Serves one client at\n"
    "a time, any number in turn, until --max-clients or a signal.";

constexpr const char* kFooter = "Exit codes: 0 served --max-clients; 2 bad command line, or the port cannot be opened.";

struct Options {
  int port = 0;
  bool obstacle = true;
  long drop_after = -1;
  long garbage_after = -1;
  bool refuse_laser = false;
  long max_clients = -1;
};

// Range in mm at `step` of the emulated scene.
std::uint32_t range_mm(int step, const Options& o, std::uint32_t scan_index) {
  const double a = (step - 540) * 0.25 * std::numbers::pi / 180.0;  // + counter-clockwise, 0 = front
  const double c = std::cos(a);
  double r = 60000.0;
  if (c > 0.05) r = std::min(r, 8000.0 / c);  // the wall 8 m ahead
  const double s = std::sin(a);
  if (o.obstacle && c > 0.0) {  // box face 1.0 m ahead, |y| <= 0.3 m
    const double t = 1000.0 / c;
    if (std::fabs(t * s) <= 300.0) r = std::min(r, t);
  }
  if (r >= 60000.0) return 1;                                            // no echo: an error code below DMIN
  return static_cast<std::uint32_t>(std::lround(r)) + (scan_index % 3);  // a little life in the numbers
}

bool send_all(int fd, const std::string& s) {
  std::size_t done = 0;
  while (done < s.size()) {
    const ssize_t n = ::send(fd, s.data() + done, s.size() - done, MSG_NOSIGNAL);
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

void serve(int fd, const Options& o) {
  std::string pending;
  fieldguard::tools::ScipSensorIdentity identity;
  identity.refuse_laser = o.refuse_laser;
  fieldguard::tools::ScipSensor sensor(identity);
  std::uint32_t scans = 0;
  bool garbage_sent = false;
  const auto t0 = Clock::now();
  auto next_scan = t0;
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    const auto wait = sensor.streaming()
                          ? std::chrono::duration_cast<std::chrono::milliseconds>(next_scan - Clock::now()).count()
                          : 1000;
    const int r = ::poll(&p, 1, static_cast<int>(std::max<long long>(0, wait)));
    if (r < 0) return;
    if (r > 0) {
      char buf[512];
      const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
      if (n <= 0) return;
      pending.append(buf, static_cast<std::size_t>(n));
      std::size_t nl = 0;
      while ((nl = pending.find_first_of("\r\n")) != std::string::npos) {
        std::string line = pending.substr(0, nl);
        pending.erase(0, nl + 1);
        if (line.empty()) continue;
        const bool was_streaming = sensor.streaming();
        const std::string reply = sensor.reply(line);
        if (sensor.streaming() && !was_streaming) next_scan = Clock::now() + std::chrono::milliseconds(25);
        if (!send_all(fd, reply)) return;
      }
      if (pending.size() > 4096) return;  // a client that sends no line ends: not a SCIP client
    }
    if (sensor.streaming() && Clock::now() >= next_scan) {
      next_scan += std::chrono::milliseconds(25);
      const auto ms =
          static_cast<std::uint32_t>(std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t0).count());
      std::vector<std::uint32_t> ranges;
      std::vector<std::uint32_t> intensities;
      for (int step = sensor.first_step(); step <= sensor.last_step(); ++step) {
        ranges.push_back(range_mm(step, o, scans));
        intensities.push_back(1000 + static_cast<std::uint32_t>(step));
      }
      const std::string s = sensor.scan(ranges, intensities, ms);
      if (o.drop_after >= 0 && scans >= static_cast<std::uint32_t>(o.drop_after)) {
        send_all(fd, s.substr(0, s.size() / 2));
        return;  // the caller closes the socket in the middle of the scan
      }
      if (o.garbage_after >= 0 && !garbage_sent && scans >= static_cast<std::uint32_t>(o.garbage_after)) {
        std::string junk;
        for (int i = 0; i < 300; ++i) junk += static_cast<char>((i * 37 + 11) % 251);
        if (!send_all(fd, junk)) return;
        garbage_sent = true;
      }
      if (!send_all(fd, s)) return;
      ++scans;
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  cli::Tool tool("fieldguard-scip-emulator", kSynopsis, kAbout, kFooter);
  CLI::App& app = tool.app();
  cli::number(app, "--port", o.port, cli::Between<int>{0, 65535},
              "listen on 127.0.0.1:N (default 0: any free port; the port is printed)")
      ->type_name("N");
  cli::checked(
      app, "--scene", o.obstacle,
      [](std::string_view s, bool& obstacle) {
        obstacle = s == "obstacle";
        return obstacle || s == "wall";
      },
      [](bool /*obstacle*/) { return true; }, "wall or obstacle",
      "wall: a wall 8 m ahead; obstacle: also a 0.6 m wide box 1.0 m in front (default)")
      ->type_name("S");
  const cli::Between<long> scans{-1, 1'000'000'000};
  cli::number(app, "--drop-after", o.drop_after, scans,
              "after N scans of a connection, send half a scan and close it (each connection;\n-1, the default: never)")
      ->type_name("N");
  cli::number(app, "--garbage-after", o.garbage_after, scans,
              "after N scans of a connection, send 300 bytes of garbage once, then go on\n(-1, the default: never)")
      ->type_name("N");
  app.add_flag("--refuse-laser", o.refuse_laser, "answer BM with status 01 (laser could not be lit)");
  cli::number(app, "--max-clients", o.max_clients, scans,
              "exit after serving N connections (default: serve until killed)")
      ->type_name("N");
  if (const auto exit_code = tool.parse(argc, argv)) return *exit_code;
  const int srv = ::socket(AF_INET, SOCK_STREAM, 0);
  const int on = 1;
  ::setsockopt(srv, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(o.port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::bind(srv, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(srv, 4) != 0) {
    std::fprintf(stderr, "fieldguard-scip-emulator: cannot listen on 127.0.0.1:%d: %s\n", o.port, std::strerror(errno));
    return 2;
  }
  socklen_t len = sizeof addr;
  ::getsockname(srv, reinterpret_cast<sockaddr*>(&addr), &len);
  std::printf("%u\n", ntohs(addr.sin_port));
  std::fflush(stdout);
  for (long served = 0; o.max_clients < 0 || served < o.max_clients; ++served) {
    const int fd = ::accept(srv, nullptr, nullptr);
    if (fd < 0) continue;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
    serve(fd, o);
    ::close(fd);
  }
  ::close(srv);
  return 0;
}
