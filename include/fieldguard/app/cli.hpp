#pragma once

namespace fieldguard::app {
// The `fieldguard` command line: subcommands replay, check-config; --help, --version.
int run_cli(int argc, char** argv);
}  // namespace fieldguard::app
