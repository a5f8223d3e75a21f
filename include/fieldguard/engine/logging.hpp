#pragma once
// One named spdlog logger per module, all to stderr with a fixed pattern and no timestamps of our own
// (under systemd the journal stamps lines). For the application layer (engine, replay, daemon): no module
// below it sees spdlog.
//
// Under systemd, stderr is the journal's stream and each line starts with its syslog priority ("<4>" for a
// warning, sd-daemon(3)'s prefixes), so `journalctl -p warning` shows exactly the warnings and errors. On a
// terminal or in a file the lines read "[safety] warning: ...".

#include <spdlog/logger.h>

#include <memory>
#include <string>
#include <string_view>

#include "fieldguard/output/safety_monitor.hpp"

namespace fieldguard::app {

[[nodiscard]] std::shared_ptr<spdlog::logger> logger(const std::string& name);

// True when `fd` is the stream systemd's journal reads: JOURNAL_STREAM ("DEVICE:INODE", set by systemd for a
// service whose output goes to the journal) names the file `fd` is open on. Null or malformed: false.
[[nodiscard]] bool is_journal_stream(int fd, const char* journal_stream);

// The syslog priority of a level: 3 error, 4 warning, 6 info, 7 debug (2 for critical).
[[nodiscard]] int syslog_priority(spdlog::level::level_enum level);

// The level of a safety event's line: a warning when the monitor's own view is degraded, an error when the stop
// request reaches nobody, info for start-up, obstacles and go (output::safety::severity).
[[nodiscard]] spdlog::level::level_enum level_of(output::safety::Severity s);

// Logs a decision that changed on the `safety` logger at its reason's level: "<what>: <event text>".
void log_safety_event(const output::safety::Event& e, std::string_view what);

}  // namespace fieldguard::app
