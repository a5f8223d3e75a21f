#pragma once
// `fieldguard inspect`: what one capture format plugs in (private to the app module).
// A format is a function that reads the capture in chunks through its decoder, writes one JSON line per
// decoded sample to the Output and fills in the Summary; plus, optionally, a guess from the file's first bytes.
// Adding a format: write `void inspect_xxx(Capture&, Output&, Summary&)` in src/app/inspect_xxx.cpp, declare
// it below, and add a row to kFormats in inspect.cpp.

#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/time.hpp"
#include "fieldguard/io/pcap_reader.hpp"

namespace fieldguard::app::inspect {

// UDP ports of the LiDAR formats (--data-port, --position-port); unset: the format's defaults.
struct PortOptions {
  std::optional<std::uint16_t> data;      // velodyne data (2368), robosense MSOP (6699)
  std::optional<std::uint16_t> position;  // velodyne position (8308), robosense DIFOP (7788)
};

// The capture, read in chunks of bounded size (memory stays bounded whatever the file's size). The first bytes
// were already read (to guess the format); they come first, so that pipes work as well as files.
// Read it one way only: for_each_chunk(), read() or open_stream().
class Capture {
 public:
  Capture(std::FILE* f, ByteSpan head) : f_(f), head_(head) {}
  // Calls `chunk` with the capture's bytes in order, once. False on a read error.
  bool for_each_chunk(const std::function<void(ByteSpan)>& chunk);
  // The next bytes, up to buf.size(); 0 at the end of the file or on a read error (read_error() tells).
  std::size_t read(std::span<std::uint8_t> buf);
  // The capture as a read-only stdio stream (for libpcap), starting at its first byte. The caller closes it;
  // closing it does not close the file. The Capture must outlive it.
  [[nodiscard]] std::FILE* open_stream();
  // The first bytes (up to 16 KiB), the ones the format was guessed from; they are still read by the above.
  [[nodiscard]] ByteSpan head() const { return head_; }
  [[nodiscard]] std::uint64_t bytes_read() const { return bytes_; }
  [[nodiscard]] bool read_error() const { return read_error_; }

  PortOptions ports;

 private:
  std::FILE* f_;
  ByteSpan head_;
  std::size_t head_pos_ = 0;
  std::uint64_t bytes_ = 0;
  bool read_error_ = false;
};

// stdout, one JSON object a line, written in blocks.
class Output {
 public:
  ~Output() { flush(); }
  void line(std::string json) {
    buf_ += json;
    buf_ += '\n';
    ++lines_;
    if (buf_.size() > kFlushAt) flush();
  }
  void flush() {
    if (!buf_.empty()) std::fwrite(buf_.data(), 1, buf_.size(), stdout);
    buf_.clear();
    std::fflush(stdout);
  }
  [[nodiscard]] std::uint64_t lines() const { return lines_; }

 private:
  static constexpr std::size_t kFlushAt = 1 << 16;
  std::string buf_;
  std::uint64_t lines_ = 0;
};

// What the summary on stderr reports. Rejection reasons and the extra counts are listed in a fixed order, zeros
// included, so that scripts can rely on the labels.
struct Summary {
  std::map<std::string, std::uint64_t> kinds;                     // records by kind ("GNGGA", "MTData2", ...)
  std::vector<std::pair<std::string, std::uint64_t>> rejections;  // by reason
  std::vector<std::pair<std::string, std::uint64_t>> extra;       // noise bytes, skipped ids, ...
  std::vector<std::pair<std::string, std::string>> notes;         // text: detected model, a file cut short, ...
  // Set when the capture turned out unusable (not a pcap after all, a byte log with a broken header, ...): the
  // command says this and exits 2 instead of printing the summary.
  std::string unusable;
};

// Bytes as upper-case hex digits, two per byte ("payload_hex", "data" keys).
[[nodiscard]] inline std::string hex_upper(std::span<const std::uint8_t> bytes) {
  constexpr std::string_view kHex = "0123456789ABCDEF";
  std::string s;
  s.reserve(bytes.size() * 2);
  for (const std::uint8_t b : bytes) {
    s += kHex[b >> 4];
    s += kHex[b & 0x0F];
  }
  return s;
}

// Seconds since the epoch as the double nearest to the stamp (for "time" keys).
[[nodiscard]] inline double seconds_of(Stamp t) {
  const std::int64_t s = t.ns / 1'000'000'000;
  const std::int64_t frac = t.ns % 1'000'000'000;
  return static_cast<double>(s) + static_cast<double>(frac) * 1e-9;
}

void inspect_nmea(Capture& in, Output& out, Summary& summary);
void inspect_xsens(Capture& in, Output& out, Summary& summary);
void inspect_velodyne(Capture& in, Output& out, Summary& summary);
void inspect_robosense(Capture& in, Output& out, Summary& summary);
void inspect_scip(Capture& in, Output& out, Summary& summary);
void inspect_candump(Capture& in, Output& out, Summary& summary);

[[nodiscard]] bool looks_like_nmea(ByteSpan head);
[[nodiscard]] bool looks_like_xsens(ByteSpan head);
[[nodiscard]] bool looks_like_pcap(ByteSpan head);       // classic pcap or pcapng, any content
[[nodiscard]] bool looks_like_robosense(ByteSpan head);  // a pcap whose first datagrams are RoboSense's
[[nodiscard]] bool looks_like_scip(ByteSpan head);
[[nodiscard]] bool looks_like_candump(ByteSpan head);

// ---- Shared by the pcap formats (inspect_pcap.cpp).

// What the first datagrams of a pcap in `head` look like: how many go to (or come from) each family's ports or
// have its payload sizes. Records cut by the end of `head` are not looked at.
struct PcapPeek {
  std::size_t datagrams = 0;
  std::size_t velodyne = 0;   // port 2368 / 8308, or 1206 / 512 bytes
  std::size_t robosense = 0;  // port 6699 / 7788, or 1248 bytes
};
[[nodiscard]] PcapPeek peek_pcap(ByteSpan head);

// Opens the capture as pcap or pcapng; on failure sets summary.unusable and returns nullopt.
[[nodiscard]] std::optional<io::PcapReader> open_pcap(Capture& in, Summary& summary);
// The reader's dropped frames by reason (io::FrameDrop names), as rejections, in a fixed order.
[[nodiscard]] std::vector<std::pair<std::string, std::uint64_t>> pcap_drops(const io::PcapStats& stats);
// Records and datagrams read (extra), and notes for a file cut short or a read that stopped on damage.
void add_pcap_stats(const io::PcapStats& stats, Summary& summary);

}  // namespace fieldguard::app::inspect
