#include "fieldguard/io/serial_reader.hpp"

#include <array>
#include <boost/asio/io_context.hpp>
#include <boost/asio/serial_port.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>

#include "io/clock.hpp"

namespace fieldguard::io {

using detail::now_ns;
using detail::seconds;

std::string_view to_string(SerialState s) {
  switch (s) {
    case SerialState::Closed: return "closed";
    case SerialState::Open: return "open";
    case SerialState::Silent: return "silent";
  }
  return "unknown";
}

// Shared with the pending asynchronous operations, so a handler that runs after stop() finds it alive.
struct SerialReader::Impl : std::enable_shared_from_this<Impl> {
  Impl(boost::asio::io_context& io, SerialOptions o, Handler h, StateHandler s)
      : port(io),
        reopen_timer(io),
        silence_timer(io),
        options(std::move(o)),
        handler(std::move(h)),
        on_state(std::move(s)) {}

  boost::asio::serial_port port;
  boost::asio::steady_timer reopen_timer;
  boost::asio::steady_timer silence_timer;
  SerialOptions options;
  Handler handler;
  StateHandler on_state;
  SerialStats stats;
  std::array<std::uint8_t, 4096> buffer{};
  bool running = false;
  bool failure_reported = false;  // the current run of failed opens has been reported once
  std::uint64_t generation = 0;   // bumps on every close, so stale handlers of an old open do nothing

  void set_state(SerialState s, const std::string& why) {
    if (stats.state.load() == s) return;
    stats.state = s;
    if (on_state) on_state(s, why);
  }

  void try_open() {
    if (!running) return;
    boost::system::error_code ec;
    port.open(options.device, ec);
    if (!ec) configure(ec);
    if (ec) {
      ++stats.open_failures;
      boost::system::error_code ignored;
      port.close(ignored);
      const std::string why = "cannot open " + options.device + ": " + ec.message() + "; retrying every " +
                              std::to_string(options.reopen_interval_s) + " s";
      if (!failure_reported && stats.state.load() == SerialState::Closed && on_state)
        on_state(SerialState::Closed, why);
      failure_reported = true;
      set_state(SerialState::Closed, why);
      schedule_reopen();
      return;
    }
    ++stats.opens;
    failure_reported = false;
    set_state(SerialState::Open, options.device + " open at " + std::to_string(options.baud) + " baud");
    arm_silence();
    read();
  }

  void configure(boost::system::error_code& ec) {
    using boost::asio::serial_port_base;
    port.set_option(serial_port_base::baud_rate(options.baud), ec);
    if (!ec) port.set_option(serial_port_base::character_size(options.data_bits), ec);
    if (!ec) {
      const auto p = options.parity == 'E'   ? serial_port_base::parity::even
                     : options.parity == 'O' ? serial_port_base::parity::odd
                                             : serial_port_base::parity::none;
      port.set_option(serial_port_base::parity(p), ec);
    }
    if (!ec) {
      port.set_option(serial_port_base::stop_bits(options.stop_bits == 2 ? serial_port_base::stop_bits::two
                                                                         : serial_port_base::stop_bits::one),
                      ec);
    }
    if (!ec) port.set_option(serial_port_base::flow_control(serial_port_base::flow_control::none), ec);
  }

  void schedule_reopen() {
    reopen_timer.expires_after(seconds(options.reopen_interval_s));
    reopen_timer.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (!ec) self->try_open();
    });
  }

  void arm_silence() {
    silence_timer.expires_after(seconds(options.silence_timeout_s));
    silence_timer.async_wait([self = shared_from_this(), gen = generation](const boost::system::error_code& ec) {
      if (ec || !self->running || gen != self->generation) return;
      if (self->stats.state.load() == SerialState::Open) {
        ++self->stats.silences;
        self->set_state(SerialState::Silent,
                        self->options.device + " silent for " + std::to_string(self->options.silence_timeout_s) + " s");
      }
    });
  }

  void read() {
    port.async_read_some(boost::asio::buffer(buffer),
                         [self = shared_from_this(), gen = generation](const boost::system::error_code& ec,
                                                                       std::size_t n) { self->on_read(ec, n, gen); });
  }

  void on_read(const boost::system::error_code& ec, std::size_t n, std::uint64_t gen) {
    if (!running || gen != generation) return;
    if (ec) {
      ++stats.read_errors;
      close();
      set_state(SerialState::Closed, options.device + " lost: " + ec.message() + "; reopening");
      schedule_reopen();
      return;
    }
    if (n > 0) {
      const std::int64_t t = now_ns();
      stats.bytes += n;
      ++stats.chunks;
      stats.last_rx_ns = t;
      if (stats.state.load() != SerialState::Open) set_state(SerialState::Open, options.device + " talking again");
      arm_silence();
      handler(ByteSpan(buffer.data(), n), Stamp{t});
    }
    read();
  }

  void close() {
    ++generation;
    boost::system::error_code ignored;
    silence_timer.cancel();
    port.close(ignored);
  }
};

SerialReader::SerialReader(boost::asio::io_context& io, SerialOptions options, Handler handler, StateHandler on_state)
    : impl_(std::make_shared<Impl>(io, std::move(options), std::move(handler), std::move(on_state))) {}

SerialReader::~SerialReader() {
  try {
    stop();
  } catch (...) {  // NOLINT(bugprone-empty-catch): closing the port failed; nothing is left to do with it
  }
}

void SerialReader::start() {
  if (impl_->running) return;
  impl_->running = true;
  impl_->try_open();
}

void SerialReader::stop() {
  if (!impl_->running) return;
  impl_->running = false;
  impl_->reopen_timer.cancel();
  impl_->close();
  impl_->stats.state = SerialState::Closed;
}

const SerialStats& SerialReader::stats() const { return impl_->stats; }

}  // namespace fieldguard::io
