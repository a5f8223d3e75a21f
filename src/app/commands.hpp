#pragma once
// The subcommands. Each returns the process exit code: 0 success, 2 unusable input or usage error,
// 1 an internal failure (a bug or the machine: out of disk, ...).

#include <string>
#include <vector>

namespace fieldguard::app {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitBadInput = 2;

int cmd_check_config(const std::vector<std::string>& args);
int cmd_replay(const std::vector<std::string>& args);
int cmd_inspect(const std::vector<std::string>& args);
int cmd_record(const std::vector<std::string>& args);
int cmd_run(const std::vector<std::string>& args);

}  // namespace fieldguard::app
