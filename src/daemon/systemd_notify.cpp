#include "daemon/systemd_notify.hpp"

#include <systemd/sd-daemon.h>

#include <cstdint>
#include <cstdlib>

namespace fieldguard::app {

SystemdNotifier SystemdNotifier::from_environment() {
  SystemdNotifier n;
  const char* socket = std::getenv("NOTIFY_SOCKET");
  n.active_ = socket != nullptr && socket[0] != '\0';
  std::uint64_t usec = 0;
  // > 0 only when WATCHDOG_USEC is set and WATCHDOG_PID (if set) names this process.
  if (n.active_ && sd_watchdog_enabled(0, &usec) > 0 && usec > 0) {
    n.watchdog_timeout_ = std::chrono::microseconds(static_cast<std::int64_t>(usec));
  }
  return n;
}

void SystemdNotifier::send(const std::string& message) {
  if (!active_) {
    return;
  }
  // pid 0: as this process. unset_environment 0: a reload or a later call must still find the socket.
  if (sd_pid_notify(0, 0, message.c_str()) <= 0) {
    ++send_errors_;
  }
}

void SystemdNotifier::ready(std::string_view status) {
  last_status_ = one_line(status);
  send("READY=1\nSTATUS=" + last_status_);
}

void SystemdNotifier::status(std::string_view status) {
  std::string line = one_line(status);
  if (line == last_status_) {
    return;
  }
  last_status_ = std::move(line);
  send("STATUS=" + last_status_);
}

void SystemdNotifier::reloading() { send("RELOADING=1"); }

void SystemdNotifier::reloaded(std::string_view status) { ready(status); }

void SystemdNotifier::stopping() { send("STOPPING=1"); }

void SystemdNotifier::progress(Clock::time_point now) {
  if (!watchdog_timeout_) {
    return;
  }
  const auto spacing = *watchdog_timeout_ / 4;
  if (last_ping_ && now - *last_ping_ < spacing) {
    return;
  }
  last_ping_ = now;
  ++pings_;
  send("WATCHDOG=1");
}

std::string one_line(std::string_view text) {
  std::string out(text);
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      c = ' ';
    }
  }
  return out;
}

}  // namespace fieldguard::app
