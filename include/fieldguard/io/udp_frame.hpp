#pragma once
// Locating a UDP payload inside a captured link-layer frame (protocols.md §9.3). Pure function.

#include <cstdint>
#include <string_view>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/expected.hpp"
#include "fieldguard/core/time.hpp"

namespace fieldguard::io {

// pcap LINKTYPE_ values we read.
inline constexpr int kLinkEthernet = 1;
inline constexpr int kLinkRaw = 101;
inline constexpr int kLinkLinuxSll = 113;
inline constexpr int kLinkLinuxSll2 = 276;

struct UdpDatagram {
  Stamp host_time;           // pcap record time (replay) or kernel receive time (live)
  std::uint32_t src_ip = 0;  // host byte order
  std::uint32_t dst_ip = 0;
  std::uint16_t src_port = 0;
  std::uint16_t dst_port = 0;
  ByteSpan payload;  // points into the caller's frame buffer
  // The IP header's total length claimed more bytes than the whole, uncut record holds, and the UDP
  // length (which fits) was trusted instead. Velodyne VLP-16 firmware sends its 8308 position packets
  // so (IP total length 1234 in a 554-byte frame: the real captures in tests/data show it). Counted.
  bool ip_length_repaired = false;
};

// Why a captured frame yielded no datagram. Every one is counted by the reader.
enum class FrameDrop : std::uint8_t {
  TruncatedRecord,  // captured length < original length (snaplen cut it)
  UnsupportedLink,  // link type we do not read
  ShortLinkHeader,  // frame too short for its link header / VLAN tags
  NotIpv4,          // EtherType / protocol is not IPv4 (ARP, IPv6, ...)
  BadIpHeader,      // version != 4, IHL < 5, header longer than the frame, total length inconsistent
  IpFragment,       // MF set or fragment offset != 0: skipped, never reassembled
  NotUdp,           // IP protocol != 17
  BadUdpLength,     // UDP length field < 8 or past the IP payload
};
inline constexpr std::size_t kFrameDropCount = 8;
[[nodiscard]] std::string_view to_string(FrameDrop d);

// `frame` is one captured record of link type `link_type`; `original_length` its length on the wire.
[[nodiscard]] Expected<UdpDatagram, FrameDrop> extract_udp(int link_type, ByteSpan frame, std::uint32_t original_length,
                                                           Stamp host_time);

}  // namespace fieldguard::io
