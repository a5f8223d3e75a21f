#pragma once
// Reads classic pcap and pcapng files through libpcap and yields UDP datagrams. One consumer thread.
// A file that cannot be used at all is an error at open(); a bad record inside a usable file is a counted
// skip; a file cut short ends the stream with truncated() set.

#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "fieldguard/core/expected.hpp"
#include "fieldguard/io/udp_frame.hpp"

namespace fieldguard::io {

struct PcapStats {
  std::uint64_t records = 0;                           // records read from the file
  std::uint64_t datagrams = 0;                         // UDP datagrams handed out
  std::uint64_t ip_length_repaired = 0;                // of them, with an impossible IP total length
  std::array<std::uint64_t, kFrameDropCount> drops{};  // by FrameDrop
  bool truncated = false;                              // the file ended inside a record
  std::string read_error;                              // libpcap's message when reading stopped early
};

class PcapReader {
 public:
  // Opens a file. Errors are one line that names the file and says what is wrong
  // ("cannot open X: No such file or directory", "X is not a pcap or pcapng file (magic 0x...)", ...).
  [[nodiscard]] static Expected<PcapReader, std::string> open(const std::string& path);
  // Same, reading from an open FILE* (takes ownership); used by the fuzzer on fmemopen() memory.
  [[nodiscard]] static Expected<PcapReader, std::string> open(std::FILE* file, const std::string& name);

  PcapReader(PcapReader&&) noexcept;
  PcapReader& operator=(PcapReader&&) noexcept;
  ~PcapReader();

  // Next UDP datagram, or nullopt at the end of the file (or where reading stopped; see stats()).
  // The payload stays valid until the next call.
  [[nodiscard]] std::optional<UdpDatagram> next();

  [[nodiscard]] const PcapStats& stats() const { return stats_; }
  [[nodiscard]] int link_type() const;

 private:
  struct Impl;
  explicit PcapReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
  PcapStats stats_;
};

}  // namespace fieldguard::io
