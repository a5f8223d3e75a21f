#include "fieldguard/io/scip_source.hpp"

#include <vector>

#include "fieldguard/drivers/scip.hpp"
#include "fieldguard/drivers/scip_session.hpp"
#include "io/clock.hpp"

namespace fieldguard::io {

struct ScipSource::Impl {
  Impl(boost::asio::io_context& io, ScipSourceOptions o, ScanHandler s, StateHandler st)
      : options(std::move(o)),
        on_scan(std::move(s)),
        on_state(std::move(st)),
        session(options.client),
        link(io, options.tcp,
             {.on_connected = [this] { connected(); },
              .on_data = [this](ByteSpan b, Stamp t) { data(b, t); },
              .on_state = [this](TcpState state, const std::string& why) { say(state == TcpState::Backoff, why); }}) {}

  ScipSourceOptions options;
  ScanHandler on_scan;
  StateHandler on_state;
  TapHandler tap;
  ScipSourceStats stats;
  scip::Session session;
  TcpClient link;  // last: its handlers use the members above

  void say(bool trouble, const std::string& s) const {
    if (on_state) on_state(trouble, s);
  }

  void send(const std::string& bytes) {
    if (bytes.empty()) return;
    if (tap) tap(ByteSpan(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), true, now());
    link.send(bytes);
  }

  static Stamp now() { return Stamp{detail::now_ns()}; }

  void connected() { send(session.connect()); }

  void data(ByteSpan bytes, Stamp t) {
    if (tap) tap(bytes, false, t);
    scip::SessionEvents ev = session.on_bytes(bytes);
    stats.parser_errors += ev.parser_errors;
    stats.decode_errors += ev.decode_errors;
    for (const auto& st : ev.sensor_status) {
      ++stats.sensor_trouble;
      say(true, "2D LiDAR reports status " + st);
    }
    for (const auto& s : ev.scans) {
      ++stats.scans;
      if (on_scan) on_scan(s, session.client().geometry(), t);
    }
    if (!ev.refusals.empty()) {
      const auto& r = ev.refusals.front();
      ++stats.refusals;
      link.reconnect("2D LiDAR refused " + std::string(scip::to_string(r.command)) + " with status " + r.status + " (" +
                     std::string(r.text) + ")");
      return;
    }
    send(ev.send);
    if (session.parser_errors_this_connection() > options.max_parser_errors) {
      link.reconnect("2D LiDAR stream unreadable: " + std::to_string(session.parser_errors_this_connection()) +
                     " framing errors on this connection");
    }
  }
};

ScipSource::ScipSource(boost::asio::io_context& io, ScipSourceOptions options, ScanHandler on_scan,
                       StateHandler on_state)
    : impl_(std::make_unique<Impl>(io, std::move(options), std::move(on_scan), std::move(on_state))) {}

ScipSource::~ScipSource() { stop(); }

void ScipSource::start() { impl_->link.start(); }

void ScipSource::stop() { impl_->link.stop(); }

const ScipSourceStats& ScipSource::stats() const { return impl_->stats; }
const TcpClientStats& ScipSource::link() const { return impl_->link.stats(); }
scip::ClientState ScipSource::protocol_state() const { return impl_->session.client().state(); }
void ScipSource::set_tap(TapHandler tap) { impl_->tap = std::move(tap); }

}  // namespace fieldguard::io
