#pragma once
// Where encoded frames go: a candump log file (replay, tests, the field engineer) or a SocketCAN CAN_RAW
// socket (the tractor). Neither blocks the caller: the socket is non-blocking and a full queue is a counted
// drop; the log is buffered and flushed once per write() batch (one pipeline frame), so a crash loses at
// most that batch. Both are thread-compatible: one sending thread.

#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/core/expected.hpp"
#include "fieldguard/core/time.hpp"
#include "fieldguard/output/can_frame.hpp"

namespace fieldguard::output {

// One line of `candump -L` / `candump -l` (protocols.md §7.2, can-utils candump.c):
// "(0000001700.123456) can0 18FF1080#010000000000053E\n" (seconds zero-padded to 10 digits, microseconds,
// the 29-bit id as 8 uppercase hex digits, the data as uppercase hex pairs). Negative stamps print as 0.
[[nodiscard]] std::string candump_line(const CanFrame& f, Stamp t, std::string_view iface);

// Empty when `iface` can name a Linux network interface (1..15 characters, no '/', ':' or whitespace);
// otherwise what is wrong with it.
[[nodiscard]] std::string check_interface_name(std::string_view iface);

struct CanSinkStats {
  std::uint64_t sent = 0;
  std::uint64_t dropped = 0;       // queue full (EAGAIN / ENOBUFS): the frame is lost, the pipeline goes on
  std::uint64_t write_errors = 0;  // anything else (interface down, short write, disk full)
  int last_errno = 0;
  std::uint64_t error_frames = 0;  // CAN_ERR_FLAG frames read back from the socket
  std::uint64_t bus_off_events = 0;
  std::uint64_t restarts = 0;
  std::uint64_t unexpected_reads = 0;  // 11-bit or remote frames, odd sizes: what the filters should have kept away
  std::uint64_t received = 0;          // extended data frames read for the J1939 node (SocketCanSink::take_received)
  std::uint64_t received_dropped = 0;  // more than kMaxReceived waiting: the oldest kept, the rest counted
  bool bus_off = false;                // since the last CAN_ERR_BUSOFF, until CAN_ERR_RESTARTED
};

// What the pipeline hands its frames to; replay and tests use the log, the daemon the socket.
class CanSink {
 public:
  virtual ~CanSink() = default;
  // Frames sent at `t` (the log writes it; the socket lets the kernel stamp them).
  virtual void write(std::span<const CanFrame> frames, Stamp t) = 0;
  [[nodiscard]] virtual const CanSinkStats& stats() const = 0;

 protected:
  CanSink() = default;
  CanSink(const CanSink&) = default;
  CanSink& operator=(const CanSink&) = default;
  CanSink(CanSink&&) = default;
  CanSink& operator=(CanSink&&) = default;
};

// Frames counted and sent nowhere: the daemon's `can.sink: none`, and replay deciding without `--can-log`.
class NullSink final : public CanSink {
 public:
  void write(std::span<const CanFrame> frames, Stamp /*t*/) override { stats_.sent += frames.size(); }
  [[nodiscard]] const CanSinkStats& stats() const override { return stats_; }

 private:
  CanSinkStats stats_;
};

class CandumpLogSink final : public CanSink {
 public:
  // Creates or truncates `path`; throws std::runtime_error naming the file and the reason if it cannot,
  // std::invalid_argument for a bad interface name.
  CandumpLogSink(const std::string& path, std::string iface);
  ~CandumpLogSink() override;
  CandumpLogSink(const CandumpLogSink&) = delete;
  CandumpLogSink& operator=(const CandumpLogSink&) = delete;
  CandumpLogSink(CandumpLogSink&&) = delete;
  CandumpLogSink& operator=(CandumpLogSink&&) = delete;

  // Every frame stamped `t`, then a flush.
  void write(std::span<const CanFrame> frames, Stamp t) override;
  [[nodiscard]] const CanSinkStats& stats() const override { return stats_; }

 private:
  std::FILE* file_ = nullptr;
  std::string iface_;
  std::string line_;
  CanSinkStats stats_;
};

class SocketCanSink final : public CanSink {
 public:
  // A CAN_RAW socket bound to `iface`, non-blocking, receiving error frames (bus-off, controller problems,
  // restarts) and what the J1939 node must hear (listen()): requests, Address Claimed, frames from our address. The
  // error says what failed and what to do (no SocketCAN in the kernel, no such interface, ...).
  [[nodiscard]] static Expected<SocketCanSink, std::string> open(std::string_view iface);

  // Adopts `fd` (a CAN_RAW socket, or in tests one end of a socketpair carrying struct can_frame) and makes
  // it non-blocking. Closes it on destruction.
  explicit SocketCanSink(int fd);
  ~SocketCanSink() override;
  SocketCanSink(SocketCanSink&& other) noexcept;
  SocketCanSink& operator=(SocketCanSink&& other) noexcept;
  SocketCanSink(const SocketCanSink&) = delete;
  SocketCanSink& operator=(const SocketCanSink&) = delete;

  enum class SendResult : std::uint8_t { Sent, Dropped, Failed };
  // Never blocks.
  SendResult send(const CanFrame& f);
  // poll(), then send() each frame; `t` is unused (the kernel stamps what goes on the bus).
  void write(std::span<const CanFrame> frames, Stamp t) override;
  // Reads what is waiting (never blocks): error frames counted, extended data frames kept for take_received().
  void poll();
  // The data frames poll() kept, oldest first, in `out` (cleared first). The sink never hands them to anyone
  // itself: write() polls too, and the J1939 node must not be entered while it is writing.
  void take_received(std::vector<CanFrame>& out);
  // The kernel's filters for the J1939 node: Request (PGN 59904) and Address Claimed (60928) from anyone, and any
  // frame from `own_address` (another node using it: an address violation). Call again when the address moves.
  // Our own frames never come back: CAN_RAW does not echo a socket's frames to itself. False when refused.
  bool listen(std::uint8_t own_address);

  static constexpr std::size_t kMaxReceived = 256;

  [[nodiscard]] const CanSinkStats& stats() const override { return stats_; }
  [[nodiscard]] int fd() const { return fd_; }

 private:
  int fd_ = -1;
  CanSinkStats stats_;
  std::vector<CanFrame> received_;
};

}  // namespace fieldguard::output
