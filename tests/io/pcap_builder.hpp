#pragma once
// Test support: builds IPv4/UDP datagrams, link-layer frames around them (Ethernet with VLAN tags, Linux
// SLL and SLL2, raw IP) and classic pcap / pcapng files (protocols.md §9), in memory and on disk in a
// temporary directory, so reader tests go through libpcap on real files. Header-only, tests only.

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace fieldguard::testing {

using Bytes = std::vector<std::uint8_t>;

inline void put_u16(Bytes& b, std::uint16_t v, bool big_endian = true) {
  if (big_endian) {
    b.push_back(static_cast<std::uint8_t>(v >> 8));
    b.push_back(static_cast<std::uint8_t>(v));
  } else {
    b.push_back(static_cast<std::uint8_t>(v));
    b.push_back(static_cast<std::uint8_t>(v >> 8));
  }
}
inline void put_u32(Bytes& b, std::uint32_t v, bool big_endian = true) {
  if (big_endian) {
    put_u16(b, static_cast<std::uint16_t>(v >> 16), true);
    put_u16(b, static_cast<std::uint16_t>(v), true);
  } else {
    put_u16(b, static_cast<std::uint16_t>(v), false);
    put_u16(b, static_cast<std::uint16_t>(v >> 16), false);
  }
}
inline void append(Bytes& b, const Bytes& more) { b.insert(b.end(), more.begin(), more.end()); }

// n bytes of a recognisable pattern.
inline Bytes pattern(std::size_t n, std::uint8_t seed = 0) {
  Bytes b(n);
  for (std::size_t i = 0; i < n; ++i) b[i] = static_cast<std::uint8_t>(seed + i * 7U);
  return b;
}

inline constexpr std::uint32_t ipv4(std::uint8_t a, std::uint8_t b, std::uint8_t c, std::uint8_t d) {
  return (std::uint32_t{a} << 24) | (std::uint32_t{b} << 16) | (std::uint32_t{c} << 8) | d;
}

// An IPv4 datagram carrying UDP. The overrides let tests write malformed headers.
struct Ipv4Udp {
  std::uint32_t src_ip = ipv4(192, 168, 1, 201);
  std::uint32_t dst_ip = ipv4(255, 255, 255, 255);
  std::uint16_t src_port = 2368;
  std::uint16_t dst_port = 2368;
  Bytes payload;
  Bytes ip_options;  // a multiple of 4 bytes, up to 40
  std::uint8_t version = 4;
  std::uint8_t protocol = 17;
  std::uint16_t flags_fragment = 0x4000;  // DF, offset 0
  std::optional<std::uint8_t> ihl;        // header length in 32-bit words; default from the options
  std::optional<std::uint16_t> total_length;
  std::optional<std::uint16_t> udp_length;
};

inline Bytes build(const Ipv4Udp& d) {
  const auto header_len = static_cast<std::uint16_t>(20 + d.ip_options.size());
  const auto udp_len = static_cast<std::uint16_t>(8 + d.payload.size());
  Bytes b;
  b.push_back(static_cast<std::uint8_t>((d.version << 4) | d.ihl.value_or(static_cast<std::uint8_t>(header_len / 4))));
  b.push_back(0);  // DSCP/ECN
  put_u16(b, d.total_length.value_or(static_cast<std::uint16_t>(header_len + udp_len)));
  put_u16(b, 0x1234);  // identification
  put_u16(b, d.flags_fragment);
  b.push_back(64);  // TTL
  b.push_back(d.protocol);
  put_u16(b, 0);  // checksum, filled in below
  put_u32(b, d.src_ip);
  put_u32(b, d.dst_ip);
  append(b, d.ip_options);
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i + 1 < b.size(); i += 2) sum += static_cast<std::uint32_t>((b[i] << 8) | b[i + 1]);
  while (sum > 0xFFFF) sum = (sum & 0xFFFF) + (sum >> 16);
  const auto checksum = static_cast<std::uint16_t>(~sum);
  b[10] = static_cast<std::uint8_t>(checksum >> 8);
  b[11] = static_cast<std::uint8_t>(checksum);
  put_u16(b, d.src_port);
  put_u16(b, d.dst_port);
  put_u16(b, d.udp_length.value_or(udp_len));
  put_u16(b, 0);  // no UDP checksum
  append(b, d.payload);
  return b;
}

// Ethernet II; each TPID in `tags` adds a 4-byte tag (outermost first) before `ethertype`.
inline Bytes ethernet(const Bytes& l3, std::uint16_t ethertype = 0x0800,
                      std::initializer_list<std::uint16_t> tags = {}) {
  Bytes b{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x60, 0x76, 0x88, 0x20, 0x12, 0x6E};
  std::uint16_t vid = 100;
  for (const std::uint16_t tpid : tags) {
    put_u16(b, tpid);
    put_u16(b, vid++);  // PCP 0, DEI 0, VLAN id
  }
  put_u16(b, ethertype);
  append(b, l3);
  return b;
}

// Linux cooked capture v1 (LINKTYPE_LINUX_SLL, 16 bytes): protocol at 14.
inline Bytes linux_sll(const Bytes& l3, std::uint16_t protocol = 0x0800) {
  Bytes b;
  put_u16(b, 0);  // packet type: to us
  put_u16(b, 1);  // ARPHRD_ETHER
  put_u16(b, 6);  // address length
  append(b, Bytes{0x60, 0x76, 0x88, 0x20, 0x12, 0x6E, 0, 0});
  put_u16(b, protocol);
  append(b, l3);
  return b;
}

