#pragma once
// Push-style NMEA 0183 stream splitter: bytes as they arrive (any chunking: a sentence split across reads,
// several in one read), decoded sentences out, everything else counted. Pure: no I/O, no logging.
//
// Framing: a sentence starts at '$' and ends after the two digits of its "*hh", or at CR or LF when it has no
// '*' (CR LF, LF and CR alone all work). Bytes outside a sentence are noise (binary garbage, JSON, text after a
// checksum, ...), except the line terminators themselves. A line that starts with '#' is noise to its end, '$'
// included (gpsd log comments, NovAtel ASCII logs). A '$' inside a sentence starts a new one; the cut-off one is
// counted as interrupted.
// Memory is bounded whatever the input: one sentence of at most kMaxSentenceLength bytes is buffered; a longer
// one is dropped (too_long) without being stored.
//
// Thread contract: thread-compatible (one instance per stream, used by one thread at a time).

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "fieldguard/drivers/nmea.hpp"

namespace fieldguard::nmea {

struct StreamCounters {
  std::uint64_t sentences = 0;     // sentences seen (from '$' to the line end): accepted + every rejection below
  std::uint64_t accepted = 0;      // decoded and handed out
  std::uint64_t bad_checksum = 0;  // '*hh' wrong, or not at the end
  std::uint64_t no_checksum = 0;   // no '*hh' (and unchecked sentences not accepted)
  std::uint64_t too_long = 0;      // over kMaxSentenceLength
  std::uint64_t bad_field = 0;     // checksum right, content not (a number that is not one, too few fields, ...)
  std::uint64_t unsupported = 0;   // a valid sentence of a type we do not decode (GSV, GSA, proprietary, ...)
  std::uint64_t interrupted = 0;   // cut off by the next '$' before its line end
  std::uint64_t noise_bytes = 0;   // bytes outside any sentence, line terminators excluded

  [[nodiscard]] std::uint64_t rejected() const {
    return bad_checksum + no_checksum + too_long + bad_field + unsupported + interrupted;
  }
};

struct StreamOptions {
  bool require_checksum = true;  // false: sentences without "*hh" are decoded unchecked (old devices)
};

class StreamParser {
 public:
  explicit StreamParser(StreamOptions options = {}) : options_(options) {}

  // Feeds the next bytes; appends every sentence completed by them to `out` (which is not cleared).
  void push(std::span<const std::uint8_t> bytes, std::vector<Sentence>& out);
  void push(std::string_view bytes, std::vector<Sentence>& out);

  // End of input: a last sentence without a line terminator is decoded as if it had one.
  void finish(std::vector<Sentence>& out);

  [[nodiscard]] const StreamCounters& counters() const { return counters_; }

 private:
  void push_byte(char c, std::vector<Sentence>& out);
  void end_sentence(std::vector<Sentence>& out);

  StreamOptions options_;
  std::array<char, kMaxSentenceLength> buf_{};
  std::size_t len_ = 0;
  std::size_t star_ = 0;  // position of the first '*' in buf_, 0 when none yet
  bool in_sentence_ = false;
  bool in_comment_ = false;    // in a line that started with '#'
  bool at_line_start_ = true;  // the next byte starts a line
  bool overflow_ = false;      // the current sentence outgrew buf_: it is dropped at its end
  StreamCounters counters_;
};

}  // namespace fieldguard::nmea
