#pragma once
// What the J1939 node hears on a SocketCAN bus: the sink's own socket (CAN_RAW does not echo a socket's frames to
// itself, so an address violation is never our own frame) watched on the io thread. Each time it is readable the
// socket is read, and then, as on every tick of the output timer (a write() may have read frames meanwhile), what
// was read goes to the link in order, bus-off and recovery too, and the socket's filters follow the address we
// hold. Thread contract: the io thread only.

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/engine/can_link.hpp"
#include "fieldguard/output/can_sink.hpp"

namespace fieldguard::app {

class BusListener {
 public:
  // Both must outlive the listener. Throws std::system_error when the socket cannot be watched.
  BusListener(boost::asio::io_context& io, output::SocketCanSink& socket, CanLink& link);
  ~BusListener();
  BusListener(const BusListener&) = delete;
  BusListener& operator=(const BusListener&) = delete;
  BusListener(BusListener&&) = delete;
  BusListener& operator=(BusListener&&) = delete;

  // Hands over what the socket has read (the watch's reads and write()'s), bus-off and recovery; no system call
  // unless our address moved. The watch calls it after reading; the output timer on every tick.
  void deliver();
  // Empty while the socket took its filters; otherwise why not (a socketpair in tests takes none).
  [[nodiscard]] const std::string& filter_problem() const { return filter_problem_; }

 private:
  void watch();

  output::SocketCanSink& socket_;
  CanLink& link_;
  boost::asio::posix::stream_descriptor watch_;
  std::vector<output::CanFrame> heard_;
  std::optional<std::uint8_t> listening_for_;
  bool bus_off_ = false;
  std::string filter_problem_;
};

}  // namespace fieldguard::app
