// `fieldguard inspect --format scip`: a Hokuyo SCIP 2.0 session, as a fieldguard byte log (io/byte_log.hpp: what
// `fieldguard record` saves of the TCP link, with host times) or as the raw text of the sensor's replies.
// The bytes from the sensor go through scip::ReplyParser; each reply is decoded: a scan, VV/PP/II information, or
// a status other than 00 / 99. Acknowledgements (status 00 of BM, QT, MD, ...) are counted, not printed.

#include <algorithm>
#include <array>
#include <cctype>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/drivers/scip.hpp"
#include "fieldguard/drivers/scip_data.hpp"
#include "inspect/inspect_byte_log.hpp"
#include "inspect/inspect_format.hpp"
#include "inspect/json_line.hpp"

namespace fieldguard::app::inspect {
namespace {

bool is_single_scan(scip::Command c) {
  using C = scip::Command;
  return c == C::GD || c == C::GE || c == C::GS;
}
bool is_info_command(scip::Command c) {
  using C = scip::Command;
  return c == C::VV || c == C::PP || c == C::II;
}

// Replies in, records out.
class Decoder {
 public:
  Decoder(Output& out, Summary& summary) : out_(out), summary_(summary) {
    for (const char* k : {"scip_scan", "scip_info", "scip_status"}) summary_.kinds[k] = 0;
  }

  void push(ByteSpan bytes, std::optional<double> time_s) {
    from_sensor_bytes_ += bytes.size();
    parser_.push(bytes, replies_);
    for (const auto& r : replies_) on_reply(r, time_s);
    replies_.clear();
  }

  void summarise() {
    const auto& pc = parser_.counters();
    for (std::size_t i = 0; i < scip::kErrorCount; ++i) {
      summary_.rejections.emplace_back(std::string(scip::to_string(static_cast<scip::Error>(i))),
                                       pc.errors[i] + content_errors_[i]);
    }
    summary_.extra.emplace_back("replies", pc.replies);
    summary_.extra.emplace_back("acks", acks_);
    summary_.extra.emplace_back("from_sensor_bytes", from_sensor_bytes_);
    summary_.extra.emplace_back("discarded_bytes", pc.discarded_bytes);
  }

 private:
  void reject(scip::Error e) { ++content_errors_[static_cast<std::size_t>(e)]; }
  void print(std::string record, const char* kind) {
    ++summary_.kinds[kind];
    out_.line(std::move(record));
  }

  void on_reply(const scip::Reply& r, std::optional<double> time_s) {
    using Cat = scip::StatusCategory;
    if (r.category == Cat::DataFollows || (is_single_scan(r.command) && r.category == Cat::Ok)) {
      on_scan(r, time_s);
    } else if (is_info_command(r.command) && r.category == Cat::Ok) {
      on_info(r, time_s);
    } else if (r.category == Cat::Ok || r.category == Cat::Scip11Ok) {
      ++acks_;
    } else {
      JsonLine j;
      j.field("type", "scip_status").field("time", time_s).field("command", scip::to_string(r.command));
      j.field("echo", r.echo).field("status", r.status).field("category", scip::to_string(r.category));
      j.field("text", scip::status_text(r.command, r.status));
      print(std::move(j).str(), "scip_status");
    }
  }

  void on_scan(const scip::Reply& r, std::optional<double> time_s) {
    const auto scan = scip::decode_scan(r);
    if (!scan) {
      reject(scan.error());
      return;
    }
    std::size_t valid = 0;
    std::optional<std::uint32_t> lo;
    std::optional<std::uint32_t> hi;
    for (const std::uint32_t mm : scan->ranges_mm) {
      if (mm < params_.dmin_mm || mm > params_.dmax_mm) continue;  // an error code, not a distance
      ++valid;
      lo = std::min(lo.value_or(mm), mm);
      hi = std::max(hi.value_or(mm), mm);
    }
    JsonLine j;
    j.field("type", "scip_scan").field("time", time_s).field("command", scip::to_string(scan->command));
    j.field("timestamp_ms", scan->timestamp_ms).field("first_step", scan->first_step);
    j.field("last_step", scan->last_step).field("cluster", scan->cluster);
    j.field("remaining_scans", scan->remaining_scans).field("values", scan->ranges_mm.size());
    j.field("valid", valid).field("min_range_mm", lo).field("max_range_mm", hi);
    j.boolean("intensities", !scan->intensities.empty());
    print(std::move(j).str(), "scip_scan");
  }

  void on_info(const scip::Reply& r, std::optional<double> time_s) {
    const auto info = scip::decode_info(r);
    if (!info) {
      reject(info.error());
      return;
    }
    if (r.command == scip::Command::PP) {
      // Later scans are judged by this sensor's DMIN..DMAX. A PP that does not add up is printed, not used.
      if (const auto p = scip::decode_parameters(r)) params_ = *p;
    }
    JsonLine j;
    j.field("type", "scip_info").field("time", time_s).field("command", scip::to_string(r.command));
    for (const auto& [label, value] : *info) {
      if (label == "type" || label == "time" || label == "command") continue;  // never a sensor's label
      j.field(label, value);
    }
    print(std::move(j).str(), "scip_info");
  }

  Output& out_;
  Summary& summary_;
  scip::ReplyParser parser_;
  std::vector<scip::Reply> replies_;
  scip::Parameters params_;  // the UTM-30LX-EW's until a PP says otherwise
  std::array<std::uint64_t, scip::kErrorCount> content_errors_{};
  std::uint64_t acks_ = 0;
  std::uint64_t from_sensor_bytes_ = 0;
};

}  // namespace

bool looks_like_scip(ByteSpan head) {
  if (starts_with_byte_log(head)) {
    // The source line names the sensor: "scip 192.168.0.10:10940", "scan2d ...".
    const std::string source = byte_log_source(head);
    return source.find("scip") != std::string::npos || source.find("scan2d") != std::string::npos ||
           source.find("hokuyo") != std::string::npos;
  }
  // Raw text that starts with a reply's echo line ("SCIP2.0", "VV", "MD0000108001000", ...).
  std::size_t start = 0;
  while (start < head.size() && (head[start] == '\n' || head[start] == '\r')) ++start;
  const auto end = std::find(head.begin() + static_cast<std::ptrdiff_t>(start), head.end(), std::uint8_t{'\n'});
  if (end == head.end()) return false;
  const std::string line(head.begin() + static_cast<std::ptrdiff_t>(start), end);
  return scip::command_of_echo(line) != scip::Command::Unknown;
}

void inspect_scip(Capture& in, Output& out, Summary& summary) {
  Decoder decoder(out, summary);
  SensorBytes bytes_in([&](ByteSpan bytes, std::optional<Stamp> host_time) {
    decoder.push(bytes, host_time ? std::optional<double>(seconds_of(*host_time)) : std::nullopt);
  });
  bytes_in.read(in);
  decoder.summarise();
  bytes_in.finish(summary);
  if (!bytes_in.byte_log()) summary.notes.emplace_back("source", "raw text of the sensor's replies (no host times)");
}

}  // namespace fieldguard::app::inspect
