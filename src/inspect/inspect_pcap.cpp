// `fieldguard inspect`: what the pcap formats (velodyne, robosense) share: recognising a pcap, peeking at its
// first datagrams to tell the LiDARs apart, opening it through io::PcapReader, and its counts for the summary.

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "fieldguard/drivers/robosense.hpp"
#include "fieldguard/drivers/velodyne_types.hpp"
#include "fieldguard/io/udp_frame.hpp"
#include "inspect/inspect_format.hpp"

namespace fieldguard::app::inspect {
namespace {

constexpr std::uint32_t kPcapngBlockSection = 0x0A0D0D0AU;
constexpr std::uint32_t kPcapngBlockInterface = 1;
constexpr std::uint32_t kPcapngBlockSimplePacket = 3;
constexpr std::uint32_t kPcapngBlockEnhancedPacket = 6;
constexpr std::uint32_t kPcapngByteOrderMagic = 0x1A2B3C4DU;
constexpr std::size_t kPeekDatagrams = 16;

std::uint32_t load32(ByteSpan b, std::size_t off, bool big_endian) {
  return big_endian ? load_be32(b, off) : load_le32(b, off);
}
std::uint16_t load16(ByteSpan b, std::size_t off, bool big_endian) {
  return big_endian ? load_be16(b, off) : load_le16(b, off);
}

void vote(PcapPeek& peek, int link_type, ByteSpan frame, std::uint32_t original_length) {
  const auto d = io::extract_udp(link_type, frame, original_length, Stamp{});
  if (!d) return;
  ++peek.datagrams;
  const auto is_port = [&](std::uint16_t a, std::uint16_t b) {
    return d->dst_port == a || d->dst_port == b || d->src_port == a || d->src_port == b;
  };
  const std::size_t n = d->payload.size();
  if (is_port(velodyne::kDefaultDataPort, velodyne::kDefaultPositionPort) || n == velodyne::kDataPacketSize ||
      n == velodyne::kPositionPacketSize) {
    ++peek.velodyne;
  }
  if (is_port(robosense::kDefaultMsopPort, robosense::kDefaultDifopPort) || n == robosense::kPacketSize) {
    ++peek.robosense;
  }
}

void peek_classic(ByteSpan head, bool big_endian, PcapPeek& peek) {
  if (head.size() < 24) return;
  const auto link_type = static_cast<int>(load32(head, 20, big_endian) & 0xFFFFU);
  std::size_t off = 24;
  while (off + 16 <= head.size() && peek.datagrams < kPeekDatagrams) {
    const std::uint32_t captured = load32(head, off + 8, big_endian);
    const std::uint32_t original = load32(head, off + 12, big_endian);
    if (captured > head.size() - off - 16) return;  // cut by the end of the head (or damaged)
    vote(peek, link_type, head.subspan(off + 16, captured), original);
    off += 16 + captured;
  }
}

void peek_pcapng(ByteSpan head, PcapPeek& peek) {
  if (head.size() < 12) return;
  bool big_endian = load_be32(head, 8) == kPcapngByteOrderMagic;
  std::vector<int> link_types;
  std::size_t off = 0;
  while (off + 12 <= head.size() && peek.datagrams < kPeekDatagrams) {
    const std::uint32_t type = load32(head, off, big_endian);
    if (type == kPcapngBlockSection) {
      big_endian = load_be32(head, off + 8) == kPcapngByteOrderMagic;
      link_types.clear();
    }
    const std::uint32_t length = load32(head, off + 4, big_endian);
    if (length < 12 || length % 4 != 0 || length > head.size() - off) return;
    const ByteSpan block = head.subspan(off, length);
    if (type == kPcapngBlockInterface && length >= 20) {
      link_types.push_back(load16(block, 8, big_endian));
    } else if (type == kPcapngBlockEnhancedPacket && length >= 32) {
      const std::uint32_t iface = load32(block, 8, big_endian);
      const std::uint32_t captured = load32(block, 20, big_endian);
      const std::uint32_t original = load32(block, 24, big_endian);
      if (iface < link_types.size() && captured <= length - 32) {
        vote(peek, link_types[iface], block.subspan(28, captured), original);
      }
    } else if (type == kPcapngBlockSimplePacket && length >= 16 && !link_types.empty()) {
      const std::uint32_t original = load32(block, 8, big_endian);
      const std::uint32_t captured = std::min<std::uint32_t>(original, length - 16);
      vote(peek, link_types.front(), block.subspan(12, captured), original);
    }
    off += length;
  }
}

}  // namespace

bool looks_like_pcap(ByteSpan head) {
  if (head.size() < 4) return false;
  const std::uint32_t le = load_le32(head, 0);
  return le == 0xA1B2C3D4U || le == 0xD4C3B2A1U || le == 0xA1B23C4DU || le == 0x4D3CB2A1U ||
         le == kPcapngBlockSection;  // classic pcap (either byte order, us or ns) or pcapng
}

PcapPeek peek_pcap(ByteSpan head) {
  PcapPeek peek;
  if (!looks_like_pcap(head)) return peek;
  const std::uint32_t le = load_le32(head, 0);
  if (le == kPcapngBlockSection) {
    peek_pcapng(head, peek);
  } else {
    peek_classic(head, le == 0xD4C3B2A1U || le == 0x4D3CB2A1U, peek);
  }
  return peek;
}

bool looks_like_robosense(ByteSpan head) {
  const PcapPeek peek = peek_pcap(head);
  return peek.robosense > peek.velodyne;
}

std::optional<io::PcapReader> open_pcap(Capture& in, Summary& summary) {
  if (!looks_like_pcap(in.head())) {
    const ByteSpan head = in.head();
    std::array<char, 96> why{};
    if (head.size() < 4) {
      std::snprintf(why.data(), why.size(), "not a pcap or pcapng file (%zu bytes)", head.size());
    } else {
      std::snprintf(why.data(), why.size(), "not a pcap or pcapng file (it starts with 0x%08X)",
                    unsigned{load_be32(head, 0)});
    }
    summary.unusable = why.data();
    return std::nullopt;
  }
  std::FILE* stream = in.open_stream();
  if (stream == nullptr) {
    summary.unusable = "cannot read the capture as a stream";
    return std::nullopt;
  }
  auto reader = io::PcapReader::open(stream, "the capture");  // takes the stream, also on failure
  if (!reader) {
    summary.unusable = reader.error();
    return std::nullopt;
  }
  return std::move(reader).value();
}

std::vector<std::pair<std::string, std::uint64_t>> pcap_drops(const io::PcapStats& stats) {
  std::vector<std::pair<std::string, std::uint64_t>> v;
  for (std::size_t i = 0; i < io::kFrameDropCount; ++i) {
    v.emplace_back(std::string(io::to_string(static_cast<io::FrameDrop>(i))), stats.drops[i]);
  }
  return v;
}

void add_pcap_stats(const io::PcapStats& stats, Summary& summary) {
  summary.extra.emplace_back("pcap_records", stats.records);
  summary.extra.emplace_back("datagrams", stats.datagrams);
  summary.extra.emplace_back("ip_length_repaired", stats.ip_length_repaired);
  if (stats.truncated) summary.notes.emplace_back("truncated", "the file ends inside a record (a capture cut short)");
  if (!stats.read_error.empty()) {
    summary.notes.emplace_back("stopped", "reading stopped at a damaged record: " + stats.read_error);
  }
}

}  // namespace fieldguard::app::inspect
