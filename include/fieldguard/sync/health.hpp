#pragma once
// Per-sensor health: age of the last sample, rate over a sliding window, error counts, and the one-line status
// (the future systemd STATUS=) naming the sensor sync is waiting for.
//
// Pure: host times are passed in. Thread-compatible.

#include <array>
#include <boost/circular_buffer.hpp>
#include <cstdint>
#include <optional>
#include <string>

#include "fieldguard/core/time.hpp"
#include "fieldguard/sync/synced_frame.hpp"

namespace fieldguard::sync {

struct SensorErrors {
  std::uint64_t decode = 0;       // rejected by the decoder (reported by the caller)
  std::uint64_t untimed = 0;      // a sample without a usable sensor time
  std::uint64_t late = 0;         // arrived after the frames that needed it were emitted
  std::uint64_t clock_jumps = 0;  // the clock model was re-seeded
  std::uint64_t suspect = 0;      // samples far off the clock model
  [[nodiscard]] std::uint64_t total() const { return decode + untimed + late + clock_jumps + suspect; }
};

struct SensorHealth {
  std::optional<Stamp> last_host;  // receive time of the last sample
  std::uint64_t samples = 0;
  SensorErrors errors;
};

class HealthMonitor {
 public:
  explicit HealthMonitor(double rate_window_s = 2.0);  // throws std::invalid_argument unless > 0

  void sample(SensorKind k, Stamp host);
  [[nodiscard]] SensorErrors& errors(SensorKind k) { return sensors_[index(k)].errors; }
  [[nodiscard]] const SensorHealth& get(SensorKind k) const { return sensors_[index(k)]; }

  // Seconds since the last sample at host time `now`; nullopt when none yet.
  [[nodiscard]] std::optional<double> age_s(SensorKind k, Stamp now) const;
  // Samples per second over the window ending at `now`.
  [[nodiscard]] double rate_hz(SensorKind k, Stamp now) const;

  // "waiting for gnss (silent 1.4 s) | lidar3d 10.0 Hz, scan2d 40.0 Hz, gnss 0.0 Hz err 3, ahrs 100.0 Hz |
  //  frames 120, incomplete 1". `waiting` empty: "ok | ...". A sensor never heard of reads "never heard".
  [[nodiscard]] std::string status_line(Stamp now, std::optional<SensorKind> waiting, std::uint64_t frames,
                                        std::uint64_t incomplete) const;
  // Each sensor's rate and errors: "lidar3d 10.0 Hz, scan2d off, gnss never heard, ahrs 100.0 Hz err 3". The
  // sensors in `off` (bit(SensorKind) of those switched off in the configuration) read "off".
  [[nodiscard]] std::string sensors_line(Stamp now, std::uint8_t off) const;

 private:
  static std::size_t index(SensorKind k) { return static_cast<std::size_t>(k); }
  struct Track {
    // Receive times within the rate window of the last sample: a ring, grown (doubled) only when the window holds
    // more than ever before, so a steady stream allocates nothing.
    boost::circular_buffer<std::int64_t> recent = boost::circular_buffer<std::int64_t>(64);
  };
  std::int64_t window_ns_;
  std::array<SensorHealth, kSensorCount> sensors_{};
  std::array<Track, kSensorCount> tracks_{};
};

}  // namespace fieldguard::sync
