#pragma once
// `fieldguard inspect`: decode a capture of any sensor into one JSON line per sample on stdout and a summary on
// stderr. The command line is the app's (app/commands.cpp); this is what it asks.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace fieldguard::app {

struct InspectOptions {
  std::string path;                            // the capture
  std::optional<std::string> format;           // a name of inspect_formats(); guessed from the bytes when not given
  std::optional<std::uint16_t> data_port;      // velodyne data (2368), robosense MSOP (6699)
  std::optional<std::uint16_t> position_port;  // velodyne position (8308), robosense DIFOP (7788)
};

// The format names `--format` takes, "a|b|...".
[[nodiscard]] std::string inspect_format_names();
// Inspects the capture; returns the process exit code (fieldguard/core/exit_code.hpp).
int inspect_capture(const InspectOptions& options);

}  // namespace fieldguard::app
