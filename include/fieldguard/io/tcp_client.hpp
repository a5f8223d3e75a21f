#pragma once
// A TCP link to a sensor (the Hokuyo's SCIP 2.0 port) on the io thread: connects, hands every chunk of
// bytes over with its receive time, sends what the protocol layer asks, and reconnects with exponential
// backoff after a refused connection, a reset, an end of stream or silence. Thread contract: everything on
// the io thread; stats() may be read from any thread.

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

struct TcpClientOptions {
  std::string host = "192.168.0.10";
  std::uint16_t port = 10940;
  double connect_timeout_s = 2.0;
  double silence_timeout_s = 1.0;  // connected but no byte for this long: drop the link and reconnect
  double backoff_initial_s = 0.1;  // first wait before reconnecting; doubles up to backoff_max_s
  double backoff_max_s = 5.0;
};

enum class TcpState : std::uint8_t { Idle = 0, Connecting = 1, Connected = 2, Backoff = 3 };
[[nodiscard]] std::string_view to_string(TcpState s);

struct TcpClientStats {
  std::atomic<std::uint64_t> connects{0};
  std::atomic<std::uint64_t> connect_failures{0};
  std::atomic<std::uint64_t> disconnects{0};  // resets, end of stream, silence
  std::atomic<std::uint64_t> silences{0};
  std::atomic<std::uint64_t> bytes_in{0};
  std::atomic<std::uint64_t> bytes_out{0};
  std::atomic<std::int64_t> last_rx_ns{0};
  std::atomic<TcpState> state{TcpState::Idle};
};

class TcpClient {
 public:
  struct Handlers {
    std::function<void()> on_connected;  // send the start-up commands here
    std::function<void(ByteSpan, Stamp)> on_data;
    std::function<void(TcpState, const std::string&)> on_state;  // every change, with a one-line reason
  };

  TcpClient(boost::asio::io_context& io, TcpClientOptions options, Handlers handlers);
  ~TcpClient();
  TcpClient(const TcpClient&) = delete;
  TcpClient& operator=(const TcpClient&) = delete;

  void start();
  void stop();  // idempotent
  // Queues bytes for the sensor; dropped (and false returned) when not connected.
  bool send(std::string_view bytes);
  // Drop the link now and reconnect after the backoff (the protocol layer saw garbage it cannot recover).
  void reconnect(const std::string& why);

  [[nodiscard]] const TcpClientStats& stats() const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace fieldguard::io
