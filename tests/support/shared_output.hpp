#pragma once
// Test support: a directory of generated test input (a simulator session) made once per build and shared by
// the test processes that need it. CTest runs every test in a process of its own, so a suite's
// SetUpTestSuite would otherwise make the same session again for each of its tests. The directory is made
// under a temporary name and renamed into place, so a half-made one is never seen; when two processes make it
// at once, the first rename wins and the other's copy is dropped. `key` must change with whatever makes the
// content (stamp_of() of the generating binary does).

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <system_error>

namespace fieldguard::testing {

// Size and modification time of `path`: changes when that binary is rebuilt.
inline std::string stamp_of(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return "missing";
  return std::to_string(st.st_size) + "-" + std::to_string(st.st_mtim.tv_sec) + "-" +
         std::to_string(st.st_mtim.tv_nsec);
}

// `root/key`, made by `make(dir)` (true when it succeeded) unless it is already there; "" when making failed.
inline std::string shared_output(const std::string& root, const std::string& key,
                                 const std::function<bool(const std::string& dir)>& make) {
  namespace fs = std::filesystem;
  const fs::path done = fs::path(root) / key;
  if (fs::exists(done / ".complete")) return done.string();
  fs::path tmp = done;
  tmp += ".part" + std::to_string(::getpid());
  std::error_code ec;
  fs::remove_all(tmp, ec);
  fs::create_directories(tmp);
  if (!make(tmp.string())) {
    fs::remove_all(tmp, ec);
    return "";
  }
  std::ofstream(tmp / ".complete") << "complete\n";
  fs::rename(tmp, done, ec);  // fails when another process got there first: its copy is as good
  if (ec) fs::remove_all(tmp, ec);
  return fs::exists(done / ".complete") ? done.string() : "";
}

}  // namespace fieldguard::testing
