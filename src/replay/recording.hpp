#pragma once
// A recording as `fieldguard record` writes it (the 3D LiDAR's pcap and the byte logs of the 2D LiDAR, GNSS
// and AHRS), read back as one stream in receive-time order: the order the daemon saw the data in. Replay and
// the tests that hold fused frames to the simulator's truth read recordings through it.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/core/expected.hpp"
#include "fieldguard/io/byte_log.hpp"
#include "fieldguard/io/pcap_reader.hpp"
#include "fieldguard/io/udp_frame.hpp"

namespace fieldguard::app {

enum class LogKind : std::uint8_t { Scan2d = 0, Gnss = 1, Ahrs = 2 };

struct LogFile {
  std::string path;
  LogKind kind;
};

struct RecordingEvent {
  Stamp time;                                 // receive time
  const io::UdpDatagram* datagram = nullptr;  // from the capture, or
  const io::ByteLogRecord* record = nullptr;  // from the log of `kind`
  LogKind kind = LogKind::Scan2d;
};

class RecordingReader {
 public:
  // "cannot open ...": the capture or a log cannot be opened or is not of its format.
  [[nodiscard]] static Expected<RecordingReader, std::string> open(const std::string& pcap, std::vector<LogFile> logs);

  // The next datagram or record, the earliest first (on a tie the capture's first); nullopt at the end. The
  // pointers stay valid until the next call.
  [[nodiscard]] std::optional<RecordingEvent> next();

  struct LogStatus {
    LogFile file;
    std::uint64_t records = 0;
    std::string source;
    bool truncated = false;
    std::string error;
  };
  [[nodiscard]] std::vector<LogStatus> logs() const;
  [[nodiscard]] const io::PcapReader& capture() const { return pcap_; }
  [[nodiscard]] bool has(LogKind k) const;

 private:
  struct Cursor {
    LogFile file;
    io::ByteLogReader reader;
    std::optional<io::ByteLogRecord> next;
    std::uint64_t records = 0;
  };
  explicit RecordingReader(io::PcapReader pcap) : pcap_(std::move(pcap)) {}

  io::PcapReader pcap_;
  std::vector<Cursor> cursors_;
  std::optional<io::UdpDatagram> datagram_;
  bool started_ = false;
  int taken_ = -2;  // what the last next() returned: -1 the datagram, >= 0 that cursor's record
  io::ByteLogRecord current_;
};

}  // namespace fieldguard::app
