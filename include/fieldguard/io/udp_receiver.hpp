#pragma once
// Live UDP input for the 3D LiDAR's data and status ports, on the io thread's Boost.Asio io_context.
// Each datagram is handed over with the kernel's receive time (SO_TIMESTAMPNS); the kernel's count of
// datagrams it dropped for want of buffer space (SO_RXQ_OVFL) is tracked. Thread contract: construct,
// start() and stop() on the io thread (or before it runs); the handler runs on the io thread.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "fieldguard/io/udp_frame.hpp"

namespace boost::asio {
class io_context;
}

namespace fieldguard::io {

struct UdpReceiverOptions {
  std::string bind_address = "0.0.0.0";
  std::uint16_t port = 2368;
  int receive_buffer_bytes = 8 * 1024 * 1024;  // asked of the kernel; it may grant less (net.core.rmem_max)
};

struct UdpReceiverStats {
  std::atomic<std::uint64_t> datagrams{0};
  std::atomic<std::uint64_t> bytes{0};
  std::atomic<std::uint64_t> kernel_drops{0};  // SO_RXQ_OVFL: dropped by the kernel before we read them
  std::atomic<std::uint64_t> truncated{0};     // larger than our buffer (MSG_TRUNC)
  std::atomic<std::uint64_t> errors{0};        // receive errors other than would-block
  std::atomic<std::int64_t> last_rx_ns{0};
};

class UdpReceiver {
 public:
  // The payload span is valid only during the call.
  using Handler = std::function<void(const UdpDatagram&)>;

  // Throws std::system_error with a message naming the address and port when the socket cannot be bound.
  UdpReceiver(boost::asio::io_context& io, const UdpReceiverOptions& options, Handler handler);
  ~UdpReceiver();
  UdpReceiver(const UdpReceiver&) = delete;
  UdpReceiver& operator=(const UdpReceiver&) = delete;

  void start();
  void stop();  // idempotent

  [[nodiscard]] const UdpReceiverStats& stats() const;
  [[nodiscard]] int granted_receive_buffer_bytes() const;
  [[nodiscard]] std::uint16_t local_port() const;  // the bound port (useful with port 0 in tests)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldguard::io
