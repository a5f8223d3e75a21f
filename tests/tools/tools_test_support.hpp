#pragma once
// Test support for tests/tools: running the tools as processes and scratch files.

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "app/run_command.hpp"

namespace fieldguard::tools_test {

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout only; stderr goes to `errors`
  std::string errors;
};

// Runs `binary args` through the shell; quote arguments yourself where needed.
inline CommandResult run(const std::string& binary, const std::string& args) {
  static int counter = 0;
  const std::filesystem::path err = std::filesystem::temp_directory_path() /
                                    ("fg_tools_err_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  const std::string cmd = "'" + binary + "' " + args + " 2>'" + err.string() + "'";
  const testing::CommandResult out = testing::run_shell(cmd);
  CommandResult r;
  r.exit_code = out.exit_code;
  r.output = out.output;
  std::ifstream e(err);
  r.errors.assign(std::istreambuf_iterator<char>(e), std::istreambuf_iterator<char>());
  std::filesystem::remove(err);
  return r;
}

// A fresh directory under the system temp directory, removed with the object.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag)
      : path_(std::filesystem::temp_directory_path() / ("fg_tools_" + tag + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  [[nodiscard]] std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

inline std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

}  // namespace fieldguard::tools_test
