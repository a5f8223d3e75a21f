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
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fieldguard/core/bytes.hpp"

namespace fieldguard::app::inspect {

// The capture, read in chunks of bounded size (memory stays bounded whatever the file's size). The first bytes
// were already read (to guess the format); they come first, so that pipes work as well as files.
class Capture {
 public:
  Capture(std::FILE* f, ByteSpan head) : f_(f), head_(head) {}
  // Calls `chunk` with the capture's bytes in order, once. False on a read error.
  bool for_each_chunk(const std::function<void(ByteSpan)>& chunk);
  [[nodiscard]] std::uint64_t bytes_read() const { return bytes_; }
  [[nodiscard]] bool read_error() const { return read_error_; }

 private:
  std::FILE* f_;
  ByteSpan head_;
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
  std::map<std::string, std::uint64_t> kinds;                      // records by kind ("GNGGA", "MTData2", ...)
  std::vector<std::pair<std::string, std::uint64_t>> rejections;  // by reason
  std::vector<std::pair<std::string, std::uint64_t>> extra;       // noise bytes, skipped ids, ...
};

void inspect_nmea(Capture& in, Output& out, Summary& summary);
void inspect_xsens(Capture& in, Output& out, Summary& summary);

[[nodiscard]] bool looks_like_nmea(ByteSpan head);
[[nodiscard]] bool looks_like_xsens(ByteSpan head);

}  // namespace fieldguard::app::inspect
