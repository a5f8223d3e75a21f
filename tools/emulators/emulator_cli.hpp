#pragma once
// Options that more than one bench emulator has, defined once (on the tools' command-line conventions,
// tools/cli/cli.hpp).

#include <string>

#include "cli/cli.hpp"

namespace fieldguard::tools {

// A serial line's rate in baud (8N1: baud / 10 bytes a second); the emulators pace their bytes by it.
inline constexpr long kMaxBaud = 4'000'000;

// --loop N: play a recording N times, each after the previous.
template <typename T>
CLI::Option* add_loop(CLI::App& app, T& loops, const std::string& recording) {
  return cli::number(app, "--loop", loops, cli::Between<T>{1, 1'000'000},
                     "play " + recording + " N times, each after the previous (default 1)")
      ->type_name("N");
}

// NAME PATH: make PATH a symlink to a pty's slave device, as /dev/serial/by-id/... names a USB adapter.
inline CLI::Option* add_link(CLI::App& app, const std::string& name, std::string& path, const std::string& device) {
  return app
      .add_option(name, path, "make PATH a symlink to " + device + ",\nas /dev/serial/by-id/... names a USB adapter")
      ->type_name("PATH");
}

}  // namespace fieldguard::tools
