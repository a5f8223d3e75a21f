#pragma once
// Live serial input (GNSS NMEA, Xsens MTi) through boost::asio::serial_port on the io thread.
// Opens the device with the configured baud rate and framing, hands every chunk of bytes to the handler
// with its receive time, notices silence, and reopens a device that disappeared (USB adapters do) or could
// not be opened, every reopen interval. Thread contract: start()/stop() and the handler on the io thread;
// stats() may be read from any thread.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/time.hpp"

namespace boost::asio {
class io_context;
}

namespace fieldguard::io {

struct SerialOptions {
  std::string device;  // e.g. /dev/ttyUSB0 or a /dev/serial/by-id/ link
  unsigned baud = 115200;
  unsigned data_bits = 8;          // 5..8
  char parity = 'N';               // N, E or O
  unsigned stop_bits = 1;          // 1 or 2
  double silence_timeout_s = 1.0;  // no byte for this long = silent
  double reopen_interval_s = 1.0;  // between attempts to (re)open the device
};

enum class SerialState : std::uint8_t { Closed = 0, Open = 1, Silent = 2 };
[[nodiscard]] std::string_view to_string(SerialState s);

struct SerialStats {
  std::atomic<std::uint64_t> bytes{0};
  std::atomic<std::uint64_t> chunks{0};
  std::atomic<std::uint64_t> opens{0};  // successful opens (1 + reopens)
  std::atomic<std::uint64_t> open_failures{0};
  std::atomic<std::uint64_t> read_errors{0};  // the device went away or failed while open
  std::atomic<std::uint64_t> silences{0};     // times it fell silent
  std::atomic<std::int64_t> last_rx_ns{0};
  std::atomic<SerialState> state{SerialState::Closed};
};

class SerialReader {
 public:
  using Handler = std::function<void(ByteSpan bytes, Stamp rx_time)>;
  // Called on every state change with a one-line reason, for the log and the status.
  using StateHandler = std::function<void(SerialState state, const std::string& why)>;

  SerialReader(boost::asio::io_context& io, SerialOptions options, Handler handler, StateHandler on_state = {});
  ~SerialReader();
  SerialReader(const SerialReader&) = delete;
  SerialReader& operator=(const SerialReader&) = delete;

  void start();
  void stop();  // idempotent

  [[nodiscard]] const SerialStats& stats() const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace fieldguard::io
