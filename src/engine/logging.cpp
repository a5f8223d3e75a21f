#include "fieldguard/engine/logging.hpp"

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

namespace fieldguard::app {

std::shared_ptr<spdlog::logger> logger(const std::string& name) {
  if (auto existing = spdlog::get(name)) return existing;
  auto l = spdlog::stderr_logger_mt(name);
  l->set_pattern("[%n] %l: %v");
  return l;
}

}  // namespace fieldguard::app