// Linux cooked capture v2 (LINKTYPE_LINUX_SLL2, 20 bytes): protocol at 0.
inline Bytes linux_sll2(const Bytes& l3, std::uint16_t protocol = 0x0800) {
  Bytes b;
  put_u16(b, protocol);
  put_u16(b, 0);   // reserved
  put_u32(b, 2);   // interface index
  put_u16(b, 1);   // ARPHRD_ETHER
  b.push_back(0);  // packet type
  b.push_back(6);  // address length
  append(b, Bytes{0x60, 0x76, 0x88, 0x20, 0x12, 0x6E, 0, 0});
  append(b, l3);
  return b;
}

// Classic pcap (pcap-savefile(5)) in either byte order and time resolution.
class ClassicPcap {
 public:
  explicit ClassicPcap(std::uint32_t link_type = 1, bool big_endian = false, bool nanosecond = false,
                       std::uint32_t snaplen = 65535)
      : big_endian_(big_endian), nanosecond_(nanosecond) {
    put_u32(bytes_, nanosecond ? 0xA1B23C4D : 0xA1B2C3D4, big_endian);
    put_u16(bytes_, 2, big_endian);
    put_u16(bytes_, 4, big_endian);
    put_u32(bytes_, 0, big_endian);
    put_u32(bytes_, 0, big_endian);
    put_u32(bytes_, snaplen, big_endian);
    put_u32(bytes_, link_type, big_endian);
  }

  // One record; `original_length` defaults to the captured size.
  ClassicPcap& add(const Bytes& captured, std::int64_t time_ns, std::optional<std::uint32_t> original_length = {}) {
    const auto sec = static_cast<std::uint32_t>(time_ns / 1'000'000'000);
    const auto sub_ns = static_cast<std::uint32_t>(time_ns % 1'000'000'000);
    put_u32(bytes_, sec, big_endian_);
    put_u32(bytes_, nanosecond_ ? sub_ns : sub_ns / 1000, big_endian_);
    put_u32(bytes_, static_cast<std::uint32_t>(captured.size()), big_endian_);
    put_u32(bytes_, original_length.value_or(static_cast<std::uint32_t>(captured.size())), big_endian_);
    append(bytes_, captured);
    return *this;
  }

  [[nodiscard]] const Bytes& bytes() const { return bytes_; }

 private:
  bool big_endian_;
  bool nanosecond_;
  Bytes bytes_;
};

// pcapng: blocks appended in the order the test calls them, starting with a Section Header Block.
class Pcapng {
 public:
  explicit Pcapng(bool big_endian = false) : big_endian_(big_endian) { section(); }

  // Section Header Block, version 1.0, section length unknown.
  Pcapng& section() {
    Bytes body;
    put_u32(body, 0x1A2B3C4D, big_endian_);
    put_u16(body, 1, big_endian_);
    put_u16(body, 0, big_endian_);
    put_u32(body, 0xFFFFFFFF, big_endian_);
    put_u32(body, 0xFFFFFFFF, big_endian_);
    return block(0x0A0D0D0A, body);
  }

  // Interface Description Block; `tsresol` is the raw if_tsresol byte (absent = microseconds).
  Pcapng& interface(std::uint16_t link_type, std::optional<std::uint8_t> tsresol = {}, std::uint32_t snaplen = 0) {
    Bytes body;
    put_u16(body, link_type, big_endian_);
    put_u16(body, 0, big_endian_);
    put_u32(body, snaplen, big_endian_);
    if (tsresol) {
      put_u16(body, 9, big_endian_);  // if_tsresol
      put_u16(body, 1, big_endian_);
      body.push_back(*tsresol);
      body.resize(body.size() + 3, 0);
      put_u32(body, 0, big_endian_);  // opt_endofopt
    }
    return block(1, body);
  }

  // Enhanced Packet Block; `timestamp` in units of the interface's resolution.
  Pcapng& enhanced(std::uint32_t interface_id, std::uint64_t timestamp, const Bytes& captured,
                   std::optional<std::uint32_t> original_length = {}) {
    Bytes body;
    put_u32(body, interface_id, big_endian_);
    put_u32(body, static_cast<std::uint32_t>(timestamp >> 32), big_endian_);
    put_u32(body, static_cast<std::uint32_t>(timestamp), big_endian_);
    put_u32(body, static_cast<std::uint32_t>(captured.size()), big_endian_);
    put_u32(body, original_length.value_or(static_cast<std::uint32_t>(captured.size())), big_endian_);
    append(body, captured);
    return block(6, body);
  }

  // Simple Packet Block: original length only, no timestamp, interface 0.
  Pcapng& simple(const Bytes& packet) {
    Bytes body;
    put_u32(body, static_cast<std::uint32_t>(packet.size()), big_endian_);
    append(body, packet);
    return block(3, body);
  }

  [[nodiscard]] const Bytes& bytes() const { return bytes_; }

 private:
  Pcapng& block(std::uint32_t type, Bytes body) {
    body.resize((body.size() + 3) / 4 * 4, 0);
    const auto total = static_cast<std::uint32_t>(body.size() + 12);
    put_u32(bytes_, type, big_endian_);
    put_u32(bytes_, total, big_endian_);
    append(bytes_, body);
    put_u32(bytes_, total, big_endian_);
    return *this;
  }

  bool big_endian_;
  Bytes bytes_;
};

// A fresh directory under the system temp dir, removed with everything in it at destruction.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "fieldguard-pcap-XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("mkdtemp failed for " + tmpl);
    path_ = tmpl;
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  // Writes `bytes` to a file of this name in the directory and returns its path.
  [[nodiscard]] std::string write(const std::string& name, const Bytes& bytes) const {
    const auto p = path_ / name;
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw std::runtime_error("cannot write " + p.string());
    return p.string();
  }

 private:
  std::filesystem::path path_;
};

}  // namespace fieldguard::testing
