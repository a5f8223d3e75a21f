#include "fieldguard/engine/logging.hpp"

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <charconv>
#include <cstdlib>

namespace fieldguard::app {

namespace {

// "%*": the line's syslog priority in sd-daemon's form, "<4>".
class PriorityFlag final : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& msg, const std::tm&, spdlog::memory_buf_t& dest) override {
    const char text[] = {'<', static_cast<char>('0' + syslog_priority(msg.level)), '>'};
    dest.append(text, text + sizeof text);
  }
  [[nodiscard]] std::unique_ptr<custom_flag_formatter> clone() const override {
    return std::make_unique<PriorityFlag>();
  }
};

bool parse_unsigned(std::string_view s, unsigned long long& out) {
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && end == s.data() + s.size() && !s.empty();
}

}  // namespace

bool is_journal_stream(int fd, const char* journal_stream) {
  if (journal_stream == nullptr) return false;
  const std::string_view v(journal_stream);
  const auto colon = v.find(':');
  unsigned long long dev = 0, ino = 0;
  if (colon == std::string_view::npos || !parse_unsigned(v.substr(0, colon), dev) ||
      !parse_unsigned(v.substr(colon + 1), ino)) {
    return false;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) return false;
  return static_cast<unsigned long long>(st.st_dev) == dev && static_cast<unsigned long long>(st.st_ino) == ino;
}

int syslog_priority(spdlog::level::level_enum level) {
  switch (level) {
    case spdlog::level::critical: return 2;
    case spdlog::level::err: return 3;
    case spdlog::level::warn: return 4;
    case spdlog::level::info: return 6;
    default: return 7;  // debug, trace
  }
}

spdlog::level::level_enum level_of(output::safety::Severity s) {
  switch (s) {
    case output::safety::Severity::Info: return spdlog::level::info;
    case output::safety::Severity::Warning: return spdlog::level::warn;
    case output::safety::Severity::Error: return spdlog::level::err;
  }
  return spdlog::level::err;
}

std::shared_ptr<spdlog::logger> logger(const std::string& name) {
  if (auto existing = spdlog::get(name)) return existing;
  auto l = spdlog::stderr_logger_mt(name);
  if (is_journal_stream(STDERR_FILENO, std::getenv("JOURNAL_STREAM"))) {  // NOLINT(concurrency-mt-unsafe): no setenv
    auto f = std::make_unique<spdlog::pattern_formatter>();
    f->add_flag<PriorityFlag>('*').set_pattern("%*[%n] %l: %v");
    l->set_formatter(std::move(f));
  } else {
    l->set_pattern("[%n] %l: %v");
  }
  return l;
}

void log_safety_event(const output::safety::Event& e, std::string_view what) {
  logger("safety")->log(level_of(output::safety::severity(e.reason)), "{}: {}", what, e.text);
}

}  // namespace fieldguard::app
