// `fieldguard inspect FILE [--format F]`: the field engineer's "what is in this capture?". Every decoded sample
// as one JSON line on stdout; a summary (counts by kind and by rejection reason) on stderr.
// The formats themselves live in inspect_<format>.cpp; see inspect_format.hpp for how to add one.

#include <sys/types.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdio>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "app/args.hpp"
#include "app/commands.hpp"
#include "app/inspect_format.hpp"

namespace fieldguard::app {
namespace {

using inspect::Capture;
using inspect::Output;
using inspect::Summary;

constexpr const char* kHelp =
    "usage: fieldguard inspect FILE [--format nmea|xsens|velodyne|robosense|scip|candump]\n"
    "                               [--data-port P] [--position-port P]\n"
    "\n"
    "Decodes a capture and prints every decoded sample as one JSON line on stdout, then a summary on stderr:\n"
    "records by kind, rejected input by reason, and the bytes that were noise. Rejected input gives no record.\n"
    "The format is guessed from the first bytes when --format is left out (a pcap by the UDP ports or sizes of\n"
    "its first datagrams: robosense for 6699/7788, velodyne otherwise).\n"
    "\n"
    "  nmea    NMEA 0183 text (GGA, RMC, VTG, HDT, THS from any talker; '#' comment lines are skipped).\n"
    "          Keys: type (talker + sentence, \"GNGGA\"); GGA: time_utc lat_deg lon_deg alt_m (above mean sea\n"
    "          level) quality sats hdop geoid_sep_m alt_hae_m dgps_age_s dgps_station; RMC: time_utc status\n"
    "          lat_deg lon_deg speed_mps course_deg date mag_var_deg mode; VTG: course_true_deg course_mag_deg\n"
    "          speed_mps mode; HDT: heading_deg; THS: heading_deg mode. South and west are negative; null where\n"
    "          the sentence's field is empty.\n"
    "  xsens   raw Xsens Xbus stream (MTData2). Keys: type \"MTData2\", packet_counter, sample_time_fine (10 kHz\n"
    "          ticks), and when present utc_time, status_word, status_byte, euler_deg [roll, pitch, yaw],\n"
    "          quat [w, x, y, z], rotation_matrix, acc, free_acc, delta_v, gyr (rad/s), delta_q, mag,\n"
    "          temperature_c, baro_pa, lat_deg, lon_deg, alt_ellipsoid_m, vel_mps, gnss_pvt, ... Other messages:\n"
    "          type (message name), mid, payload_hex.\n"
    "  velodyne\n"
    "          pcap/pcapng of an HDL-32E or VLP-16 (data on UDP 2368, position on 8308; --data-port,\n"
    "          --position-port). \"velodyne_data\": time (pcap, s) port timestamp_us (past the hour) return_mode\n"
    "          product_byte first_azimuth_deg last_azimuth_deg points (returns decoded with the detected model).\n"
    "          \"velodyne_position\": time port timestamp_us pps nmea nmea_error lat_deg lon_deg. The summary\n"
    "          says the model and why, and the rotations.\n"
    "  robosense\n"
    "          pcap/pcapng of an RS-LiDAR-32 (MSOP on 6699, DIFOP on 7788; --data-port, --position-port).\n"
    "          \"robosense_msop\": time port timestamp_utc temperature_c first_azimuth_deg last_azimuth_deg\n"
    "          dual_layout points; MSOP packets before a DIFOP with the angle table are rejected\n"
    "          (msop_no_calibration). \"robosense_difop\": time port rpm firmware_top firmware_bottom serial\n"
    "          return_mode return_mode_byte distance_unit fov_start_deg fov_end_deg timestamp_utc angle_table.\n"
    "  scip    a fieldguard byte log (FGBYTELOG1) of a SCIP 2.0 session, or the sensor's replies as raw text.\n"
    "          \"scip_scan\": time (host, s; null for raw text) command timestamp_ms first_step last_step cluster\n"
    "          remaining_scans values valid min_range_mm max_range_mm (over the valid ranges: DMIN..DMAX of PP,\n"
    "          null when none) intensities. \"scip_info\" (VV, PP, II): time command and the reply's LABEL keys.\n"
    "          \"scip_status\" (a status other than 00/99): time command echo status category text.\n"
    "  candump\n"
    "          candump -L / -l log lines \"(1621880457.123456) can0 18FEF100#00FF0000FFFFFFFF\" (or candump's\n"
    "          default \"can0  18FEF100   [8]  00 FF ...\" output). \"can\": time iface id extended dlc data, for\n"
    "          29-bit ids the J1939 fields priority pgn sa (and da below PF 240), rtr / fd fd_flags / len8_dlc /\n"
    "          dir when they apply. \"can_error\": an error frame (time iface id error_class dlc data).\n"
    "\n"
    "Exit code 0 when the file was read (even with rejections), 2 when it is unusable (missing, empty, a format\n"
    "that cannot be told, a pcap or byte log whose header is broken).\n";

using InspectFn = void (*)(Capture&, Output&, Summary&);
using GuessFn = bool (*)(ByteSpan);

struct Format {
  const char* name;
  InspectFn run;
  GuessFn guess;  // nullptr: only with --format
};

// Guesses are tried in this order. A pcap whose first datagrams are not RoboSense's is reported as velodyne.
const std::array<Format, 6> kFormats = {{
    {"robosense", inspect::inspect_robosense, inspect::looks_like_robosense},
    {"velodyne", inspect::inspect_velodyne, inspect::looks_like_pcap},
    {"scip", inspect::inspect_scip, inspect::looks_like_scip},
    {"nmea", inspect::inspect_nmea, inspect::looks_like_nmea},
    {"candump", inspect::inspect_candump, inspect::looks_like_candump},
    {"xsens", inspect::inspect_xsens, inspect::looks_like_xsens},
}};

// A UDP port option: 1..65535. nullopt (with `error` set) for anything else.
std::optional<std::uint16_t> port_option(const Args& args, const std::string& name, std::string& error) {
  const auto v = args.get(name);
  if (!v) return std::nullopt;
  unsigned port = 0;
  const auto r = std::from_chars(v->data(), v->data() + v->size(), port);
  if (r.ec != std::errc{} || r.ptr != v->data() + v->size() || port == 0 || port > 65535) {
    error = "--" + name + " wants a UDP port number 1..65535, not '" + *v + "'";
    return std::nullopt;
  }
  return static_cast<std::uint16_t>(port);
}

const Format* find_format(const std::string& name) {
  for (const auto& f : kFormats) {
    if (name == f.name) return &f;
  }
  return nullptr;
}

std::string format_names() {
  std::string names;
  for (const auto& f : kFormats) names += std::string(names.empty() ? "" : "|") + f.name;
  return names;
}

void print_summary(const std::string& path, const Format& format, bool guessed, std::uint64_t bytes,
                   std::uint64_t records, const Summary& s) {
  const auto row = [](const std::string& label, std::uint64_t n) {
    std::fprintf(stderr, "  %-18s %llu\n", label.c_str(), static_cast<unsigned long long>(n));
  };
  std::fprintf(stderr, "inspect summary: %s\n", path.c_str());
  std::fprintf(stderr, "  %-18s %s%s\n", "format", format.name, guessed ? " (guessed)" : "");
  row("bytes", bytes);
  row("records", records);
  for (const auto& [kind, n] : s.kinds) row(kind, n);
  std::uint64_t rejected = 0;
  for (const auto& r : s.rejections) rejected += r.second;
  row("rejected", rejected);
  for (const auto& [reason, n] : s.rejections) row(reason, n);
  for (const auto& [label, n] : s.extra) row(label, n);
  for (const auto& [label, text] : s.notes) std::fprintf(stderr, "  %-18s %s\n", label.c_str(), text.c_str());
}

// fopencookie read function over a Capture.
ssize_t read_capture(void* cookie, char* buf, std::size_t size) {
  auto* capture = static_cast<inspect::Capture*>(cookie);
  const std::size_t n = capture->read(std::span<std::uint8_t>(reinterpret_cast<std::uint8_t*>(buf), size));  // NOLINT
  if (n == 0 && capture->read_error()) return -1;
  return static_cast<ssize_t>(n);
}
int close_capture(void* /*cookie*/) { return 0; }  // the file belongs to cmd_inspect

}  // namespace

bool inspect::Capture::for_each_chunk(const std::function<void(ByteSpan)>& chunk) {
  std::vector<std::uint8_t> buf(1 << 16);
  while (true) {
    const std::size_t n = read(buf);
    if (n == 0) return !read_error_;
    chunk(ByteSpan(buf.data(), n));
  }
}

std::size_t inspect::Capture::read(std::span<std::uint8_t> buf) {
  if (head_pos_ < head_.size()) {
    const std::size_t n = std::min(buf.size(), head_.size() - head_pos_);
    std::copy_n(head_.begin() + static_cast<std::ptrdiff_t>(head_pos_), n, buf.begin());
    head_pos_ += n;
    bytes_ += n;
    return n;
  }
  if (read_error_ || buf.empty()) return 0;
  const std::size_t n = std::fread(buf.data(), 1, buf.size(), f_);
  bytes_ += n;
  if (n == 0) read_error_ = std::ferror(f_) != 0;
  return n;
}

std::FILE* inspect::Capture::open_stream() {
  const cookie_io_functions_t io{read_capture, nullptr, nullptr, close_capture};
  return fopencookie(this, "rb", io);
}

int cmd_inspect(const std::vector<std::string>& argv) {
  const Args args(argv, {"format", "data-port", "position-port"}, {"help"});
  if (args.has("help")) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  if (!args.ok() || args.positional().size() != 1) {
    const std::string why = !args.ok()                    ? args.error()
                            : args.positional().empty()  ? std::string("no capture file given")
                                                          : "more than one file: " + args.positional()[1];
    std::fprintf(stderr, "fieldguard inspect: %s\n\n%s", why.c_str(), kHelp);
    return kExitBadInput;
  }
  const std::string path = args.positional().front();
  inspect::PortOptions ports;
  std::string port_error;
  ports.data = port_option(args, "data-port", port_error);
  if (port_error.empty()) ports.position = port_option(args, "position-port", port_error);
  if (!port_error.empty()) {
    std::fprintf(stderr, "fieldguard inspect: %s\n", port_error.c_str());
    return kExitBadInput;
  }
  const Format* format = nullptr;
  if (const auto name = args.get("format")) {
    format = find_format(*name);
    if (format == nullptr) {
      std::fprintf(stderr, "fieldguard inspect: unknown format '%s'; use one of %s\n", name->c_str(),
                   format_names().c_str());
      return kExitBadInput;
    }
  }

  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) {
    std::fprintf(stderr, "fieldguard inspect: cannot open '%s': check the path and permissions\n", path.c_str());
    return kExitBadInput;
  }
  // Enough to see the first datagrams of a LiDAR pcap (a dozen 1.2 KB packets).
  std::array<std::uint8_t, 16384> head{};
  const std::size_t head_size = std::fread(head.data(), 1, head.size(), file.get());
  if (head_size == 0) {
    std::fprintf(stderr, "fieldguard inspect: '%s' is empty (or unreadable): nothing to inspect\n", path.c_str());
    return kExitBadInput;
  }
  const bool guessed = format == nullptr;
  if (guessed) {
    for (const auto& f : kFormats) {
      if (f.guess != nullptr && f.guess(ByteSpan(head.data(), head_size))) {
        format = &f;
        break;
      }
    }
    if (format == nullptr) {
      std::fprintf(stderr, "fieldguard inspect: cannot tell the format of '%s'; give it with --format %s\n",
                   path.c_str(), format_names().c_str());
      return kExitBadInput;
    }
  }
  Capture capture(file.get(), ByteSpan(head.data(), head_size));
  capture.ports = ports;
  Output out;
  Summary summary;
  format->run(capture, out, summary);
  out.flush();
  if (!summary.unusable.empty()) {
    std::fprintf(stderr, "fieldguard inspect: %s (format %s%s)\n", summary.unusable.c_str(), format->name,
                 guessed ? ", guessed" : "");
    return kExitBadInput;
  }
  print_summary(path, *format, guessed, capture.bytes_read(), out.lines(), summary);
  if (capture.read_error()) {
    std::fprintf(stderr, "fieldguard inspect: reading '%s' failed after %llu bytes: the summary covers those only\n",
                 path.c_str(), static_cast<unsigned long long>(capture.bytes_read()));
    return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace fieldguard::app
