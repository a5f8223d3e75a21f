#pragma once
// One named spdlog logger per module, all to stderr with a fixed pattern and no timestamps of our own
// (under systemd the journal stamps lines). For the application layer (engine, replay, daemon): no module
// below it sees spdlog.

#include <spdlog/logger.h>

#include <memory>
#include <string>

namespace fieldguard::app {

[[nodiscard]] std::shared_ptr<spdlog::logger> logger(const std::string& name);

}  // namespace fieldguard::app
