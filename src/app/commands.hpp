#pragma once
// The subcommands' command lines (commands.cpp, check_config.cpp). Each returns the process exit code
// (fieldguard/core/exit_code.hpp).

#include <string>
#include <vector>

namespace fieldguard::app {

int cmd_check_config(const std::vector<std::string>& args);
int cmd_replay(const std::vector<std::string>& args);
int cmd_inspect(const std::vector<std::string>& args);
int cmd_record(const std::vector<std::string>& args);
int cmd_run(const std::vector<std::string>& args);

}  // namespace fieldguard::app
