#pragma once
// One time type for the whole code base: signed nanoseconds since the Unix epoch (UTC).
// Every sample carries two: the sensor's own time mapped to UTC where the sensor gives it, and the host
// receive time (pcap record time in replay, kernel receive time live).

#include <chrono>
#include <cstdint>

namespace fieldguard {

using Nanos = std::chrono::nanoseconds;

struct Stamp {
  std::int64_t ns = 0;  // ns since the Unix epoch; 0 = unknown

  [[nodiscard]] double seconds() const { return static_cast<double>(ns) * 1e-9; }
  friend auto operator<=>(const Stamp&, const Stamp&) = default;
};

// A duration from the configuration's seconds (heartbeat periods, timeouts), rounded toward zero to whole ns.
[[nodiscard]] inline Nanos nanos_from_seconds(double seconds) {
  return std::chrono::duration_cast<Nanos>(std::chrono::duration<double>(seconds));
}

// The host's wall clock now, as a receive time.
[[nodiscard]] inline Stamp wall_clock_now() {
  return Stamp{std::chrono::duration_cast<Nanos>(std::chrono::system_clock::now().time_since_epoch()).count()};
}

struct SampleTimes {
  Stamp sensor;  // the sensor's own clock (mapped to UTC where possible)
  Stamp host;    // when the host received it
};

}  // namespace fieldguard
