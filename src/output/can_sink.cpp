#include "fieldguard/output/can_sink.hpp"

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace fieldguard::output {
namespace {

static_assert(sizeof(can_frame) == 16, "struct can_frame is the 16-byte CAN_MTU record");

constexpr std::array<char, 16> kHex{'0', '1', '2', '3', '4', '5', '6', '7', '8', '9', 'A', 'B', 'C', 'D', 'E', 'F'};

void append_hex(std::string& s, std::uint64_t v, int digits) {
  for (int i = digits - 1; i >= 0; --i) s.push_back(kHex[(v >> (4U * static_cast<unsigned>(i))) & 0xFU]);
}

void append_dec(std::string& s, std::uint64_t v, int width) {
  std::array<char, 24> buf{};
  int n = 0;
  do {
    buf[static_cast<std::size_t>(n++)] = static_cast<char>('0' + v % 10);
    v /= 10;
  } while (v != 0);
  for (int i = n; i < width; ++i) s.push_back('0');
  while (n > 0) s.push_back(buf[static_cast<std::size_t>(--n)]);
}

void append_line(std::string& s, const CanFrame& f, Stamp t, std::string_view iface) {
  const std::uint64_t ns = t.ns < 0 ? 0 : static_cast<std::uint64_t>(t.ns);
  s.push_back('(');
  append_dec(s, ns / 1'000'000'000U, 10);
  s.push_back('.');
  append_dec(s, (ns % 1'000'000'000U) / 1000U, 6);
  s += ") ";
  s += iface;
  s.push_back(' ');
  append_hex(s, f.id & kEffMask, 8);
  s.push_back('#');
  const std::size_t len = f.len > 8 ? 8 : f.len;
  for (std::size_t i = 0; i < len; ++i) append_hex(s, f.data[i], 2);
  s.push_back('\n');
}

std::string errno_text(int e) { return std::strerror(e); }  // NOLINT(concurrency-mt-unsafe): start-up only

}  // namespace

std::string candump_line(const CanFrame& f, Stamp t, std::string_view iface) {
  std::string s;
  append_line(s, f, t, iface);
  return s;
}

std::string check_interface_name(std::string_view iface) {
  if (iface.empty()) return "the CAN interface name is empty (e.g. can0)";
  if (iface.size() >= IFNAMSIZ)
    return "the CAN interface name '" + std::string(iface) + "' is longer than 15 characters";
  for (const char c : iface) {
    if (c == '/' || c == ':' || c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\0') {
      return "the CAN interface name '" + std::string(iface) + "' contains '/', ':', NUL or whitespace";
    }
  }
  return {};
}

// --- candump log ---------------------------------------------------------------------------------------

CandumpLogSink::CandumpLogSink(const std::string& path, std::string iface) : iface_(std::move(iface)) {
  if (const auto bad = check_interface_name(iface_); !bad.empty()) throw std::invalid_argument(bad);
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) {
    throw std::runtime_error("cannot create the CAN log " + path + ": " + errno_text(errno) +
                             " (check the directory exists and is writable)");
  }
  line_.reserve(64);
}

CandumpLogSink::~CandumpLogSink() {
  if (file_ != nullptr) std::fclose(file_);
}

void CandumpLogSink::write(std::span<const CanFrame> frames, Stamp t) {
  for (const CanFrame& f : frames) {
    line_.clear();
    append_line(line_, f, t, iface_);
    if (std::fwrite(line_.data(), 1, line_.size(), file_) == line_.size()) {
      ++stats_.sent;
    } else {
      ++stats_.write_errors;
      stats_.last_errno = errno;
    }
  }
  if (std::fflush(file_) != 0) {
    ++stats_.write_errors;
    stats_.last_errno = errno;
  }
}

// --- SocketCAN -----------------------------------------------------------------------------------------

Expected<SocketCanSink, std::string> SocketCanSink::open(std::string_view iface) {
  if (auto bad = check_interface_name(iface); !bad.empty()) return Unexpected{std::move(bad)};
  const std::string name(iface);
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    const int e = errno;
    return Unexpected{"cannot open a CAN_RAW socket for " + name + ": " + errno_text(e) +
                      (e == EAFNOSUPPORT || e == EPROTONOSUPPORT
                           ? " (this kernel has no SocketCAN: load it with `modprobe can_raw`)"
                           : "")};
  }
  SocketCanSink sink(fd);  // closes fd on every early return below
  const unsigned index = ::if_nametoindex(name.c_str());
  if (index == 0) {
    return Unexpected{"CAN interface " + name + ": " + errno_text(errno) + " (check `ip link show " + name +
                      "` and the configured interface name)"};
  }
  // No data frames in until listen() says which the J1939 node needs; the error classes the sink counts.
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, nullptr, 0) != 0) {
    return Unexpected{"CAN_RAW_FILTER on " + name + ": " + errno_text(errno)};
  }
  const can_err_mask_t err_mask = CAN_ERR_BUSOFF | CAN_ERR_RESTARTED | CAN_ERR_CRTL | CAN_ERR_TX_TIMEOUT;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) != 0) {
    return Unexpected{"CAN_RAW_ERR_FILTER on " + name + ": " + errno_text(errno)};
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(index);
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {  // NOLINT: the sockets API
    return Unexpected{"cannot bind the CAN_RAW socket to " + name + ": " + errno_text(errno)};
  }
  return sink;
}

