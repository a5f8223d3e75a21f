#include "fieldguard/drivers/xsens_stream.hpp"

#include <algorithm>

namespace fieldguard::xsens {
namespace {

// Twice the largest frame: after a scan less than one frame is left, so a push always has room for more.
constexpr std::size_t kCapacity = 2 * kMaxFrameSize;

}  // namespace

StreamParser::StreamParser() { buf_.reserve(kCapacity); }

void StreamParser::push(ByteSpan bytes, std::vector<StreamItem>& out) {
  while (!bytes.empty()) {
    if (start_ > 0) {
      buf_.erase(buf_.begin(), buf_.begin() + static_cast<std::ptrdiff_t>(start_));
      start_ = 0;
    }
    const std::size_t n = std::min(kCapacity - buf_.size(), bytes.size());
    buf_.insert(buf_.end(), bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
    bytes = bytes.subspan(n);
    scan(false, out);
  }
}

void StreamParser::finish(std::vector<StreamItem>& out) {
  scan(true, out);
  buf_.clear();
  start_ = 0;
}

void StreamParser::scan(bool at_end, std::vector<StreamItem>& out) {
  const ByteSpan b(buf_);
  std::size_t pos = start_;
  while (pos < b.size()) {
    const auto preamble = std::find(b.begin() + static_cast<std::ptrdiff_t>(pos), b.end(), kPreamble);
    const auto skipped = static_cast<std::size_t>(preamble - (b.begin() + static_cast<std::ptrdiff_t>(pos)));
    counters_.garbage_bytes += skipped;
    pos += skipped;
    if (pos == b.size()) break;
    const auto frame = decode_frame(b.subspan(pos));
    if (frame) {
      emit(*frame, out);
      pos += frame->frame_size;
      continue;
    }
    switch (frame.error()) {
      case Error::TooShort:
        if (!at_end) {
          start_ = pos;
          return;  // wait for the rest
        }
        if (b.size() - pos >= 2) ++counters_.truncated_frame;  // 0xFA 0xFF and not enough after it
        break;
      case Error::TooLong: ++counters_.too_long; break;
      case Error::BadChecksum: ++counters_.bad_checksum; break;
      default: break;  // BadPreamble: 0xFA without 0xFF
    }
    // Resynchronise from the byte after this preamble.
    ++counters_.garbage_bytes;
    ++pos;
  }
  start_ = pos;
}

void StreamParser::emit(const Message& m, std::vector<StreamItem>& out) {
  ++counters_.messages;
  if (m.mid != mid::kMtData2) {
    ++counters_.other_messages;
    out.emplace_back(RawMessage{m.mid, std::vector<std::uint8_t>(m.payload.begin(), m.payload.end())});
    return;
  }
  auto data = decode_mtdata2(m.payload);
  if (!data) {
    if (data.error() == Error::TruncatedPacket) {
      ++counters_.truncated_packet;
    } else {
      ++counters_.bad_packet_size;
    }
    return;
  }
  ++counters_.mtdata2;
  counters_.unknown_data_ids += data->unknown_ids.size();
  out.emplace_back(std::move(data).value());
}

}  // namespace fieldguard::xsens
