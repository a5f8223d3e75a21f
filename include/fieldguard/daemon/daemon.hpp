#pragma once
// The live side: `fieldguard run` (the daemon) and `fieldguard record`. The command lines are the app's
// (app/commands.cpp); these are what they ask.

#include <optional>
#include <string>

namespace fieldguard::app {

struct RunOptions {
  std::string config;                  // configuration file, read again on SIGHUP
  std::optional<std::string> can_log;  // a candump -L log instead of the configured CAN sink
  std::optional<std::string> mcap_out;  // view.mcap.path instead of the configuration's (a bounded series of files)
  bool quiet = false;                  // no summary on exit
};

// Runs the daemon until SIGTERM / SIGINT; returns the process exit code (fieldguard/core/exit_code.hpp).
int run_daemon(const RunOptions& options);

struct RecordOptions {
  std::string config;
  std::string out;                         // the session directory
  std::optional<double> duration;          // seconds (> 0); until a signal when not given
  std::optional<std::string> samples_out;  // every decoded sample as a JSON line
};

// Records the enabled live sources until a signal or the duration; returns the process exit code.
int record(const RecordOptions& options);

}  // namespace fieldguard::app
