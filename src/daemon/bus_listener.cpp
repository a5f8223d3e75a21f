#include "daemon/bus_listener.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

namespace fieldguard::app {

BusListener::BusListener(boost::asio::io_context& io, output::SocketCanSink& socket, CanLink& link)
    : socket_(socket), link_(link), watch_(io) {
  const int fd = ::dup(socket.fd());  // the watch closes its own copy
  if (fd < 0) throw std::system_error(errno, std::generic_category(), "cannot watch the CAN socket");
  watch_.assign(fd);
  watch();
}

BusListener::~BusListener() {
  boost::system::error_code ignored;
  watch_.cancel(ignored);
  watch_.close(ignored);
}

void BusListener::watch() {
  watch_.async_wait(boost::asio::posix::stream_descriptor::wait_read, [this](const boost::system::error_code& ec) {
    if (ec) return;
    socket_.poll();
    deliver();
    watch();
  });
}

void BusListener::deliver() {
  const Stamp now = wall_clock_now();
  const bool off = socket_.stats().bus_off;
  if (off != bus_off_) {
    bus_off_ = off;
    if (off) {
      link_.bus_off(now);
    } else {
      link_.bus_recovered(now);
    }
  }
  socket_.take_received(heard_);
  for (const auto& f : heard_) link_.receive(f, now);
  const auto* node = link_.node();
  const auto address = node != nullptr ? node->claimer().address() : std::nullopt;
  if (address && address != listening_for_) {
    listening_for_ = address;
    filter_problem_ = socket_.listen(*address) ? std::string() : std::strerror(errno);
  }
}

}  // namespace fieldguard::app
