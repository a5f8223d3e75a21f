#pragma once
// The SCIP 2.0 client's protocol state machine: start-up SCIP2.0 -> VV -> PP -> II -> BM -> MD (or ME), then
// scans until stop() (QT) or reset() (RS). Pure: it consumes parsed replies (scip::ReplyParser) and says what to
// send next, which scan arrived, or that the sensor refused a command and with which status; the live TCP client
// only moves bytes and keeps time. One producer: not thread-safe.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "fieldguard/drivers/scip.hpp"
#include "fieldguard/drivers/scip_data.hpp"

namespace fieldguard::scip {

struct ClientConfig {
  ScanRequest scan{};      // steps, cluster, interval; scans = 0 streams until QT
  bool intensity = false;  // ME (ranges + intensities) instead of MD
};

enum class ClientState : std::uint8_t {
  Idle,               // nothing sent yet (or after a reset completed)
  SwitchingProtocol,  // SCIP2.0 sent
  ReadingVersion,     // VV sent
  ReadingParameters,  // PP sent
  ReadingState,       // II sent
  LaserOn,            // BM sent
  StartingScans,      // MD/ME sent, waiting for its 00
  Streaming,          // scans arrive (status 99)
  Stopping,           // QT sent
  Resetting,          // RS sent
  Stopped,            // QT or RS acknowledged
  Failed,             // the sensor refused a command of the sequence, or PP could not be read
};
[[nodiscard]] std::string_view to_string(ClientState s);

struct Refusal {
  Command command = Command::Unknown;  // the command refused
  std::string status;                  // its status code ("01", "0L", ...), empty for an unreadable PP
  std::string_view text;               // status_text(), or the decode error's name
};

// What the caller does with one reply. At most one of scan / refused is set.
struct ClientEvent {
  std::string send;                          // command line to send next (LF-terminated), empty = nothing
  std::optional<Scan> scan;                  // a decoded scan (Streaming, and scans still arriving while stopping)
  std::optional<Refusal> refused;            // the client is Failed; send nothing more, reconnect or reset
  std::optional<Error> error;                // a scan or info reply whose contents could not be decoded (counted)
  std::optional<std::string> sensor_status;  // a scan reply with 21..49, 50..97 or 98 instead of 99
};

struct ClientCounters {
  std::uint64_t replies = 0;
  std::uint64_t scans = 0;
  std::uint64_t unexpected_replies = 0;  // replies to commands not in flight (stale scans after a reconnect...)
  std::uint64_t sensor_trouble = 0;      // scan replies with status 21..97
  std::uint64_t resumed = 0;             // scan replies with status 98
  std::array<std::uint64_t, kErrorCount> errors{};  // content errors by Error
};

class Client {
 public:
  // Throws std::invalid_argument for a scan request that cannot be encoded.
  explicit Client(ClientConfig config = {});

  // Starts (or restarts, after a reconnect) the sequence: returns the SCIP2.0 command line.
  [[nodiscard]] std::string start();
  // QT: laser off, stop streaming. Scans still in flight are delivered; QT's 00 moves to Stopped.
  [[nodiscard]] std::string stop();
  // RS: reset the sensor's settings (stops streaming, laser off).
  [[nodiscard]] std::string reset();

  ClientEvent on_reply(const Reply& reply);

  [[nodiscard]] ClientState state() const { return state_; }
  [[nodiscard]] const InfoMap& version() const { return version_; }                          // VV
  [[nodiscard]] const std::optional<Parameters>& parameters() const { return parameters_; }  // PP
  [[nodiscard]] const InfoMap& sensor_state() const { return sensor_state_; }                // II
  [[nodiscard]] Geometry geometry() const;  // from PP, or the UTM-30LX-EW's defaults before it
  [[nodiscard]] const ClientCounters& counters() const { return counters_; }
  [[nodiscard]] const std::optional<Refusal>& failure() const { return failure_; }

 private:
  [[nodiscard]] Command scan_command() const { return config_.intensity ? Command::ME : Command::MD; }
  ClientEvent refuse(const Reply& reply, std::string_view text);
  ClientEvent on_scan(const Reply& reply);

  ClientConfig config_;
  std::string scan_line_;
  ClientState state_ = ClientState::Idle;
  InfoMap version_;
  std::optional<Parameters> parameters_;
  InfoMap sensor_state_;
  ClientCounters counters_;
  std::optional<Refusal> failure_;
};

}  // namespace fieldguard::scip
