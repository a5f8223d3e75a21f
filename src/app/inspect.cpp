// `fieldguard inspect FILE [--format F]`: the field engineer's "what is in this capture?". Every decoded sample
// as one JSON line on stdout; a summary (counts by kind and by rejection reason) on stderr.
// The formats themselves live in inspect_<format>.cpp; see inspect_format.hpp for how to add one.

#include <array>
#include <cstdio>
#include <memory>
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
    "\n"
    "Decodes a capture and prints every decoded sample as one JSON line on stdout, then a summary on stderr:\n"
    "records by kind, rejected input by reason, and the bytes that were noise. Rejected input gives no record.\n"
    "The format is guessed from the first bytes when --format is left out.\n"
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
    "\n"
    "Exit code 0 when the file was read (even with rejections), 2 when it is unusable (missing, empty, a format\n"
    "that cannot be told or is not supported yet).\n";

using InspectFn = void (*)(Capture&, Output&, Summary&);
using GuessFn = bool (*)(ByteSpan);

struct Format {
  const char* name;
  InspectFn run;  // nullptr: recognised, not supported yet
  GuessFn guess;  // nullptr: only with --format
};

bool looks_like_pcap(ByteSpan head) {
  if (head.size() < 4) return false;
  const std::uint32_t le = load_le32(head, 0);
  return le == 0xA1B2C3D4U || le == 0xD4C3B2A1U || le == 0xA1B23C4DU || le == 0x4D3CB2A1U ||
         le == 0x0A0D0D0AU;  // classic pcap (either byte order, us or ns) or pcapng
}

// Guesses are tried in this order. A pcap is reported as velodyne (the LiDAR formats come as pcap).
const std::array<Format, 6> kFormats = {{
    {"velodyne", nullptr, looks_like_pcap},
    {"nmea", inspect::inspect_nmea, inspect::looks_like_nmea},
    {"xsens", inspect::inspect_xsens, inspect::looks_like_xsens},
    {"robosense", nullptr, nullptr},
    {"scip", nullptr, nullptr},
    {"candump", nullptr, nullptr},
}};

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
}

}  // namespace

bool inspect::Capture::for_each_chunk(const std::function<void(ByteSpan)>& chunk) {
  bytes_ = head_.size();
  chunk(head_);
  std::vector<std::uint8_t> buf(1 << 16);
  while (true) {
    const std::size_t n = std::fread(buf.data(), 1, buf.size(), f_);
    if (n > 0) {
      bytes_ += n;
      chunk(ByteSpan(buf.data(), n));
    }
    if (n < buf.size()) {
      read_error_ = std::ferror(f_) != 0;
      return !read_error_;
    }
  }
}

int cmd_inspect(const std::vector<std::string>& argv) {
  const Args args(argv, {"format"}, {"help"});
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
  std::array<std::uint8_t, 4096> head{};
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
  if (format->run == nullptr) {
    std::fprintf(stderr, "fieldguard inspect: format '%s'%s is not yet supported by inspect\n", format->name,
                 guessed ? " (guessed)" : "");
    return kExitBadInput;
  }

  Capture capture(file.get(), ByteSpan(head.data(), head_size));
  Output out;
  Summary summary;
  format->run(capture, out, summary);
  out.flush();
  print_summary(path, *format, guessed, capture.bytes_read(), out.lines(), summary);
  if (capture.read_error()) {
    std::fprintf(stderr, "fieldguard inspect: reading '%s' failed after %llu bytes: the summary covers those only\n",
                 path.c_str(), static_cast<unsigned long long>(capture.bytes_read()));
    return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace fieldguard::app
