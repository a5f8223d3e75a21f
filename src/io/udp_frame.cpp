#include "fieldguard/io/udp_frame.hpp"

#include <cstddef>
#include <optional>

namespace fieldguard::io {
namespace {

constexpr std::uint16_t kEtherTypeIpv4 = 0x0800;
constexpr std::uint16_t kEtherTypeVlan = 0x8100;     // 802.1Q customer tag
constexpr std::uint16_t kEtherTypeQinQ = 0x88A8;     // 802.1ad service tag
constexpr std::uint16_t kEtherTypeQinQOld = 0x9100;  // pre-802.1ad double tagging, still seen on switches
constexpr std::size_t kEthernetHeader = 14;
constexpr std::size_t kVlanTag = 4;
constexpr std::size_t kSllHeader = 16;
constexpr std::size_t kSllProtocol = 14;
constexpr std::size_t kSll2Header = 20;
constexpr std::size_t kSll2Protocol = 0;
constexpr std::size_t kIpv4MinHeader = 20;
constexpr std::size_t kUdpHeader = 8;
constexpr std::uint8_t kIpProtoUdp = 17;
constexpr std::uint16_t kIpMoreFragments = 0x2000;
constexpr std::uint16_t kIpFragmentOffset = 0x1FFF;

// Where the IPv4 header starts, or why there is none.
struct LinkResult {
  std::size_t ip_offset = 0;
  std::optional<FrameDrop> drop;
};

[[nodiscard]] LinkResult drop(FrameDrop d) { return LinkResult{0, d}; }

[[nodiscard]] LinkResult ethernet_ip_offset(ByteSpan frame) {
  if (frame.size() < kEthernetHeader) return drop(FrameDrop::ShortLinkHeader);
  std::size_t type_offset = 12;
  std::uint16_t type = load_be16(frame, type_offset);
  // Each tag is 4 bytes (TPID + TCI) before the next EtherType; any number may be stacked.
  while (type == kEtherTypeVlan || type == kEtherTypeQinQ || type == kEtherTypeQinQOld) {
    type_offset += kVlanTag;
    if (frame.size() < type_offset + 2) return drop(FrameDrop::ShortLinkHeader);
    type = load_be16(frame, type_offset);
  }
  if (type != kEtherTypeIpv4) return drop(FrameDrop::NotIpv4);
  return LinkResult{type_offset + 2, std::nullopt};
}

[[nodiscard]] LinkResult cooked_ip_offset(ByteSpan frame, std::size_t header, std::size_t protocol_offset) {
  if (frame.size() < header) return drop(FrameDrop::ShortLinkHeader);
  if (load_be16(frame, protocol_offset) != kEtherTypeIpv4) return drop(FrameDrop::NotIpv4);
  return LinkResult{header, std::nullopt};
}

[[nodiscard]] LinkResult raw_ip_offset(ByteSpan frame) {
  // No link header: the version nibble tells IPv4 from IPv6.
  if (frame.empty()) return drop(FrameDrop::BadIpHeader);
  const unsigned version = frame[0] >> 4U;
  if (version == 6) return drop(FrameDrop::NotIpv4);
  return LinkResult{0, std::nullopt};
}

[[nodiscard]] bool is_supported_link(int link_type) {
  return link_type == kLinkEthernet || link_type == kLinkLinuxSll || link_type == kLinkLinuxSll2 ||
         link_type == kLinkRaw;
}

[[nodiscard]] LinkResult ip_offset(int link_type, ByteSpan frame) {
  switch (link_type) {
    case kLinkEthernet: return ethernet_ip_offset(frame);
    case kLinkLinuxSll: return cooked_ip_offset(frame, kSllHeader, kSllProtocol);
    case kLinkLinuxSll2: return cooked_ip_offset(frame, kSll2Header, kSll2Protocol);
    case kLinkRaw: return raw_ip_offset(frame);
    default: return drop(FrameDrop::UnsupportedLink);
  }
}

}  // namespace

std::string_view to_string(FrameDrop d) {
  switch (d) {
    case FrameDrop::TruncatedRecord: return "truncated_record";
    case FrameDrop::UnsupportedLink: return "unsupported_link";
    case FrameDrop::ShortLinkHeader: return "short_link_header";
    case FrameDrop::NotIpv4: return "not_ipv4";
    case FrameDrop::BadIpHeader: return "bad_ip_header";
    case FrameDrop::IpFragment: return "ip_fragment";
    case FrameDrop::NotUdp: return "not_udp";
    case FrameDrop::BadUdpLength: return "bad_udp_length";
  }
  return "unknown";
}

Expected<UdpDatagram, FrameDrop> extract_udp(int link_type, ByteSpan frame, std::uint32_t original_length,
                                             Stamp host_time) {
  if (!is_supported_link(link_type)) return Unexpected{FrameDrop::UnsupportedLink};
  // A record cut by the snaplen is counted as such, whatever part of it survived.
  if (frame.size() < original_length) return Unexpected{FrameDrop::TruncatedRecord};
  const LinkResult link = ip_offset(link_type, frame);
  if (link.drop) return Unexpected{*link.drop};

  // Everything after the link header; Ethernet padding and FCS may follow the IP datagram.
  const ByteSpan ip = frame.subspan(link.ip_offset);
  if (ip.size() < kIpv4MinHeader) return Unexpected{FrameDrop::BadIpHeader};
  const unsigned version = ip[0] >> 4U;
  const std::size_t header_len = (ip[0] & 0x0FU) * 4U;
  if (version != 4 || header_len < kIpv4MinHeader || header_len > ip.size()) {
    return Unexpected{FrameDrop::BadIpHeader};
  }
  std::size_t total_len = load_be16(ip, 2);
  if (total_len < header_len) return Unexpected{FrameDrop::BadIpHeader};
  // The record is whole (checked above), so a total length past its end is the sender's error, not a
  // cut: fall back to what the record holds and let the UDP length decide (checked below).
  const bool repaired = total_len > ip.size();
  if (repaired) total_len = ip.size();

  // The protocol byte is in every fragment, so a fragmented non-UDP datagram counts as NotUdp.
  if (ip[9] != kIpProtoUdp) return Unexpected{FrameDrop::NotUdp};
  const std::uint16_t flags_offset = load_be16(ip, 6);
  if ((flags_offset & kIpMoreFragments) != 0 || (flags_offset & kIpFragmentOffset) != 0) {
    return Unexpected{FrameDrop::IpFragment};
  }

  const ByteSpan ip_payload = ip.subspan(header_len, total_len - header_len);
  if (ip_payload.size() < kUdpHeader) return Unexpected{FrameDrop::BadUdpLength};
  const std::size_t udp_len = load_be16(ip_payload, 4);
  if (udp_len < kUdpHeader || udp_len > ip_payload.size()) {
    return Unexpected{repaired ? FrameDrop::BadIpHeader : FrameDrop::BadUdpLength};
  }

  UdpDatagram d;
  d.host_time = host_time;
  d.src_ip = load_be32(ip, 12);
  d.dst_ip = load_be32(ip, 16);
  d.src_port = load_be16(ip_payload, 0);
  d.dst_port = load_be16(ip_payload, 2);
  d.payload = ip_payload.subspan(kUdpHeader, udp_len - kUdpHeader);
  d.ip_length_repaired = repaired;
  return d;
}

}  // namespace fieldguard::io
