#pragma once
// Push-style Xsens Xbus stream parser: bytes as they arrive (any chunking), messages out, resynchronising after
// garbage, a corrupted length or a bad checksum by searching for the next 0xFA 0xFF from the byte after the
// rejected preamble (so a real frame hidden inside a false one is still found). Pure: no I/O, no logging.
// Memory is bounded: the buffer never holds more than 2 * kMaxFrameSize bytes whatever the input.
//
// Thread contract: thread-compatible (one instance per stream, used by one thread at a time).

#include <cstdint>
#include <variant>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/drivers/xsens.hpp"
#include "fieldguard/drivers/xsens_mtdata2.hpp"

namespace fieldguard::xsens {

struct StreamCounters {
  std::uint64_t messages = 0;          // frames with a good checksum (MTData2 or other)
  std::uint64_t mtdata2 = 0;           // MTData2 messages decoded and handed out
  std::uint64_t other_messages = 0;    // good frames of other message ids, handed out as RawMessage
  std::uint64_t bad_checksum = 0;      // candidate frames whose checksum failed
  std::uint64_t too_long = 0;          // candidate frames with a length over kMaxPayload
  std::uint64_t truncated_packet = 0;  // MTData2 with a packet running past the payload end (message dropped)
  std::uint64_t bad_packet_size = 0;   // MTData2 with a known data id of the wrong size (message dropped)
  std::uint64_t truncated_frame = 0;   // a frame cut off by the end of the input (finish())
  std::uint64_t unknown_data_ids = 0;  // MTData2 packets skipped because their data id is unknown
  std::uint64_t garbage_bytes = 0;     // bytes not part of any good frame (noise, rejected frames' preambles)

  [[nodiscard]] std::uint64_t rejected() const {
    return bad_checksum + too_long + truncated_packet + bad_packet_size + truncated_frame;
  }
};

// A good frame of a message id other than MTData2 (acks, configuration replies, errors, wake-up, ...).
struct RawMessage {
  std::uint8_t mid = 0;
  std::vector<std::uint8_t> payload;
};

using StreamItem = std::variant<MtData2, RawMessage>;

class StreamParser {
 public:
  StreamParser();

  // Feeds the next bytes; appends every message completed by them to `out` (which is not cleared).
  void push(ByteSpan bytes, std::vector<StreamItem>& out);

  // End of input: whatever is left can no longer complete. Counts it, and still finds any complete frame
  // that sits behind a false preamble in it.
  void finish(std::vector<StreamItem>& out);

  [[nodiscard]] const StreamCounters& counters() const { return counters_; }

 private:
  void scan(bool at_end, std::vector<StreamItem>& out);
  void emit(const Message& m, std::vector<StreamItem>& out);

  std::vector<std::uint8_t> buf_;  // capacity fixed at construction
  std::size_t start_ = 0;          // first unconsumed byte in buf_
  StreamCounters counters_;
};

}  // namespace fieldguard::xsens
