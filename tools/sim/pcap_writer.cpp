#include "sim/pcap_writer.hpp"

#include <array>
#include <cerrno>
#include <cstring>

namespace fieldguard::sim {

namespace {

constexpr std::size_t kHeaderBytes = 42;

void le32(std::uint8_t* p, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8U * i));
}
void le16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v & 0xFFU);
  p[1] = static_cast<std::uint8_t>(v >> 8U);
}
void be16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 8U);
  p[1] = static_cast<std::uint8_t>(v & 0xFFU);
}

}  // namespace

void build_udp_headers(std::uint8_t* h, std::size_t payload_size, std::uint16_t ip_id, std::uint16_t src_port,
                       std::uint16_t dst_port) {
  // Ethernet II: broadcast destination, a Velodyne OUI (60:76:88) source, EtherType IPv4.
  constexpr std::array<std::uint8_t, 14> eth{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x60,
                                             0x76, 0x88, 0x00, 0x00, 0x01, 0x08, 0x00};
  std::memcpy(h, eth.data(), eth.size());
  std::uint8_t* ip = h + 14;
  const auto udp_len = static_cast<std::uint16_t>(8 + payload_size);
  const auto ip_len = static_cast<std::uint16_t>(20 + udp_len);
  ip[0] = 0x45;  // IPv4, 5 words
  ip[1] = 0x00;
  be16(ip + 2, ip_len);
  be16(ip + 4, ip_id);
  be16(ip + 6, 0x4000);  // don't fragment
  ip[8] = 64;            // TTL
  ip[9] = 17;            // UDP
  be16(ip + 10, 0);
  constexpr std::array<std::uint8_t, 8> addrs{192, 168, 1, 201, 255, 255, 255, 255};
  std::memcpy(ip + 12, addrs.data(), addrs.size());
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i < 20; i += 2) sum += static_cast<std::uint32_t>(ip[i] << 8U) | ip[i + 1];
  while (sum > 0xFFFFU) sum = (sum & 0xFFFFU) + (sum >> 16U);
  be16(ip + 10, static_cast<std::uint16_t>(~sum & 0xFFFFU));
  std::uint8_t* udp = ip + 20;
  be16(udp, src_port);
  be16(udp + 2, dst_port);
  be16(udp + 4, udp_len);
  be16(udp + 6, 0);  // no checksum (allowed in IPv4)
}

PcapWriter::~PcapWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

bool PcapWriter::fail(const std::string& what) {
  error_ = what + " " + path_ + ": " + std::strerror(errno);
  return false;
}

bool PcapWriter::open(const std::string& path) {
  path_ = path;
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) return fail("cannot create");
  std::array<std::uint8_t, 24> g{};
  le32(g.data(), 0xA1B2C3D4U);  // microsecond timestamps
  le16(g.data() + 4, 2);
  le16(g.data() + 6, 4);
  le32(g.data() + 16, 65535);  // snaplen
  le32(g.data() + 20, 1);      // LINKTYPE_ETHERNET
  if (std::fwrite(g.data(), 1, g.size(), file_) != g.size()) return fail("cannot write");
  return true;
}

bool PcapWriter::write_udp(std::span<const std::uint8_t> payload, std::int64_t time_ns, std::uint16_t src_port,
                           std::uint16_t dst_port) {
  std::array<std::uint8_t, 16 + kHeaderBytes> head{};
  const auto frame_len = static_cast<std::uint32_t>(kHeaderBytes + payload.size());
  const std::int64_t us = time_ns / 1000;
  le32(head.data(), static_cast<std::uint32_t>(us / 1000000));
  le32(head.data() + 4, static_cast<std::uint32_t>(us % 1000000));
  le32(head.data() + 8, frame_len);
  le32(head.data() + 12, frame_len);
  build_udp_headers(head.data() + 16, payload.size(), ip_id_++, src_port, dst_port);
  if (std::fwrite(head.data(), 1, head.size(), file_) != head.size() ||
      std::fwrite(payload.data(), 1, payload.size(), file_) != payload.size()) {
    return fail("cannot write");
  }
  return true;
}

bool PcapWriter::close() {
  if (file_ == nullptr) return true;
  const bool ok = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok) return fail("cannot close");
  return true;
}

}  // namespace fieldguard::sim
