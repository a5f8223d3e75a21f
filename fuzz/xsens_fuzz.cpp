// libFuzzer target for the Xsens decoders: decode_frame() and decode_mtdata2() on the raw input, the input as an
// MTData2 payload inside a valid frame, and xsens::StreamParser fed whole and in chunks whose sizes come from the
// input. Invariants (a violation traps): the chunking changes nothing (same messages, same counters); decoded
// frames lie inside the input; the stream parser's buffer stays bounded.
// Run: fuzz_xsens -max_total_time=60 CORPUS_DIR fuzz/corpus/xsens

#include <cstddef>
#include <cstdint>
#include <variant>
#include <vector>

#include "fieldguard/drivers/xsens.hpp"
#include "fieldguard/drivers/xsens_mtdata2.hpp"
#include "fieldguard/drivers/xsens_stream.hpp"

namespace {

namespace xs = fieldguard::xsens;
using fieldguard::ByteSpan;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

bool same(const xs::StreamCounters& a, const xs::StreamCounters& b) {
  return a.messages == b.messages && a.mtdata2 == b.mtdata2 && a.other_messages == b.other_messages &&
         a.bad_checksum == b.bad_checksum && a.too_long == b.too_long && a.truncated_packet == b.truncated_packet &&
         a.bad_packet_size == b.bad_packet_size && a.truncated_frame == b.truncated_frame &&
         a.unknown_data_ids == b.unknown_data_ids && a.garbage_bytes == b.garbage_bytes;
}

// A summary of a stream item that chunking must not change.
std::uint64_t digest(const xs::StreamItem& item) {
  if (const auto* d = std::get_if<xs::MtData2>(&item)) {
    return (1ULL << 40) | (static_cast<std::uint64_t>(d->packet_counter.value_or(0)) << 8) | d->unknown_ids.size();
  }
  const auto& m = std::get<xs::RawMessage>(item);
  return (static_cast<std::uint64_t>(m.mid) << 32) | m.payload.size();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const ByteSpan bytes(data, size);

  if (const auto m = xs::decode_frame(bytes)) {
    check(m->frame_size <= size && m->payload.size() + 5 <= m->frame_size);
    check(m->payload.data() >= data && m->payload.data() + m->payload.size() <= data + size);
    if (m->mid == xs::mid::kMtData2) (void)xs::decode_mtdata2(m->payload);
  }
  if (const auto d = xs::decode_mtdata2(bytes)) {
    check(d->unknown_ids.size() <= size / 3);
  }
  // The input as a payload, framed: the frame must decode and give the payload back.
  if (size <= xs::kMaxPayload) {
    const auto framed = xs::encode_frame(xs::mid::kMtData2, bytes);
    const auto m = xs::decode_frame(framed);
    check(m.has_value() && m->payload.size() == size && m->frame_size == framed.size());
  }

  xs::StreamParser whole;
  std::vector<xs::StreamItem> a;
  whole.push(bytes, a);
  whole.finish(a);
  const auto& c = whole.counters();
  check(c.messages == c.mtdata2 + c.other_messages + c.truncated_packet + c.bad_packet_size);
  check(a.size() == c.mtdata2 + c.other_messages);
  check(c.garbage_bytes <= size);

  xs::StreamParser pieces;
  std::vector<xs::StreamItem> b;
  std::size_t k = 0;
  for (std::size_t off = 0; off < size;) {
    const std::size_t n = std::min<std::size_t>(size - off, 1U + data[k++ % size]);
    pieces.push(bytes.subspan(off, n), b);
    off += n;
  }
  pieces.finish(b);
  check(same(c, pieces.counters()));
  check(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) check(digest(a[i]) == digest(b[i]));
  return 0;
}
