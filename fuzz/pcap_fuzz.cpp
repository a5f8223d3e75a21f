// libFuzzer target for the pcap/pcapng reader (through libpcap, on fmemopen() memory) and for
// extract_udp() on the raw input under every link type we read.
// Run: fuzz_pcap -max_total_time=60 CORPUS_DIR   (seed with a few small pcap and pcapng files)

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <numeric>
#include <vector>

#include "fieldguard/io/pcap_reader.hpp"
#include "fieldguard/io/udp_frame.hpp"

namespace {

using fieldguard::ByteSpan;
using fieldguard::Stamp;
namespace io = fieldguard::io;

// A payload must lie inside the bytes it was found in.
void check_inside(const io::UdpDatagram& d, const std::uint8_t* begin, std::size_t size) {
  const std::uint8_t* p = d.payload.data();
  if (p < begin || p + d.payload.size() > begin + size) __builtin_trap();
  volatile std::uint8_t sink = 0;
  for (const std::uint8_t b : d.payload) sink = static_cast<std::uint8_t>(sink ^ b);
}

void fuzz_frame(const std::uint8_t* data, std::size_t size) {
  const ByteSpan frame(data, size);
  const auto wire = static_cast<std::uint32_t>(size);
  constexpr std::array<int, 5> kLinks{io::kLinkEthernet, io::kLinkRaw, io::kLinkLinuxSll, io::kLinkLinuxSll2, 227};
  for (const int link : kLinks) {
    const auto r = io::extract_udp(link, frame, wire, Stamp{1});
    if (r) check_inside(*r, data, size);
    const auto cut = io::extract_udp(link, frame, wire + 1, Stamp{1});
    if (cut || cut.error() != (link == 227 ? io::FrameDrop::UnsupportedLink : io::FrameDrop::TruncatedRecord)) {
      __builtin_trap();
    }
  }
}

void fuzz_reader(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> copy(data, data + size);  // fmemopen() takes a writable buffer
  std::FILE* file = ::fmemopen(copy.empty() ? nullptr : copy.data(), copy.size(), "rb");
  if (file == nullptr) return;
  auto reader = io::PcapReader::open(file, "fuzz-input");
  if (!reader) return;
  while (auto d = reader->next()) {
    volatile std::uint8_t sink = 0;
    for (const std::uint8_t b : d->payload) sink = static_cast<std::uint8_t>(sink ^ b);
  }
  // Every record read is either handed out or counted as one drop.
  const io::PcapStats& s = reader->stats();
  const std::uint64_t dropped = std::accumulate(s.drops.begin(), s.drops.end(), std::uint64_t{0});
  if (s.datagrams + dropped != s.records) __builtin_trap();
  if (reader->next()) __builtin_trap();  // the end stays the end
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz_frame(data, size);
  fuzz_reader(data, size);
  return 0;
}
