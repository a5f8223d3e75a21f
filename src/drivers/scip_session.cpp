#include "fieldguard/drivers/scip_session.hpp"

namespace fieldguard::scip {

std::string Session::connect() {
  parser_.reset();
  client_ = Client(config_);
  errors_seen_ = parser_.counters().rejected();
  errors_this_connection_ = 0;
  return client_.start();
}

SessionEvents Session::on_bytes(ByteSpan bytes) {
  SessionEvents ev;
  replies_.clear();
  parser_.push(bytes, replies_);
  const std::uint64_t errors = parser_.counters().rejected();
  ev.parser_errors = errors - errors_seen_;
  errors_seen_ = errors;
  errors_this_connection_ += ev.parser_errors;
  for (const auto& r : replies_) {
    ClientEvent e = client_.on_reply(r);
    if (e.error) ++ev.decode_errors;
    if (e.sensor_status) ev.sensor_status.push_back(*e.sensor_status);
    if (e.refused) {
      ev.refusals.push_back(*e.refused);
      break;  // the client is Failed: nothing after this reply means anything
    }
    ev.send += e.send;
    if (e.scan) ev.scans.push_back(std::move(*e.scan));
  }
  return ev;
}

}  // namespace fieldguard::scip
