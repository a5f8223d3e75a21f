#pragma once
// Test support: runs a program as a child process (an emulator, the fieldguard binary), reads lines of its
// standard output (the emulators print their port or device first), and ends it when the test is done.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

namespace fieldguard::testing {

class ChildProcess {
 public:
  // argv[0] is the program's path.
  explicit ChildProcess(const std::vector<std::string>& argv) {
    int out[2];
    if (::pipe(out) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], STDOUT_FILENO);
      ::close(out[0]);
      ::close(out[1]);
      std::vector<char*> a;
      for (const auto& s : argv) a.push_back(const_cast<char*>(s.c_str()));
      a.push_back(nullptr);
      ::execv(a[0], a.data());
      ::_exit(127);
    }
    ::close(out[1]);
    out_ = ::fdopen(out[0], "r");
  }
  ~ChildProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
    }
    if (out_ != nullptr) std::fclose(out_);
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // The next line of its output without the line end, "" at the end of its output.
  std::string line() {
    char buf[256] = {};
    if (out_ == nullptr || std::fgets(buf, sizeof buf, out_) == nullptr) return {};
    std::string s(buf);
    s.erase(s.find_last_not_of("\r\n") + 1);
    return s;
  }

  // Sends it a signal (SIGTERM: how a daemon or an emulator is told to stop and report).
  void signal(int sig) const {
    if (pid_ > 0) ::kill(pid_, sig);
  }

  // Waits for it to exit by itself; its exit code, or -1 when a signal ended it.
  int wait() {
    int status = 0;
    if (pid_ > 0) ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
  FILE* out_ = nullptr;
};

}  // namespace fieldguard::testing
