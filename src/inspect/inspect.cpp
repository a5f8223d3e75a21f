// `fieldguard inspect FILE [--format F]`: the field engineer's "what is in this capture?". Every decoded sample
// as one JSON line on stdout; a summary (counts by kind and by rejection reason) on stderr.
// The formats themselves live in inspect_<format>.cpp; see inspect_format.hpp for how to add one.

#include "fieldguard/inspect/inspect.hpp"

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

#include "fieldguard/core/exit_code.hpp"
#include "inspect/inspect_format.hpp"

namespace fieldguard::app {
namespace {

using inspect::Capture;
using inspect::Output;
using inspect::Summary;

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

const Format* find_format(const std::string& name) {
  for (const auto& f : kFormats) {
    if (name == f.name) return &f;
  }
  return nullptr;
}

}  // namespace

std::string inspect_format_names() {
  std::string names;
  for (const auto& f : kFormats) names += std::string(names.empty() ? "" : "|") + f.name;
  return names;
}

namespace {

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
int close_capture(void* /*cookie*/) { return 0; }  // the file belongs to inspect_capture

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

int inspect_capture(const InspectOptions& opt) {
  const std::string& path = opt.path;
  inspect::PortOptions ports;
  ports.data = opt.data_port;
  ports.position = opt.position_port;
  const Format* format = nullptr;
  if (const auto& name = opt.format) {
    format = find_format(*name);
    if (format == nullptr) {
      std::fprintf(stderr, "fieldguard inspect: unknown format '%s'; use one of %s\n", name->c_str(),
                   inspect_format_names().c_str());
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
                   path.c_str(), inspect_format_names().c_str());
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
