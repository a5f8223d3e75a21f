#pragma once
// Command-line options of the bench tools (emulators and players): `--name value` pairs and flags, with a
// clear message and exit code 2 for a missing or malformed value instead of an exception.

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace fieldguard::tools {

class Options {
 public:
  Options(int argc, char** argv, const char* program, const char* usage)
      : argc_(argc), argv_(argv), program_(program), usage_(usage) {}

  // Advances to the next option; false when there are none left. `--help` prints the usage and exits 0.
  bool next() {
    if (++i_ >= argc_) return false;
    name_ = argv_[i_];
    if (name_ == "--help") {
      std::fputs(usage_, stdout);
      std::exit(0);
    }
    return true;
  }
  [[nodiscard]] bool is(const char* name) const { return name_ == name; }

  [[nodiscard]] std::string text() {
    if (i_ + 1 >= argc_) fail(name_ + " needs a value");
    return argv_[++i_];
  }
  [[nodiscard]] long integer(long min, long max) {
    const std::string v = text();
    errno = 0;
    char* end = nullptr;
    const long n = std::strtol(v.c_str(), &end, 10);
    if (v.empty() || *end != '\0' || errno != 0 || n < min || n > max) {
      fail(name_ + " takes a whole number from " + std::to_string(min) + " to " + std::to_string(max) + ", not '" +
           v + "'");
    }
    return n;
  }
  [[nodiscard]] double number(double min, double max) {
    const std::string v = text();
    errno = 0;
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || errno != 0 || !(x >= min && x <= max)) {
      fail(name_ + " takes a number from " + std::to_string(min) + " to " + std::to_string(max) + ", not '" + v + "'");
    }
    return x;
  }
  [[noreturn]] void unknown() { fail("unknown option " + name_); }
  [[noreturn]] void fail(const std::string& why) {
    std::fprintf(stderr, "%s: %s\n%s", program_, why.c_str(), usage_);
    std::exit(2);
  }

 private:
  int argc_;
  char** argv_;
  const char* program_;
  const char* usage_;
  int i_ = 0;
  std::string name_;
};

}  // namespace fieldguard::tools
