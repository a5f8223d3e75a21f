#pragma once
// The subcommands' command lines (CLI11). Each add_* declares a subcommand's options on `top` and binds
// them to the options of its module; after a successful parse, `run` calls that module. Private to app.

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace fieldguard::app {

// What the parsed command does: returns the process exit code (fieldguard/core/exit_code.hpp). Its checks
// that CLI11 cannot express (one of two options, ...) come first and return kExitBadInput through `usage_error`.
struct Command {
  CLI::App* app = nullptr;
  std::string usage;  // the synopsis line(s) after "usage: "
  std::function<int()> run;
};

// A usage error of `cmd`: "fieldguard <cmd>: <why>", then the command's help, on stderr; kExitBadInput.
int usage_error(const CLI::App& cmd, const std::string& why);

Command add_check_config(CLI::App& top);
Command add_replay(CLI::App& top);
Command add_inspect(CLI::App& top);
Command add_record(CLI::App& top);
Command add_run(CLI::App& top);

}  // namespace fieldguard::app
