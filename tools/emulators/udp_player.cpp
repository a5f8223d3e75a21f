// fieldguard-udp-player: plays the UDP datagrams of a capture (pcap or pcapng) to a host over real UDP
// sockets, paced by the capture's own record times: a LiDAR on the bench for the daemon's live path and
// its end-to-end tests. Each datagram goes to the port it was captured on, or to the port --map gives.
// Prints "playing N datagrams" on stdout once the capture is read, then plays; prints a summary on stderr.
// When the capture ends (and its loops), the player exits: the "sensor" falls silent. SIGTERM or SIGINT
// stops it early, still with the summary (how many datagrams went out is what a load test compares).
// --live-time restamps every HDL-32E data packet with the sending host's wall clock, as a GPS-synchronised
// sensor stamps its packets, so a looped capture's sensor clock runs on instead of jumping back at each loop.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "emulator_cli.hpp"
#include "fieldguard/io/pcap_reader.hpp"

namespace {

namespace cli = fieldguard::tools::cli;

constexpr const char* kSynopsis =
    "fieldguard-udp-player --pcap FILE [--host ADDR] [--map FROM:TO]... [--speed X] [--loop N]\n"
    "                             [--delay SECONDS] [--live-time]";

constexpr const char* kAbout =
    "Plays the UDP datagrams of a capture to a host over real UDP sockets, paced by the capture's record\n"
    "times: a LiDAR on the bench. Prints \"playing N datagrams\" on stdout once the capture is read, then\n"
    "plays, and exits when the capture (and its loops) ends; SIGTERM or SIGINT stops it early. A summary goes\n"
    "to stderr either way.";

constexpr const char* kFooter = "Exit codes: 0 played, 1 a send failed, 2 bad command line or unreadable capture.";

// "FROM:TO": a captured port (0..65535) and the port to send to (1..65535).
bool parse_map(std::string_view text, std::pair<std::uint16_t, std::uint16_t>& out) {
  const std::string m(text);
  unsigned from = 0;
  unsigned to = 0;
  char tail = 0;
  if (std::sscanf(m.c_str(), "%u:%u%c", &from, &to, &tail) != 2 || from > 65535 || to == 0 || to > 65535) return false;
  out = {static_cast<std::uint16_t>(from), static_cast<std::uint16_t>(to)};
  return true;
}

// The HDL-32E data packet and its timestamp field (protocols.md §1: u32 LE, µs past the top of the UTC hour).
constexpr std::size_t kDataPacketSize = 1206;
constexpr std::size_t kTimestampOffset = 1200;
constexpr std::int64_t kUsPerHour = 3'600'000'000LL;

void stamp_now(std::vector<std::uint8_t>& payload) {
  const std::int64_t us =
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count();
  const auto past_hour = static_cast<std::uint32_t>(((us % kUsPerHour) + kUsPerHour) % kUsPerHour);
  for (std::size_t i = 0; i < 4; ++i) payload[kTimestampOffset + i] = static_cast<std::uint8_t>(past_hour >> (8U * i));
}

volatile sig_atomic_t g_stop = 0;
extern "C" void on_stop_signal(int /*signal*/) { g_stop = 1; }

struct Datagram {
  std::int64_t t_ns;  // record time
  std::uint16_t port;
  std::vector<std::uint8_t> payload;
};

}  // namespace

