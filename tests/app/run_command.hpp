#pragma once
// Test support: runs the real `fieldguard` binary and captures its exit code and output.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace fieldguard::testing {

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr, interleaved
};

// Runs `cmd` through the shell; the exit code (128 + the signal for a killed process) and what it wrote on stdout.
inline CommandResult run_shell(const std::string& cmd) {
  CommandResult r;
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  const int status = ::pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

#ifdef FIELDGUARD_BINARY
// `args` is appended to the binary's path as shell words; quote them yourself where needed.
inline CommandResult run_fieldguard(const std::string& args) {
  const std::string cmd = std::string("'") + FIELDGUARD_BINARY + "' " + args + " 2>&1";
  return run_shell(cmd);
}
#endif

// The number after `label` in a summary line such as "  points            12345".
inline long long summary_number(const std::string& output, const std::string& label) {
  const auto pos = output.find("  " + label + " ");
  if (pos == std::string::npos) return -1;
  return std::stoll(output.substr(output.find_first_not_of(' ', pos + 2 + label.size())));
}

}  // namespace fieldguard::testing
