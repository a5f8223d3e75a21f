// SCIP 2.0 client protocol state machine (protocols.md §3.4; the start-up sequence of issue 4).
#include "fieldguard/drivers/scip_client.hpp"

#include <utility>

namespace fieldguard::scip {

namespace {

bool is_ok(const Reply& r) { return r.category == StatusCategory::Ok; }

}  // namespace

std::string_view to_string(ClientState s) {
  switch (s) {
    case ClientState::Idle: return "idle";
    case ClientState::SwitchingProtocol: return "switching_protocol";
    case ClientState::ReadingVersion: return "reading_version";
    case ClientState::ReadingParameters: return "reading_parameters";
    case ClientState::ReadingState: return "reading_state";
    case ClientState::LaserOn: return "laser_on";
    case ClientState::StartingScans: return "starting_scans";
    case ClientState::Streaming: return "streaming";
    case ClientState::Stopping: return "stopping";
    case ClientState::Resetting: return "resetting";
    case ClientState::Stopped: return "stopped";
    case ClientState::Failed: return "failed";
  }
  return "unknown";
}

Client::Client(ClientConfig config) : config_(config), scan_line_(encode_scan(scan_command(), config_.scan)) {}

std::string Client::start() {
  state_ = ClientState::SwitchingProtocol;
  failure_.reset();
  return encode_command(Command::Scip20);
}

std::string Client::stop() {
  state_ = ClientState::Stopping;
  return encode_command(Command::QT);
}

std::string Client::reset() {
  state_ = ClientState::Resetting;
  return encode_command(Command::RS);
}

Geometry Client::geometry() const { return parameters_ ? Geometry::from(*parameters_) : Geometry{}; }

ClientEvent Client::refuse(const Reply& reply, std::string_view text) {
  state_ = ClientState::Failed;
  failure_ = Refusal{.command = reply.command, .status = reply.status, .text = text};
  ClientEvent e;
  e.refused = failure_;
  return e;
}

ClientEvent Client::on_scan(const Reply& reply) {
  ClientEvent e;
  switch (reply.category) {
    case StatusCategory::DataFollows: {
      auto scan = decode_scan(reply);
      if (!scan) {
        ++counters_.errors[static_cast<std::size_t>(scan.error())];
        e.error = scan.error();
        return e;
      }
      ++counters_.scans;
      e.scan = std::move(*scan);
      return e;
    }
    case StatusCategory::Stopped:
    case StatusCategory::HardwareTrouble:
      ++counters_.sensor_trouble;
      e.sensor_status = reply.status;
      return e;
    case StatusCategory::Resumed:
      ++counters_.resumed;
      e.sensor_status = reply.status;
      return e;
    default:
      ++counters_.unexpected_replies;  // e.g. a repeated 00 acknowledgement
      return e;
  }
}

ClientEvent Client::on_reply(const Reply& reply) {
  ++counters_.replies;
  const bool our_scans = reply.command == scan_command();
  const auto unexpected = [&] {
    ++counters_.unexpected_replies;
    return ClientEvent{};
  };
  ClientEvent e;
  switch (state_) {
    case ClientState::SwitchingProtocol:
      if (reply.command != Command::Scip20) return unexpected();
      // 00 / "0": switched; 0E: the sensor does not know the command, i.e. it speaks SCIP 2.0 only (assumed).
      if (!is_ok(reply) && reply.category != StatusCategory::Scip11Ok && reply.status != "0E") {
        return refuse(reply, status_text(reply.command, reply.status));
      }
      state_ = ClientState::ReadingVersion;
      e.send = encode_command(Command::VV);
      return e;

    case ClientState::ReadingVersion:
      if (reply.command != Command::VV) return unexpected();
      if (!is_ok(reply)) return refuse(reply, status_text(reply.command, reply.status));
      if (auto info = decode_info(reply)) {
        version_ = std::move(*info);
      } else {
        ++counters_.errors[static_cast<std::size_t>(info.error())];
        e.error = info.error();  // the version is for the log only: go on
      }
      state_ = ClientState::ReadingParameters;
      e.send = encode_command(Command::PP);
      return e;

    case ClientState::ReadingParameters: {
      if (reply.command != Command::PP) return unexpected();
      if (!is_ok(reply)) return refuse(reply, status_text(reply.command, reply.status));
      auto p = decode_parameters(reply);
      if (!p) {
        ++counters_.errors[static_cast<std::size_t>(p.error())];
        // Without DMIN/DMAX/AFRT/ARES ranges cannot be told from error codes: do not stream.
        e = refuse(reply, to_string(p.error()));
        e.error = p.error();
        return e;
      }
      parameters_ = std::move(*p);
      state_ = ClientState::ReadingState;
      e.send = encode_command(Command::II);
      return e;
    }

    case ClientState::ReadingState:
      if (reply.command != Command::II) return unexpected();
      if (!is_ok(reply)) return refuse(reply, status_text(reply.command, reply.status));
      if (auto info = decode_info(reply)) {
        sensor_state_ = std::move(*info);
      } else {
        ++counters_.errors[static_cast<std::size_t>(info.error())];
        e.error = info.error();
      }
      state_ = ClientState::LaserOn;
      e.send = encode_command(Command::BM);
      return e;

    case ClientState::LaserOn:
      if (reply.command != Command::BM) return unexpected();
      if (!is_ok(reply) && reply.status != "02") return refuse(reply, status_text(reply.command, reply.status));
      state_ = ClientState::StartingScans;
      e.send = scan_line_;
      return e;

    case ClientState::StartingScans:
      if (!our_scans) return unexpected();
      if (is_ok(reply)) {
        state_ = ClientState::Streaming;
        return e;
      }
      if (reply.category == StatusCategory::DataFollows) {  // the 00 was lost: the scans are what matters
        state_ = ClientState::Streaming;
        return on_scan(reply);
      }
      return refuse(reply, status_text(reply.command, reply.status));

    case ClientState::Streaming:
      if (!our_scans) return unexpected();
      return on_scan(reply);

    case ClientState::Stopping:
    case ClientState::Resetting: {
      const Command want = state_ == ClientState::Stopping ? Command::QT : Command::RS;
      if (our_scans) return on_scan(reply);  // scans sent before the sensor read QT/RS
      if (reply.command != want) return unexpected();
      if (!is_ok(reply)) return refuse(reply, status_text(reply.command, reply.status));
      state_ = ClientState::Stopped;
      return e;
    }

    case ClientState::Idle:
    case ClientState::Stopped:
    case ClientState::Failed: return unexpected();
  }
  return unexpected();
}

}  // namespace fieldguard::scip
