#include "fieldguard/io/udp_receiver.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <array>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>
#include <cerrno>
#include <cstring>
#include <system_error>

#include "fieldguard/core/time.hpp"

namespace fieldguard::io {

struct UdpReceiver::Impl {
  Impl(boost::asio::io_context& io, const UdpReceiverOptions& o, Handler h)
      : socket(io), options(o), handler(std::move(h)) {}

  boost::asio::ip::udp::socket socket;
  UdpReceiverOptions options;
  Handler handler;
  UdpReceiverStats stats;
  std::array<std::uint8_t, 65536> buffer{};
  std::uint32_t last_ovfl = 0;
  bool have_ovfl = false;
  bool running = false;
  int granted = 0;

  void arm() {
    socket.async_wait(boost::asio::socket_base::wait_read, [this](const boost::system::error_code& ec) {
      if (ec || !running) return;  // operation_aborted on stop()
      drain();
      arm();
    });
  }

  // Reads every datagram that is queued, without blocking.
  void drain() {
    alignas(cmsghdr) std::array<char, CMSG_SPACE(sizeof(timespec)) + CMSG_SPACE(sizeof(std::uint32_t)) + 64> control{};
    for (int budget = 0; budget < 4096; ++budget) {
      sockaddr_in from{};
      iovec iov{buffer.data(), buffer.size()};
      msghdr msg{};
      msg.msg_name = &from;
      msg.msg_namelen = sizeof from;
      msg.msg_iov = &iov;
      msg.msg_iovlen = 1;
      msg.msg_control = control.data();
      msg.msg_controllen = control.size();
      const ssize_t n = ::recvmsg(socket.native_handle(), &msg, MSG_DONTWAIT);
      if (n < 0) {
        if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) ++stats.errors;
        return;
      }
      std::int64_t rx_ns = 0;
      for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMPNS) {
          timespec ts{};
          std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
          rx_ns = static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
        } else if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
          std::uint32_t ovfl = 0;
          std::memcpy(&ovfl, CMSG_DATA(c), sizeof ovfl);
          if (have_ovfl)
            stats.kernel_drops += static_cast<std::uint32_t>(ovfl - last_ovfl);
          else
            stats.kernel_drops += ovfl;
          last_ovfl = ovfl;
          have_ovfl = true;
        }
      }
      if (rx_ns == 0) {
        rx_ns = wall_clock_now().ns;
      }
      if ((msg.msg_flags & MSG_TRUNC) != 0) {
        ++stats.truncated;
        continue;
      }
      ++stats.datagrams;
      stats.bytes += static_cast<std::uint64_t>(n);
      stats.last_rx_ns = rx_ns;
      UdpDatagram d;
      d.host_time = Stamp{rx_ns};
      d.src_ip = ntohl(from.sin_addr.s_addr);
      d.src_port = ntohs(from.sin_port);
      d.dst_port = options.port;
      d.payload = ByteSpan(buffer.data(), static_cast<std::size_t>(n));
      handler(d);
    }
  }
};

UdpReceiver::UdpReceiver(boost::asio::io_context& io, const UdpReceiverOptions& options, Handler handler)
    : impl_(std::make_unique<Impl>(io, options, std::move(handler))) {
  namespace ip = boost::asio::ip;
  boost::system::error_code ec;
  const auto addr = ip::make_address(options.bind_address, ec);
  if (ec) {
    throw std::system_error(std::make_error_code(std::errc::invalid_argument),
                            "bad UDP bind address '" + options.bind_address + "'");
  }
  auto& s = impl_->socket;
  s.open(addr.is_v6() ? ip::udp::v6() : ip::udp::v4());
  s.set_option(boost::asio::socket_base::reuse_address(true));
  s.set_option(boost::asio::socket_base::receive_buffer_size(options.receive_buffer_bytes), ec);
  const int on = 1;
  ::setsockopt(s.native_handle(), SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
  ::setsockopt(s.native_handle(), SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on);
  s.bind(ip::udp::endpoint(addr, options.port), ec);
  if (ec) {
    throw std::system_error(ec, "cannot bind UDP " + options.bind_address + ":" + std::to_string(options.port));
  }
  boost::asio::socket_base::receive_buffer_size granted;
  s.get_option(granted);
  impl_->granted = granted.value();
  impl_->options.port = s.local_endpoint().port();
  s.non_blocking(true);
}

UdpReceiver::~UdpReceiver() { stop(); }

void UdpReceiver::start() {
  if (impl_->running) return;
  impl_->running = true;
  impl_->arm();
}

void UdpReceiver::stop() {
  if (!impl_ || !impl_->running) return;
  impl_->running = false;
  boost::system::error_code ec;
  impl_->socket.cancel(ec);
}

const UdpReceiverStats& UdpReceiver::stats() const { return impl_->stats; }
int UdpReceiver::granted_receive_buffer_bytes() const { return impl_->granted; }
std::uint16_t UdpReceiver::local_port() const { return impl_->options.port; }

}  // namespace fieldguard::io
