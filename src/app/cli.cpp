#include "fieldguard/app/cli.hpp"

#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "fieldguard/core/exit_code.hpp"
#include "fieldguard/core/version.hpp"

namespace fieldguard::app {
namespace {

constexpr const char* kUsage =
    "usage: fieldguard <command> [options]\n"
    "\n"
    "Obstacle detection for autonomous tractors: LiDAR, GNSS and AHRS in, obstacles and a stop request out.\n"
    "\n"
    "commands:\n"
    "  replay         run captured sensor data (pcap) through the pipeline\n"
    "  check-config   validate a configuration file and list every problem\n"
    "  inspect        decode a capture (NMEA, Xsens, ...) into one JSON line per sample\n"
    "  record         save what the live sensors send, for replay\n"
    "  run            the daemon: live sensors -> detection -> stop decision -> CAN\n"
    "\n"
    "options:\n"
    "  --help         this text; `fieldguard <command> --help` for a command's options\n"
    "  --version      print the version\n";

}  // namespace

int run_cli(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    std::fputs(kUsage, stderr);
    return kExitBadInput;
  }
  const std::string cmd = args.front();
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  try {
    if (cmd == "--help" || cmd == "-h" || cmd == "help") {
      std::fputs(kUsage, stdout);
      return kExitOk;
    }
    if (cmd == "--version") {
      std::printf("%s\n", version_string());
      return kExitOk;
    }
    if (cmd == "check-config") return cmd_check_config(rest);
    if (cmd == "replay") return cmd_replay(rest);
    if (cmd == "inspect") return cmd_inspect(rest);
    if (cmd == "record") return cmd_record(rest);
    if (cmd == "run") return cmd_run(rest);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fieldguard %s: internal error: %s\n", cmd.c_str(), e.what());
    return kExitFailure;
  }
  std::fprintf(stderr, "fieldguard: unknown command '%s'\n\n%s", cmd.c_str(), kUsage);
  return kExitBadInput;
}

}  // namespace fieldguard::app
