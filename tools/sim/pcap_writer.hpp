#pragma once
// Writes a classic pcap (protocols.md §9.1): microsecond timestamps, LINKTYPE_ETHERNET, each UDP payload
// wrapped in Ethernet II + IPv4 (no options, DF, header checksum) + UDP (checksum 0) = 42 header bytes,
// as the sensor broadcasts it: 192.168.1.201:2368 -> 255.255.255.255:2368.

#include <cstdint>
#include <cstdio>
#include <span>
#include <string>

namespace fieldguard::sim {

class PcapWriter {
 public:
  PcapWriter() = default;
  PcapWriter(const PcapWriter&) = delete;
  PcapWriter& operator=(const PcapWriter&) = delete;
  ~PcapWriter();

  // Creates the file and writes the global header. False (with error()) if it cannot.
  [[nodiscard]] bool open(const std::string& path);
  // One record, time in ns since the Unix epoch (written truncated to microseconds).
  [[nodiscard]] bool write_udp(std::span<const std::uint8_t> payload, std::int64_t time_ns, std::uint16_t src_port,
                               std::uint16_t dst_port);
  // Flushes and closes; false if a write failed.
  [[nodiscard]] bool close();
  [[nodiscard]] const std::string& error() const { return error_; }

 private:
  bool fail(const std::string& what);
  std::FILE* file_ = nullptr;
  std::string path_;
  std::string error_;
  std::uint16_t ip_id_ = 0;
};

// The 42-byte Ethernet/IPv4/UDP header for a payload of `payload_size` bytes.
void build_udp_headers(std::uint8_t* out42, std::size_t payload_size, std::uint16_t ip_id, std::uint16_t src_port,
                       std::uint16_t dst_port);

}  // namespace fieldguard::sim
