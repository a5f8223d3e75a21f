#pragma once
// Writes received UDP datagrams as a nanosecond pcap (Ethernet/IPv4/UDP frames around each payload) through
// libpcap, so `record`'s LiDAR capture opens in Wireshark, PCL, VeloView and our own replay. One writer thread.

#include <cstdint>
#include <memory>
#include <string>

#include "fieldguard/core/expected.hpp"
#include "fieldguard/io/udp_frame.hpp"

namespace fieldguard::io {

class PcapWriter {
 public:
  [[nodiscard]] static Expected<PcapWriter, std::string> create(const std::string& path);
  PcapWriter(PcapWriter&&) noexcept;
  PcapWriter& operator=(PcapWriter&&) noexcept;
  ~PcapWriter();

  // The datagram's host_time becomes the record time; addresses and ports are kept. False when it is too
  // large for one unfragmented IPv4 datagram.
  bool write(const UdpDatagram& d);
  bool flush();

 private:
  struct Impl;
  explicit PcapWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldguard::io
