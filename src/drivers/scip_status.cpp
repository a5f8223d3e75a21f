// SCIP 2.0 status codes: categories and text (protocols.md §3.4; SCIP 2.0 spec C-42-03320B; hokuyolx
// statuses.py for the generic codes, which are [single-source]).
#include "fieldguard/drivers/scip.hpp"

namespace fieldguard::scip {

namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }

bool is_scan(Command c) {
  return c == Command::MD || c == Command::ME || c == Command::MS || c == Command::GD || c == Command::GE ||
         c == Command::GS;
}

std::string_view parameter_error_text(Command c, int n) {
  if (c == Command::BM) {
    if (n == 1) return "laser could not be lit (unstable or abnormal condition)";
    if (n == 2) return "laser already on";
  }
  if (is_scan(c)) {
    switch (n) {
      case 1: return "start step is not a number";
      case 2: return "end step is not a number";
      case 3: return "cluster count is not a number";
      case 4: return "end step out of range";
      case 5: return "end step smaller than start step";
      case 6: return "scan interval is not a number";
      case 7: return "number of scans is not a number";
      default: break;
    }
  }
  if (c == Command::TM) {
    switch (n) {
      case 1: return "invalid time-sync control code";
      case 2: return "already in time-sync mode";
      case 3: return "already out of time-sync mode";
      case 4: return "not in time-sync mode";
      default: break;
    }
  }
  if (c == Command::RB && n == 1) return "reboot requested: send RB again to confirm";
  return "parameter error";
}

}  // namespace

std::string_view to_string(StatusCategory c) {
  switch (c) {
    case StatusCategory::Ok: return "ok";
    case StatusCategory::DataFollows: return "data_follows";
    case StatusCategory::ParameterError: return "parameter_error";
    case StatusCategory::CommandRejected: return "command_rejected";
    case StatusCategory::Stopped: return "stopped";
    case StatusCategory::HardwareTrouble: return "hardware_trouble";
    case StatusCategory::Resumed: return "resumed";
    case StatusCategory::Scip11Ok: return "scip11_ok";
  }
  return "unknown";
}

std::optional<StatusCategory> classify_status(std::string_view code) {
  if (code == "0") return StatusCategory::Scip11Ok;
  if (code.size() != 2) return std::nullopt;
  if (is_digit(code[0]) && is_digit(code[1])) {
    const int n = (code[0] - '0') * 10 + (code[1] - '0');
    if (n == 0) return StatusCategory::Ok;
    if (n <= 9) return StatusCategory::ParameterError;
    if (n == 10) return StatusCategory::CommandRejected;
    if (n >= 21 && n <= 49) return StatusCategory::Stopped;
    if (n >= 50 && n <= 97) return StatusCategory::HardwareTrouble;
    if (n == 98) return StatusCategory::Resumed;
    if (n == 99) return StatusCategory::DataFollows;
    return std::nullopt;
  }
  if (code[0] == '0') {
    switch (code[1]) {
      case 'D':
      case 'E':
      case 'F':
      case 'G':
      case 'H':
      case 'L':
      case 'M': return StatusCategory::CommandRejected;
      default: break;
    }
  }
  return std::nullopt;
}

std::string_view status_text(Command c, std::string_view code) {
  const auto cat = classify_status(code);
  if (!cat) return "unknown status";
  switch (*cat) {
    case StatusCategory::Ok: return "ok";
    case StatusCategory::Scip11Ok: return "ok (SCIP 1.1 reply)";
    case StatusCategory::DataFollows: return "scan data follows";
    case StatusCategory::Resumed: return "resumed after the laser was found working again";
    case StatusCategory::Stopped: return "processing stopped to verify an error";
    case StatusCategory::HardwareTrouble: return "hardware trouble (laser, motor, ...)";
    case StatusCategory::ParameterError: return parameter_error_text(c, code[1] - '0');
    case StatusCategory::CommandRejected: break;
  }
  if (code == "10") return "denied";
  switch (code[1]) {
    case 'D': return "command too long";
    case 'E': return "command not defined";
    case 'F': return "command not supported";
    case 'G': return "tag too long";
    case 'H': return "command too short";
    case 'L': return "sensor in an abnormal state";
    case 'M': return "sensor unstable";
    default: break;
  }
  return "command rejected";
}

}  // namespace fieldguard::scip