SocketCanSink::SocketCanSink(int fd) : fd_(fd) {
  if (fd_ < 0) throw std::invalid_argument("SocketCanSink: invalid file descriptor");
  const int flags = ::fcntl(fd_, F_GETFL);
  if (flags < 0 || ::fcntl(fd_, F_SETFL, flags | O_NONBLOCK) != 0) {
    const int e = errno;
    ::close(fd_);
    fd_ = -1;
    throw std::runtime_error("SocketCanSink: cannot make the socket non-blocking: " + errno_text(e));
  }
}

SocketCanSink::~SocketCanSink() {
  if (fd_ >= 0) ::close(fd_);
}

SocketCanSink::SocketCanSink(SocketCanSink&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), stats_(other.stats_), received_(std::move(other.received_)) {}

SocketCanSink& SocketCanSink::operator=(SocketCanSink&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
    stats_ = other.stats_;
    received_ = std::move(other.received_);
  }
  return *this;
}

// NOLINTNEXTLINE(readability-make-member-function-const): it changes what the socket receives
bool SocketCanSink::listen(std::uint8_t own_address) {
  constexpr canid_t kPf = 0x00FF0000U;  // the PDU format byte: the PGN of a PDU1 message without its destination
  const can_filter filters[] = {
      {CAN_EFF_FLAG | 0x00EA0000U, CAN_EFF_FLAG | CAN_RTR_FLAG | kPf},    // Request
      {CAN_EFF_FLAG | 0x00EE0000U, CAN_EFF_FLAG | CAN_RTR_FLAG | kPf},    // Address Claimed, Cannot Claim
      {CAN_EFF_FLAG | own_address, CAN_EFF_FLAG | CAN_RTR_FLAG | 0xFFU},  // anything from our address
  };
  return ::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, filters, sizeof filters) == 0;
}

void SocketCanSink::take_received(std::vector<CanFrame>& out) {
  out.clear();
  out.swap(received_);
}

SocketCanSink::SendResult SocketCanSink::send(const CanFrame& f) {
  can_frame cf{};
  cf.can_id = (f.id & CAN_EFF_MASK) | CAN_EFF_FLAG;
  cf.len = f.len > CAN_MAX_DLEN ? CAN_MAX_DLEN : f.len;
  std::memcpy(cf.data, f.data.data(), cf.len);
  ssize_t n = 0;
  do {
    n = ::send(fd_, &cf, sizeof cf, MSG_DONTWAIT | MSG_NOSIGNAL);
  } while (n < 0 && errno == EINTR);
  if (n == static_cast<ssize_t>(sizeof cf)) {
    ++stats_.sent;
    return SendResult::Sent;
  }
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS)) {
    ++stats_.dropped;
    stats_.last_errno = errno;
    return SendResult::Dropped;
  }
  ++stats_.write_errors;
  stats_.last_errno = n < 0 ? errno : EIO;
  return SendResult::Failed;
}

void SocketCanSink::write(std::span<const CanFrame> frames, Stamp /*t*/) {
  poll();
  for (const CanFrame& f : frames) (void)send(f);
}

void SocketCanSink::poll() {
  for (;;) {
    can_frame cf{};
    const ssize_t n = ::recv(fd_, &cf, sizeof cf, MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EINTR) continue;
      return;  // EAGAIN: nothing waiting; anything else shows up again on send
    }
    if (n == 0) return;  // the socketpair peer closed (tests); a CAN socket never reads 0
    if (n != static_cast<ssize_t>(sizeof cf)) {
      ++stats_.unexpected_reads;
      continue;
    }
    if ((cf.can_id & CAN_ERR_FLAG) == 0) {
      if ((cf.can_id & CAN_EFF_FLAG) == 0 || (cf.can_id & CAN_RTR_FLAG) != 0 || cf.len > CAN_MAX_DLEN) {
        ++stats_.unexpected_reads;
        continue;
      }
      if (received_.size() >= kMaxReceived) {
        ++stats_.received_dropped;
        continue;
      }
      CanFrame f;
      f.id = cf.can_id & CAN_EFF_MASK;
      f.len = cf.len;
      std::memcpy(f.data.data(), cf.data, cf.len);
      received_.push_back(f);
      ++stats_.received;
      continue;
    }
    ++stats_.error_frames;
    if ((cf.can_id & CAN_ERR_BUSOFF) != 0) {
      ++stats_.bus_off_events;
      stats_.bus_off = true;
    }
    if ((cf.can_id & CAN_ERR_RESTARTED) != 0) {
      ++stats_.restarts;
      stats_.bus_off = false;
    }
  }
}

}  // namespace fieldguard::output