int main(int argc, char** argv) {
  std::string pcap;
  std::string host = "127.0.0.1";
  std::map<std::uint16_t, std::uint16_t> map;
  double speed = 1.0;
  long loops = 1;
  double delay_s = 0.0;
  bool live_time = false;
  cli::Tool tool("fieldguard-udp-player", kSynopsis, kAbout, kFooter);
  CLI::App& app = tool.app();
  app.add_option("--pcap", pcap, "the capture to play (pcap or pcapng; every UDP datagram in it)")->type_name("FILE");
  app.add_option("--host", host, "IPv4 address to send to (default 127.0.0.1)")->type_name("ADDR");
  // Each --map adds one pair; the validator holds every one to FROM:TO.
  std::vector<std::string> maps;
  app.add_option("--map", maps,
                 "send datagrams captured on port FROM to port TO (default: the captured port);\n"
                 "datagrams on ports no --map names are skipped once any --map is given")
      ->type_name("FROM:TO")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            std::pair<std::uint16_t, std::uint16_t> m;
            return parse_map(text, m) ? "" : "wants FROM:TO ports (FROM 0..65535, TO 1..65535), not '" + text + "'";
          },
          ""));
  cli::number(app, "--speed", speed, cli::Between<double>{0.0, 1000.0},
              "1 = the capture's pace (default), 2 = twice as fast, 0 = as fast as possible")
      ->type_name("X");
  fieldguard::tools::add_loop(app, loops, "the capture");
  cli::number(app, "--delay", delay_s, cli::Between<double>{0.0, 3600.0},
              "wait this long after printing the count before the first datagram (default 0)")
      ->type_name("SECONDS");
  app.add_flag("--live-time", live_time,
               "rewrite the timestamp of every 1206-byte data packet (u32 LE at byte 1200) to the\n"
               "host's UTC wall clock in microseconds past the hour when it is sent");
  if (const auto exit_code = tool.parse(argc, argv)) return *exit_code;
  for (const std::string& text : maps) {
    std::pair<std::uint16_t, std::uint16_t> m;
    if (parse_map(text, m)) map[m.first] = m.second;
  }
  if (pcap.empty()) return tool.fail("--pcap is required");
  sockaddr_in to{};
  to.sin_family = AF_INET;
  if (::inet_pton(AF_INET, host.c_str(), &to.sin_addr) != 1)
    return tool.fail("--host: wants an IPv4 address, not '" + host + "'");

  auto reader = fieldguard::io::PcapReader::open(pcap);
  if (!reader) {
    std::fprintf(stderr, "fieldguard-udp-player: %s\n", reader.error().c_str());
    return 2;
  }
  std::vector<Datagram> datagrams;
  std::uint64_t skipped = 0;
  while (auto d = reader->next()) {
    std::uint16_t port = d->dst_port;
    if (!map.empty()) {
      const auto it = map.find(d->dst_port);
      if (it == map.end()) {
        ++skipped;
        continue;
      }
      port = it->second;
    }
    datagrams.push_back({d->host_time.ns, port, {d->payload.begin(), d->payload.end()}});
  }
  if (!reader->stats().read_error.empty()) {
    std::fprintf(stderr, "fieldguard-udp-player: %s: %s (playing what was read)\n", pcap.c_str(),
                 reader->stats().read_error.c_str());
  }
  if (datagrams.empty()) {
    std::fprintf(stderr, "fieldguard-udp-player: no datagram to play in %s\n", pcap.c_str());
    return 2;
  }

  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    std::fprintf(stderr, "fieldguard-udp-player: socket: %s\n", std::strerror(errno));
    return 1;
  }
  std::printf("playing %zu datagrams\n", datagrams.size());
  std::fflush(stdout);
  if (delay_s > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(delay_s));

  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sa.sa_flags = SA_RESTART;
  ::sigaction(SIGTERM, &sa, nullptr);
  ::sigaction(SIGINT, &sa, nullptr);
  using Clock = std::chrono::steady_clock;
  const std::int64_t span_ns = datagrams.back().t_ns - datagrams.front().t_ns;
  // One capture period between loops, so that a looped capture keeps its packet spacing at the seam.
  const std::int64_t period_ns =
      span_ns + (datagrams.size() > 1 ? span_ns / static_cast<std::int64_t>(datagrams.size() - 1) : 0);
  const Clock::time_point start = Clock::now();
  std::uint64_t sent = 0;
  std::uint64_t sent_data = 0;
  std::int64_t last_sent_us = 0;
  for (long l = 0; l < loops && g_stop == 0; ++l) {
    for (Datagram& d : datagrams) {
      if (g_stop != 0) break;
      if (speed > 0.0) {
        const double offset_s = static_cast<double>(d.t_ns - datagrams.front().t_ns + l * period_ns) * 1e-9 / speed;
        std::this_thread::sleep_until(
            start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(offset_s)));
      }
      if (live_time && d.payload.size() == kDataPacketSize) stamp_now(d.payload);
      to.sin_port = htons(d.port);
      if (::sendto(fd, d.payload.data(), d.payload.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to) !=
          static_cast<ssize_t>(d.payload.size())) {
        std::fprintf(stderr, "fieldguard-udp-player: send to %s:%u failed after %llu datagrams: %s\n", host.c_str(),
                     d.port, static_cast<unsigned long long>(sent), std::strerror(errno));
        ::close(fd);
        return 1;
      }
      // When the receiver last heard from us, on the clock its logs use: a test of a silence timeout measures
      // from here, not from when it saw this process exit (late by a scheduling delay on a loaded machine).
      last_sent_us =
          std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
              .count();
      ++sent;
      if (d.payload.size() == kDataPacketSize) ++sent_data;
    }
  }
  ::close(fd);
  const double took = std::chrono::duration<double>(Clock::now() - start).count();
  std::fprintf(stderr,
               "fieldguard-udp-player: sent %llu datagrams (%llu data packets) in %.3f s (%llu skipped by --map)%s, "
               "the last at %lld us UTC\n",
               static_cast<unsigned long long>(sent), static_cast<unsigned long long>(sent_data), took,
               static_cast<unsigned long long>(skipped), g_stop != 0 ? ", stopped by a signal" : "",
               static_cast<long long>(last_sent_us));
  return 0;
}
