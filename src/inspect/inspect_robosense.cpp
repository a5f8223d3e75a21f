// `fieldguard inspect --format robosense`: a pcap/pcapng of an RS-LiDAR-32. One record per MSOP packet the
// decoder could decode (it needs a DIFOP with the angle table first: earlier MSOP packets are rejected as
// msop_no_calibration) and one per DIFOP packet.

#include <array>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "fieldguard/drivers/robosense_stream.hpp"
#include "inspect/inspect_format.hpp"
#include "inspect/json_line.hpp"

namespace fieldguard::app::inspect {
namespace {

namespace rs = robosense;

// "2024-03-21T08:30:15.123456Z": UTC, microseconds (what the RS-32 header carries).
std::string utc_iso8601(Stamp t) {
  std::int64_t s = t.ns / 1'000'000'000;
  std::int64_t ns = t.ns % 1'000'000'000;
  if (ns < 0) {
    ns += 1'000'000'000;
    --s;
  }
  const auto secs = static_cast<std::time_t>(s);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  std::array<char, 48> buf{};
  std::snprintf(buf.data(), buf.size(), "%04d-%02d-%02dT%02d:%02d:%02d.%06lldZ", tm.tm_year + 1900, tm.tm_mon + 1,
                tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<long long>(ns / 1000));
  return buf.data();
}

std::string msop_record(double time_s, std::uint16_t port, const rs::MsopHeader& h, std::uint64_t points) {
  JsonLine j;
  j.field("type", "robosense_msop").field("time", time_s).field("port", port);
  j.field("timestamp_utc", utc_iso8601(h.sensor_time));
  j.field("temperature_c", static_cast<double>(h.temperature_c));
  j.field("first_azimuth_deg", h.azimuth_cdeg.front() / 100.0);
  j.field("last_azimuth_deg", h.azimuth_cdeg.back() / 100.0);
  j.boolean("dual_layout", h.dual_layout);
  j.field("points", points);
  return std::move(j).str();
}

std::string difop_record(double time_s, std::uint16_t port, const rs::DifopInfo& d) {
  JsonLine j;
  j.field("type", "robosense_difop").field("time", time_s).field("port", port);
  j.field("rpm", d.rpm);
  j.field("firmware_top", hex_upper(d.top_firmware)).field("firmware_bottom", hex_upper(d.bottom_firmware));
  j.field("serial", hex_upper(d.serial));
  j.field("return_mode", rs::to_string(d.return_mode)).field("return_mode_byte", d.return_mode_byte);
  j.field("distance_unit", rs::to_string(d.distance_unit));
  j.field("fov_start_deg", d.fov_start_cdeg / 100.0).field("fov_end_deg", d.fov_end_cdeg / 100.0);
  if (d.utc_time) {
    j.field("timestamp_utc", utc_iso8601(*d.utc_time));
  } else {
    j.null("timestamp_utc");
  }
  j.boolean("angle_table", d.calibration.has_value());
  return std::move(j).str();
}

}  // namespace

void inspect_robosense(Capture& in, Output& out, Summary& summary) {
  auto reader = open_pcap(in, summary);
  if (!reader) return;
  const std::uint16_t msop_port = in.ports.data.value_or(rs::kDefaultMsopPort);
  const std::uint16_t difop_port = in.ports.position.value_or(rs::kDefaultDifopPort);

  rs::Stream stream;
  summary.kinds["robosense_msop"] = 0;
  summary.kinds["robosense_difop"] = 0;
  std::vector<LidarFrame> frames;
  std::uint64_t other_port = 0;
  while (const auto d = reader->next()) {
    const double time_s = seconds_of(d->host_time);
    if (d->dst_port == msop_port) {
      const auto before = stream.counters();
      stream.push_msop(d->payload, d->host_time, frames);
      for (auto& f : frames) stream.recycle(std::move(f));
      frames.clear();
      const auto& after = stream.counters();
      if (after.msop_decoded == before.msop_decoded) continue;  // rejected, counted by reason
      const auto header = rs::read_msop_header(d->payload);     // valid: the decoder read it
      ++summary.kinds["robosense_msop"];
      out.line(msop_record(time_s, d->dst_port, *header, after.points - before.points));
    } else if (d->dst_port == difop_port) {
      const auto accepted = stream.counters().difop_accepted;
      stream.push_difop(d->payload);
      if (stream.counters().difop_accepted == accepted) continue;
      ++summary.kinds["robosense_difop"];
      out.line(difop_record(time_s, d->dst_port, *stream.last_difop()));
    } else {
      ++other_port;
    }
  }
  stream.finish(frames);

  const auto& c = stream.counters();
  summary.rejections = pcap_drops(reader->stats());
  summary.rejections.emplace_back("other_port", other_port);
  for (std::size_t i = 0; i < rs::kDecodeErrorCount; ++i) {
    summary.rejections.emplace_back("msop_" + std::string(rs::to_string(static_cast<rs::DecodeError>(i))),
                                    c.msop_errors[i]);
  }
  for (std::size_t i = 0; i < rs::kDecodeErrorCount; ++i) {
    summary.rejections.emplace_back("difop_" + std::string(rs::to_string(static_cast<rs::DecodeError>(i))),
                                    c.difop_errors[i]);
  }
  add_pcap_stats(reader->stats(), summary);
  summary.extra.emplace_back("msop_packets", c.msop_packets);
  summary.extra.emplace_back("difop_packets", c.difop_packets);
  summary.extra.emplace_back("difop_without_angles", c.difop_without_angles);
  summary.extra.emplace_back("difop_angle_changes", c.difop_angle_changes);
  summary.extra.emplace_back("points", c.points);
  summary.extra.emplace_back("rotations_full", c.full_rotations);
  summary.extra.emplace_back("rotations_partial", c.partial_rotations);
  const auto& dec = stream.decoder();
  if (dec.ready()) {
    summary.notes.emplace_back(
        "calibration", "angle table from DIFOP, distance unit " + std::string(rs::to_string(*dec.distance_unit())));
  } else {
    summary.notes.emplace_back(
        "calibration", c.difop_accepted == 0 ? "none: no valid DIFOP packet, MSOP packets cannot be decoded"
                                             : "none: no DIFOP with an angle table, MSOP packets cannot be decoded");
  }
  summary.notes.emplace_back("ports", "MSOP " + std::to_string(msop_port) + ", DIFOP " + std::to_string(difop_port));
}

}  // namespace fieldguard::app::inspect
