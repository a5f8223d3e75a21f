#include "fieldguard/io/scip_source.hpp"

#include <vector>

#include "fieldguard/drivers/scip.hpp"

namespace fieldguard::io {

struct ScipSource::Impl {
  Impl(boost::asio::io_context& io, ScipSourceOptions o, ScanHandler s, StateHandler st)
      : options(std::move(o)), on_scan(std::move(s)), on_state(std::move(st)), client(options.client),
        link(io, options.tcp,
             {.on_connected = [this] { connected(); },
              .on_data = [this](ByteSpan b, Stamp t) { data(b, t); },
              .on_state = [this](TcpState, const std::string& why) { say(why); }}) {}

  ScipSourceOptions options;
  ScanHandler on_scan;
  StateHandler on_state;
  ScipSourceStats stats;
  scip::ReplyParser parser;
  scip::Client client;
  std::uint64_t parser_errors_at_connect = 0;
  std::vector<scip::Reply> replies;
  TcpClient link;  // last: its handlers use the members above

  void say(const std::string& s) const {
    if (on_state) on_state(s);
  }

  void connected() {
    parser.reset();
    client = scip::Client(options.client);
    parser_errors_at_connect = parser.counters().rejected();
    counted_errors_ = 0;
    link.send(client.start());
  }

  void data(ByteSpan bytes, Stamp t) {
    replies.clear();
    parser.push(bytes, replies);
    const std::uint64_t errors = parser.counters().rejected() - parser_errors_at_connect;
    stats.parser_errors = stats.parser_errors.load() + (errors - std::min(errors, counted_errors_));
    counted_errors_ = errors;
    for (const auto& r : replies) {
      scip::ClientEvent ev = client.on_reply(r);
      if (ev.error) ++stats.decode_errors;
      if (ev.sensor_status) {
        ++stats.sensor_trouble;
        say("2D LiDAR reports status " + *ev.sensor_status);
      }
      if (ev.refused) {
        ++stats.refusals;
        link.reconnect("2D LiDAR refused " + std::string(scip::to_string(ev.refused->command)) + " with status " +
                       ev.refused->status + " (" + std::string(ev.refused->text) + ")");
        return;
      }
      if (!ev.send.empty()) link.send(ev.send);
      if (ev.scan) {
        ++stats.scans;
        if (on_scan) on_scan(*ev.scan, client.geometry(), t);
      }
    }
    if (errors > options.max_parser_errors) {
      link.reconnect("2D LiDAR stream unreadable: " + std::to_string(errors) + " framing errors on this connection");
    }
  }

  std::uint64_t counted_errors_ = 0;
};

ScipSource::ScipSource(boost::asio::io_context& io, ScipSourceOptions options, ScanHandler on_scan,
                       StateHandler on_state)
    : impl_(std::make_unique<Impl>(io, std::move(options), std::move(on_scan), std::move(on_state))) {}

ScipSource::~ScipSource() { stop(); }

void ScipSource::start() { impl_->link.start(); }

void ScipSource::stop() { impl_->link.stop(); }

const ScipSourceStats& ScipSource::stats() const { return impl_->stats; }
const TcpClientStats& ScipSource::link() const { return impl_->link.stats(); }
scip::ClientState ScipSource::protocol_state() const { return impl_->client.state(); }

}  // namespace fieldguard::io
