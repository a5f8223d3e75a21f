#include "fieldguard/io/tcp_client.hpp"

#include <array>
#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>
#include <chrono>
#include <deque>

#include "io/clock.hpp"

namespace fieldguard::io {

using detail::now_ns;
using detail::seconds;

std::string_view to_string(TcpState s) {
  switch (s) {
    case TcpState::Idle: return "idle";
    case TcpState::Connecting: return "connecting";
    case TcpState::Connected: return "connected";
    case TcpState::Backoff: return "backoff";
  }
  return "unknown";
}

namespace {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

}  // namespace

struct TcpClient::Impl : std::enable_shared_from_this<Impl> {
  Impl(asio::io_context& io, TcpClientOptions o, Handlers h)
      : socket(io),
        resolver(io),
        timer(io),
        silence(io),
        options(std::move(o)),
        handlers(std::move(h)),
        backoff_s(options.backoff_initial_s) {}

  tcp::socket socket;
  tcp::resolver resolver;
  asio::steady_timer timer;    // connect timeout and backoff
  asio::steady_timer silence;  // silence while connected
  TcpClientOptions options;
  Handlers handlers;
  TcpClientStats stats;
  std::array<std::uint8_t, 16384> buffer{};
  std::deque<std::string> outbox;
  bool running = false;
  double backoff_s;
  std::uint64_t generation = 0;  // bumps on every drop, so handlers of an old connection do nothing

  void set_state(TcpState s, const std::string& why) {
    if (stats.state.load() == s) return;
    stats.state = s;
    if (handlers.on_state) handlers.on_state(s, why);
  }

  [[nodiscard]] std::string peer() const { return options.host + ":" + std::to_string(options.port); }

  void connect() {
    if (!running) return;
    set_state(TcpState::Connecting, "connecting to " + peer());
    const auto gen = generation;
    boost::system::error_code ec;
    const auto endpoints = resolver.resolve(options.host, std::to_string(options.port), ec);
    if (ec) {
      fail_connect("cannot resolve " + options.host + ": " + ec.message());
      return;
    }
    timer.expires_after(seconds(options.connect_timeout_s));
    timer.async_wait([self = shared_from_this(), gen](const boost::system::error_code& e) {
      if (!e && gen == self->generation && self->stats.state.load() == TcpState::Connecting) {
        boost::system::error_code ignored;
        self->socket.close(ignored);  // the pending connect completes with operation_aborted
      }
    });
    asio::async_connect(
        socket, endpoints, [self = shared_from_this(), gen](const boost::system::error_code& e, const tcp::endpoint&) {
          if (!self->running || gen != self->generation) return;
          self->timer.cancel();
          if (e) {
            self->fail_connect("cannot connect to " + self->peer() + ": " +
                               (e == asio::error::operation_aborted ? std::string("timed out") : e.message()));
            return;
          }
          self->on_connected();
        });
  }

  void fail_connect(const std::string& why) {
    ++stats.connect_failures;
    drop_socket();
    backoff(why);
  }

  void backoff(const std::string& why) {
    set_state(TcpState::Backoff, why + "; retrying in " + std::to_string(backoff_s) + " s");
    timer.expires_after(seconds(backoff_s));
    backoff_s = std::min(backoff_s * 2.0, options.backoff_max_s);
    timer.async_wait([self = shared_from_this()](const boost::system::error_code& e) {
      if (!e) self->connect();
    });
  }

  void on_connected() {
    ++stats.connects;
    backoff_s = options.backoff_initial_s;
    boost::system::error_code ec;
    socket.set_option(tcp::no_delay(true), ec);
    set_state(TcpState::Connected, "connected to " + peer());
    arm_silence();
    read();
    if (handlers.on_connected) handlers.on_connected();
  }

  void arm_silence() {
    silence.expires_after(seconds(options.silence_timeout_s));
    silence.async_wait([self = shared_from_this(), gen = generation](const boost::system::error_code& e) {
      if (e || !self->running || gen != self->generation) return;
      ++self->stats.silences;
      self->drop("no data from " + self->peer() + " for " + std::to_string(self->options.silence_timeout_s) + " s");
    });
  }

  void read() {
    socket.async_read_some(asio::buffer(buffer), [self = shared_from_this(), gen = generation](
                                                     const boost::system::error_code& e, std::size_t n) {
      if (!self->running || gen != self->generation) return;
      if (e) {
        self->drop(e == asio::error::eof ? self->peer() + " closed the connection" : self->peer() + ": " + e.message());
        return;
      }
      const std::int64_t t = now_ns();
      self->stats.bytes_in += n;
      self->stats.last_rx_ns = t;
      self->arm_silence();
      if (self->handlers.on_data) self->handlers.on_data(ByteSpan(self->buffer.data(), n), Stamp{t});
      if (gen == self->generation) self->read();  // on_data may have asked for a reconnect
    });
  }

  void write_next() {
    asio::async_write(socket, asio::buffer(outbox.front()),
                      [self = shared_from_this(), gen = generation](const boost::system::error_code& e, std::size_t n) {
                        if (!self->running || gen != self->generation) return;
                        if (e) {
                          self->drop("writing to " + self->peer() + ": " + e.message());
                          return;
                        }
                        self->stats.bytes_out += n;
                        self->outbox.pop_front();
                        if (!self->outbox.empty()) self->write_next();
                      });
  }

  void drop_socket() {
    ++generation;
    outbox.clear();
    silence.cancel();
    boost::system::error_code ignored;
    socket.shutdown(tcp::socket::shutdown_both, ignored);
    socket.close(ignored);
  }

  void drop(const std::string& why) {
    ++stats.disconnects;
    drop_socket();
    backoff(why);
  }
};

TcpClient::TcpClient(asio::io_context& io, TcpClientOptions options, Handlers handlers)
    : impl_(std::make_shared<Impl>(io, std::move(options), std::move(handlers))) {}

TcpClient::~TcpClient() { stop(); }

void TcpClient::start() {
  if (impl_->running) return;
  impl_->running = true;
  impl_->connect();
}

void TcpClient::stop() {
  if (!impl_->running) return;
  impl_->running = false;
  impl_->timer.cancel();
  impl_->drop_socket();
  impl_->stats.state = TcpState::Idle;
}

bool TcpClient::send(std::string_view bytes) {
  if (impl_->stats.state.load() != TcpState::Connected) return false;
  impl_->outbox.emplace_back(bytes);
  if (impl_->outbox.size() == 1) impl_->write_next();
  return true;
}

void TcpClient::reconnect(const std::string& why) {
  if (impl_->running && impl_->stats.state.load() == TcpState::Connected) impl_->drop(why);
}

const TcpClientStats& TcpClient::stats() const { return impl_->stats; }

}  // namespace fieldguard::io
