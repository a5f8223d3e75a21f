#pragma once
// The daemon's side of systemd's notify protocol (Type=notify, WatchdogSec=), through libsystemd's
// sd_pid_notify. Outside systemd (no NOTIFY_SOCKET) every call is a no-op, so `fieldguard run` behaves the
// same by hand and under the service manager.
//
// The watchdog is fed by progress, not by a timer: `progress()` is called when a frame's stop/go decision
// has been made (from a real frame, or from a frame period that passed without one, which the safety
// monitor also decides on). A pipeline that stalls makes no decisions, so WATCHDOG=1 stops and systemd
// restarts the daemon; a LiDAR that goes silent does not stall the decisions (they say stop, sensor
// fault), so the daemon is not restarted for a fault restarting cannot mend.
// Thread contract: one thread (the output stage) calls everything.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace fieldguard::app {

class SystemdNotifier {
 public:
  using Clock = std::chrono::steady_clock;

  // Reads NOTIFY_SOCKET, WATCHDOG_USEC and WATCHDOG_PID (through sd_watchdog_enabled) once.
  static SystemdNotifier from_environment();

  [[nodiscard]] bool active() const { return active_; }
  // The service's WatchdogSec, when the watchdog is enabled for this process.
  [[nodiscard]] std::optional<std::chrono::microseconds> watchdog_timeout() const { return watchdog_timeout_; }

  // READY=1 with a STATUS= line: sent once, when every required sensor has delivered.
  void ready(std::string_view status);
  // STATUS= alone (the one-line health summary `systemctl status` shows). Sent only when it changed.
  void status(std::string_view status);
  // RELOADING=1 when SIGHUP starts a config reload; READY=1 again once it is done (or rejected).
  void reloading();
  void reloaded(std::string_view status);
  // STOPPING=1 on SIGTERM / SIGINT.
  void stopping();

  // A decision was made at `now`. Sends WATCHDOG=1 at most once per quarter of the watchdog timeout, so
  // a 5 Hz pipeline under WatchdogSec=2s pings every 0.5 s and a missed ping still leaves three more.
  void progress(Clock::time_point now);

  [[nodiscard]] std::uint64_t watchdog_pings() const { return pings_; }
  // sd_pid_notify failures (socket gone, buffer full): counted, never fatal.
  [[nodiscard]] std::uint64_t send_errors() const { return send_errors_; }

 private:
  SystemdNotifier() = default;
  void send(const std::string& message);

  bool active_ = false;
  std::optional<std::chrono::microseconds> watchdog_timeout_;
  std::optional<Clock::time_point> last_ping_;
  std::string last_status_;
  std::uint64_t pings_ = 0;
  std::uint64_t send_errors_ = 0;
};

// STATUS= text must be one line: newlines and other control characters become spaces.
[[nodiscard]] std::string one_line(std::string_view text);

}  // namespace fieldguard::app
