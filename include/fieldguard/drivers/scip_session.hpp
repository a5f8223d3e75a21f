#pragma once
// One SCIP 2.0 conversation as the client sees it: the reply parser and the client state machine, reset at
// every new connection. Pure: the live source (io::ScipSource) and replay of a recorded byte log both run
// the same Session, so they decode the same bytes to the same scans. Not thread-safe.

#include <cstdint>
#include <string>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/drivers/scip.hpp"
#include "fieldguard/drivers/scip_client.hpp"
#include "fieldguard/drivers/scip_data.hpp"

namespace fieldguard::scip {

struct SessionEvents {
  std::string send;  // command lines to send now (concatenated), empty = nothing
  std::vector<Scan> scans;
  std::vector<Refusal> refusals;  // the sensor refused a command: the caller drops the connection
  std::vector<std::string> sensor_status;
  std::uint64_t decode_errors = 0;
  std::uint64_t parser_errors = 0;  // new framing errors in these bytes
};

class Session {
 public:
  explicit Session(ClientConfig config = {}) : config_(config), client_(config) {}

  // A new connection: forget the old one. Returns the first command to send.
  [[nodiscard]] std::string connect();
  // Bytes from the sensor.
  [[nodiscard]] SessionEvents on_bytes(ByteSpan bytes);

  [[nodiscard]] const Client& client() const { return client_; }
  [[nodiscard]] std::uint64_t parser_errors_this_connection() const { return errors_this_connection_; }
  [[nodiscard]] const ParserCounters& parser_counters() const { return parser_.counters(); }

 private:
  ClientConfig config_;
  Client client_;
  ReplyParser parser_;
  std::vector<Reply> replies_;
  std::uint64_t errors_seen_ = 0;
  std::uint64_t errors_this_connection_ = 0;
};

}  // namespace fieldguard::scip
