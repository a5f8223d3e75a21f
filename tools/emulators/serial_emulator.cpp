// fieldguard-serial-emulator: plays a recorded NMEA or Xsens byte stream into a pseudo-terminal, paced at
// the line rate of the given baud rate (8N1: baud / 10 bytes per second), so the daemon's serial reader can
// be tested against a real tty. Prints the slave device path (or --link, a symlink to it) on stdout, one
// line, then plays. The slave side is put in raw mode and held open, so bytes written before the reader
// opens wait in the pty unchanged.

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "emulator_cli.hpp"

namespace {

namespace cli = fieldguard::tools::cli;

constexpr const char* kSynopsis =
    "fieldguard-serial-emulator --file FILE [--baud N] [--loop N] [--chunk BYTES] [--link PATH]\n"
    "                                  [--hold-open SECONDS] [--garbage-every N]";

constexpr const char* kAbout =
    "Plays a recorded byte stream into a pseudo-terminal, paced at the line rate of --baud (8N1: baud / 10\n"
    "bytes a second), so a serial reader can be tested against a real tty. Prints the slave device path (or\n"
    "--link) on stdout, one line, then plays. The slave side is raw and held open: bytes written before the\n"
    "reader opens it wait in the pty unchanged.";

constexpr const char* kFooter = "Exit codes: 0 played; 2 bad command line, unreadable file, or the pty failed.";

int fail(const std::string& what) {
  std::fprintf(stderr, "fieldguard-serial-emulator: %s\n", what.c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string file;
  std::string link;
  unsigned long baud = 115200;
  unsigned long loops = 1;
  unsigned long chunk = 64;
  unsigned long garbage_every = 0;
  double hold_open_s = 1.0;
  cli::Tool tool("fieldguard-serial-emulator", kSynopsis, kAbout, kFooter);
  CLI::App& app = tool.app();
  app.add_option("--file", file, "bytes to play (an NMEA log, an Xsens MTData2 capture, ...)")->type_name("FILE");
  cli::number(app, "--baud", baud, cli::Between<unsigned long>{0, fieldguard::tools::kMaxBaud},
              "pace at N/10 bytes per second (default 115200); 0 = as fast as the pty takes them")
      ->type_name("N");
  fieldguard::tools::add_loop(app, loops, "the file");
  cli::number(app, "--chunk", chunk, cli::Between<unsigned long>{1, 1 << 20}, "bytes per write (default 64)")
      ->type_name("BYTES");
  fieldguard::tools::add_link(app, "--link", link, "the slave device (printed in its place)");
  cli::number(app, "--hold-open", hold_open_s, cli::Between<double>{0.0, 86400.0},
              "keep the pty open S seconds after the last byte (default 1), then close it:\n"
              "the reader sees the device disappear")
      ->type_name("S");
  cli::number(app, "--garbage-every", garbage_every, cli::Between<unsigned long>{0, 1'000'000'000},
              "after every N chunks write 7 bytes of line noise (default 0 = never)")
      ->type_name("N");
  if (const auto exit_code = tool.parse(argc, argv)) return *exit_code;
  if (file.empty()) return tool.fail("--file is required");
  std::ifstream in(file, std::ios::binary);
  if (!in) return fail("cannot read " + file);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());

  const int master = ::posix_openpt(O_RDWR | O_NOCTTY);
  if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0)
    return fail(std::string("no pty: ") + std::strerror(errno));
  const std::string slave_path = ::ptsname(master);
  const int slave = ::open(slave_path.c_str(), O_RDWR | O_NOCTTY);
  if (slave < 0) return fail("cannot open " + slave_path);
  termios t{};
  ::tcgetattr(slave, &t);
  ::cfmakeraw(&t);
  ::tcsetattr(slave, TCSANOW, &t);
  if (!link.empty()) {
    std::error_code ec;
    std::filesystem::remove(link, ec);
    std::filesystem::create_symlink(slave_path, link, ec);
    if (ec) return fail("cannot link " + link + ": " + ec.message());
  }
  std::printf("%s\n", link.empty() ? slave_path.c_str() : link.c_str());
  std::fflush(stdout);

  const auto start = std::chrono::steady_clock::now();
  const double bytes_per_s = static_cast<double>(baud) / 10.0;
  std::size_t written = 0;
  unsigned long chunks = 0;
  for (unsigned long l = 0; l < loops; ++l) {
    for (std::size_t off = 0; off < bytes.size(); off += chunk) {
      const std::size_t n = std::min<std::size_t>(chunk, bytes.size() - off);
      if (baud > 0) {
        std::this_thread::sleep_until(start +
                                      std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                          std::chrono::duration<double>(static_cast<double>(written) / bytes_per_s)));
      }
      std::size_t done = 0;
      while (done < n) {
        const ssize_t w = ::write(master, bytes.data() + off + done, n - done);
        if (w < 0) {
          if (errno == EINTR) continue;
          return fail(std::string("write failed: ") + std::strerror(errno));
        }
        done += static_cast<std::size_t>(w);
      }
      written += n;
      if (garbage_every != 0 && ++chunks % garbage_every == 0) {
        const char noise[] = {'\x00', '\xFA', '\x13', '$', '\xFF', '*', '\x7F'};
        if (::write(master, noise, sizeof noise) < 0) return fail("write failed");
        written += sizeof noise;
      }
    }
  }
  ::tcdrain(master);
  std::this_thread::sleep_for(std::chrono::duration<double>(hold_open_s));
  ::close(slave);
  ::close(master);
  if (!link.empty()) {
    std::error_code ec;
    std::filesystem::remove(link, ec);
  }
  std::fprintf(stderr, "fieldguard-serial-emulator: played %zu bytes\n", written);
  return 0;
}
