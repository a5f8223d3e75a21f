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

#include "options.hpp"

namespace {

constexpr const char* kUsage =
    "usage: fieldguard-serial-emulator --file FILE [--baud N] [--loop N] [--chunk BYTES] [--link PATH]\n"
    "                                  [--hold-open SECONDS] [--garbage-every N]\n"
    "  --file FILE        bytes to play (an NMEA log, an Xsens MTData2 capture, ...)\n"
    "  --baud N           pace at N/10 bytes per second (default 115200); 0 = as fast as the pty takes them\n"
    "  --loop N           play the file N times (default 1)\n"
    "  --chunk BYTES      bytes per write (default 64)\n"
    "  --link PATH        also make PATH a symlink to the slave device (like /dev/serial/by-id/...)\n"
    "  --hold-open S      keep the pty open S seconds after the last byte (default 1), then close it:\n"
    "                     the reader sees the device disappear\n"
    "  --garbage-every N  after every N chunks write 7 bytes of line noise (default 0 = never)\n";

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
  fieldguard::tools::Options opt(argc, argv, "fieldguard-serial-emulator", kUsage);
  while (opt.next()) {
    if (opt.is("--file")) file = opt.text();
    else if (opt.is("--baud")) baud = static_cast<unsigned long>(opt.integer(0, 4'000'000));
    else if (opt.is("--loop")) loops = static_cast<unsigned long>(opt.integer(1, 1'000'000));
    else if (opt.is("--chunk")) chunk = static_cast<unsigned long>(opt.integer(1, 1 << 20));
    else if (opt.is("--link")) link = opt.text();
    else if (opt.is("--hold-open")) hold_open_s = opt.number(0.0, 86400.0);
    else if (opt.is("--garbage-every")) garbage_every = static_cast<unsigned long>(opt.integer(0, 1'000'000'000));
    else opt.unknown();
  }
  if (file.empty()) return fail("--file is required");
  std::ifstream in(file, std::ios::binary);
  if (!in) return fail("cannot read " + file);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());

  const int master = ::posix_openpt(O_RDWR | O_NOCTTY);
  if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0) return fail(std::string("no pty: ") + std::strerror(errno));
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
        std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
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
