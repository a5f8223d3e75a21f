// `fieldguard inspect --format xsens`: a raw Xsens Xbus byte stream (MTData2 measurements and any other messages).

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>
#include <variant>

#include "fieldguard/drivers/xsens_stream.hpp"
#include "inspect/inspect_byte_log.hpp"
#include "inspect/inspect_format.hpp"
#include "inspect/json_line.hpp"

namespace fieldguard::app::inspect {
namespace {

namespace xs = xsens;

std::array<double, 3> values(const xs::Vec3& v) { return {v.x, v.y, v.z}; }
std::array<double, 4> values(const xs::Quat& q) { return {q.w, q.x, q.y, q.z}; }

template <typename T>
void put(JsonLine& j, std::string_view key, const std::optional<T>& v) {
  if (v) {
    const auto a = values(*v);
    j.array(key, a);
  }
}

// RFC 3339 with the nanoseconds, trailing zeros dropped ("2019-01-20T13:47:24.1219Z", "...:29Z").
std::string utc_string(const xs::UtcTime& t) {
  std::array<char, 48> buf{};
  std::snprintf(buf.data(), buf.size(), "%04u-%02u-%02uT%02u:%02u:%02u", unsigned{t.year}, unsigned{t.month},
                unsigned{t.day}, unsigned{t.hour}, unsigned{t.minute}, unsigned{t.second});
  std::string s = buf.data();
  if (t.ns != 0) {
    std::snprintf(buf.data(), buf.size(), ".%09u", static_cast<unsigned>(t.ns));
    std::string frac = buf.data();
    while (frac.back() == '0') frac.pop_back();
    s += frac;
  }
  return s + "Z";
}

JsonLine pvt_json(const xs::GnssPvt& p) {
  JsonLine j;
  j.field("itow_ms", p.itow_ms).field("year", p.year).field("month", p.month).field("day", p.day);
  j.field("hour", p.hour).field("min", p.min).field("sec", p.sec).field("valid", p.valid);
  j.field("t_acc_ns", p.t_acc_ns).field("nano_ns", p.nano_ns).field("fix_type", p.fix_type);
  j.field("flags", p.flags).field("num_sv", p.num_sv).field("reserved1", p.reserved1);
  j.field("lon_1e7deg", p.lon_1e7deg).field("lat_1e7deg", p.lat_1e7deg);
  j.field("height_mm", p.height_mm).field("hmsl_mm", p.hmsl_mm);
  j.field("h_acc_mm", p.h_acc_mm).field("v_acc_mm", p.v_acc_mm);
  j.field("vel_n_mmps", p.vel_n_mmps).field("vel_e_mmps", p.vel_e_mmps).field("vel_d_mmps", p.vel_d_mmps);
  j.field("gspeed_mmps", p.gspeed_mmps).field("head_mot_1e5deg", p.head_mot_1e5deg);
  j.field("s_acc_mmps", p.s_acc_mmps).field("head_acc_1e5deg", p.head_acc_1e5deg);
  j.field("head_veh_1e5deg", p.head_veh_1e5deg);
  j.field("gdop", p.gdop).field("pdop", p.pdop).field("tdop", p.tdop).field("vdop", p.vdop);
  j.field("hdop", p.hdop).field("ndop", p.ndop).field("edop", p.edop);
  return j;
}

JsonLine sat_info_json(const xs::GnssSatInfo& s) {
  JsonLine j;
  j.field("itow_ms", s.itow_ms).field("num_svs", s.num_svs);
  JsonLine::Json sats = JsonLine::Json::array();
  for (const auto& sv : s.satellites)
    sats.push_back(JsonLine::Json::array({sv.gnss_id, sv.sv_id, sv.cno_dbhz, sv.flags}));
  j.value("satellites", std::move(sats));  // [gnss_id, sv_id, cno_dbhz, flags] each
  return j;
}

std::string record(const xs::MtData2& d) {
  JsonLine j;
  j.field("type", "MTData2");
  j.field("packet_counter", d.packet_counter).field("sample_time_fine", d.sample_time_fine);
  if (d.sample_time_coarse) j.field("sample_time_coarse", *d.sample_time_coarse);
  if (d.utc_time) j.field("utc_time", utc_string(*d.utc_time)).field("utc_flags", d.utc_time->flags);
  if (d.status_word) j.field("status_word", *d.status_word);
  if (d.status_byte) j.field("status_byte", *d.status_byte);
  if (d.euler_deg) {
    put(j, "euler_deg", d.euler_deg);
    j.field("euler_frame", xs::to_string(d.euler_frame));
  }
  if (d.quaternion) {
    put(j, "quat", d.quaternion);
    j.field("quat_frame", xs::to_string(d.quaternion_frame));
  }
  if (d.rotation_matrix) {
    j.array("rotation_matrix", *d.rotation_matrix);
    j.field("rotation_matrix_frame", xs::to_string(d.rotation_matrix_frame));
  }
  put(j, "acc", d.acceleration);
  put(j, "free_acc", d.free_acceleration);
  put(j, "acc_hr", d.acceleration_hr);
  put(j, "delta_v", d.delta_v);
  put(j, "gyr", d.rate_of_turn);
  put(j, "gyr_hr", d.rate_of_turn_hr);
  put(j, "delta_q", d.delta_q);
  put(j, "mag", d.magnetic_field);
  if (d.temperature_c) j.field("temperature_c", *d.temperature_c);
  if (d.baro_pressure_pa) j.field("baro_pa", *d.baro_pressure_pa);
  if (d.lat_deg) j.field("lat_deg", *d.lat_deg).field("lon_deg", d.lon_deg);
  if (d.altitude_msl_m) j.field("alt_msl_m", *d.altitude_msl_m);
  if (d.altitude_ellipsoid_m) j.field("alt_ellipsoid_m", *d.altitude_ellipsoid_m);
  put(j, "position_ecef_m", d.position_ecef_m);
  if (d.velocity_mps) {
    put(j, "vel_mps", d.velocity_mps);
    j.field("vel_frame", xs::to_string(d.velocity_frame));
  }
  if (d.gnss_pvt) j.object("gnss_pvt", pvt_json(*d.gnss_pvt));
  if (d.gnss_sat_info) j.object("gnss_sat_info", sat_info_json(*d.gnss_sat_info));
  if (!d.unknown_ids.empty()) j.value("unknown_data_ids", d.unknown_ids);
  return std::move(j).str();
}

std::string message_kind(std::uint8_t mid) {
  const auto name = xs::message_name(mid);
  if (!name.empty()) return std::string(name);
  std::array<char, 16> buf{};
  std::snprintf(buf.data(), buf.size(), "mid_0x%02X", unsigned{mid});
  return buf.data();
}

std::string record(const xs::RawMessage& m) {
  JsonLine j;
  j.field("type", message_kind(m.mid)).field("mid", m.mid).field("payload_hex", hex_upper(m.payload));
  return std::move(j).str();
}

}  // namespace

bool looks_like_xsens(ByteSpan head) {
  if (starts_with_byte_log(head)) {
    // What `fieldguard record` saves of the serial line; the source line names it ("ahrs /dev/ttyUSB0 ...").
    const std::string source = byte_log_source(head);
    return source.find("ahrs") != std::string::npos || source.find("xsens") != std::string::npos ||
           source.find("mti") != std::string::npos;
  }
  // A complete, valid Xbus frame anywhere in the first bytes, or an MTData2 header.
  for (std::size_t i = 0; i + 2 < head.size(); ++i) {
    if (head[i] != xs::kPreamble || head[i + 1] != xs::kBusMaster) continue;
    if (head[i + 2] == xs::mid::kMtData2 || xs::decode_frame(head.subspan(i))) return true;
  }
  return false;
}

void inspect_xsens(Capture& in, Output& out, Summary& summary) {
  xs::StreamParser parser;
  std::vector<xs::StreamItem> items;
  const auto take = [&] {
    for (const auto& item : items) {
      if (const auto* d = std::get_if<xs::MtData2>(&item)) {
        ++summary.kinds["MTData2"];
        out.line(record(*d));
      } else {
        const auto& m = std::get<xs::RawMessage>(item);
        ++summary.kinds[message_kind(m.mid)];
        out.line(record(m));
      }
    }
    items.clear();
  };
  // A byte log of the serial line (`fieldguard record`), or the raw bytes.
  SensorBytes bytes_in([&](ByteSpan bytes, std::optional<Stamp>) {
    parser.push(bytes, items);
    take();
  });
  bytes_in.read(in);
  parser.finish(items);
  take();
  const auto& c = parser.counters();
  summary.rejections = {{"bad_checksum", c.bad_checksum},
                        {"too_long", c.too_long},
                        {"truncated_packet", c.truncated_packet},
                        {"bad_packet_size", c.bad_packet_size},
                        {"truncated_frame", c.truncated_frame}};
  summary.extra = {{"unknown_data_ids", c.unknown_data_ids}, {"garbage_bytes", c.garbage_bytes}};
  bytes_in.finish(summary);
}

}  // namespace fieldguard::app::inspect
