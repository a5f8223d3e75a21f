#include "fieldguard/io/can_reader.hpp"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cerrno>
#include <cstring>
#include <utility>

namespace fieldguard::io {
namespace {

std::string errno_text(int e) { return std::strerror(e); }

}  // namespace

Expected<int, std::string> CanReader::open_socket(std::string_view iface, const std::vector<CanFilter>& filters) {
  const std::string name(iface);
  if (name.empty() || name.size() >= IFNAMSIZ)
    return Unexpected{std::string("CAN interface name '" + name + "' is not valid")};
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    return Unexpected{
        "cannot open a CAN_RAW socket: " + errno_text(errno) +
        (errno == EAFNOSUPPORT ? " (no SocketCAN in this kernel: load the can and can_raw modules)" : "")};
  }
  std::vector<can_filter> kf;
  kf.reserve(filters.size());
  for (const CanFilter& f : filters) {
    kf.push_back(
        can_filter{(f.id & CAN_EFF_MASK) | CAN_EFF_FLAG, (f.mask & CAN_EFF_MASK) | CAN_EFF_FLAG | CAN_RTR_FLAG});
  }
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, kf.empty() ? nullptr : kf.data(),
                   static_cast<socklen_t>(kf.size() * sizeof(can_filter))) != 0) {
    const int e = errno;
    ::close(fd);
    return Unexpected{"CAN_RAW_FILTER on " + name + ": " + errno_text(e)};
  }
  const unsigned index = ::if_nametoindex(name.c_str());
  if (index == 0) {
    const int e = errno;
    ::close(fd);
    return Unexpected{"no CAN interface '" + name + "': " + errno_text(e) + " (ip link show type can)"};
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(index);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const int e = errno;
    ::close(fd);
    return Unexpected{"cannot bind a CAN socket to " + name + ": " + errno_text(e)};
  }
  return fd;
}

struct CanReader::Impl {
  Impl(boost::asio::io_context& io, int fd, std::vector<CanFilter> f, Handler h)
      : stream(io, fd), filters(std::move(f)), handler(std::move(h)) {
    stream.non_blocking(true);
  }
  boost::asio::posix::stream_descriptor stream;
  std::vector<CanFilter> filters;
  Handler handler;
  CanReaderStats stats;
  bool running = false;

  [[nodiscard]] bool passes(std::uint32_t id) const {
    if (filters.empty()) return false;
    for (const CanFilter& f : filters) {
      if ((id & f.mask) == (f.id & f.mask)) return true;
    }
    return false;
  }

  void arm() {
    if (!running) return;
    stream.async_wait(boost::asio::posix::stream_descriptor::wait_read, [this](const boost::system::error_code& ec) {
      if (ec || !running) return;
      drain();
      arm();
    });
  }

  void drain() {
    for (;;) {
      can_frame cf{};
      const ssize_t n = ::recv(stream.native_handle(), &cf, sizeof cf, MSG_DONTWAIT);
      if (n < 0) {
        if (errno == EINTR) continue;
        if (errno != EAGAIN && errno != EWOULDBLOCK) ++stats.errors;
        return;
      }
      if (n == 0) return;  // a socketpair's peer closed (tests)
      const Stamp now = wall_clock_now();
      if (n != static_cast<ssize_t>(sizeof cf) || cf.can_dlc > CAN_MAX_DLEN) {
        ++stats.bad_size;
        continue;
      }
      // The kernel filters a real CAN socket; a socketpair's frames are filtered here with the same rule.
      if ((cf.can_id & CAN_EFF_FLAG) == 0 || (cf.can_id & (CAN_RTR_FLAG | CAN_ERR_FLAG)) != 0 ||
          !passes(cf.can_id & CAN_EFF_MASK)) {
        ++stats.not_ours;
        continue;
      }
      ++stats.frames;
      handler(cf.can_id & CAN_EFF_MASK, std::span<const std::uint8_t>(cf.data, cf.can_dlc), now);
    }
  }
};

CanReader::CanReader(boost::asio::io_context& io, int fd, std::vector<CanFilter> filters, Handler handler)
    : impl_(std::make_unique<Impl>(io, fd, std::move(filters), std::move(handler))) {}

CanReader::~CanReader() { stop(); }

void CanReader::start() {
  if (impl_->running) return;
  impl_->running = true;
  impl_->arm();
}

void CanReader::stop() {
  if (!impl_->running) return;
  impl_->running = false;
  boost::system::error_code ec;
  impl_->stream.cancel(ec);
}

const CanReaderStats& CanReader::stats() const { return impl_->stats; }

}  // namespace fieldguard::io
