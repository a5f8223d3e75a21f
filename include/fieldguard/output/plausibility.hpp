#pragma once
// Plausibility of GNSS fixes and AHRS attitudes, sample by sample, for the stop decision. Pure: the samples
// carry their own times; no clock is read. Thread-compatible: one checker per sensor, one caller at a time; a
// daemon that checks on its io thread hands the result of check() to the output stage itself (an atomic), and
// take() serves single-threaded callers (replay, tests).

#include <cstdint>
#include <optional>
#include <string_view>

#include "fieldguard/core/time.hpp"
#include "fieldguard/output/safety_params.hpp"

namespace fieldguard::output::safety {

enum class Problem : std::uint8_t {
  None = 0,
  NotFinite,       // a NaN or infinite value
  NoFix,           // fix quality 0 or absent ("no data is no data")
  FixNotAccepted,  // a quality outside GnssLimits::accepted_fix_mask
  TooFewSatellites,
  HdopTooHigh,
  OutOfRange,    // latitude or longitude outside the globe, angles outside +-180 / +-90 degrees
  PositionJump,  // moved faster than GnssLimits::max_speed_mps since the previous fix
  TimeWentBack,  // the sensor's time is earlier than the previous sample's
  RollBeyondLimit,
  PitchBeyondLimit,
  AttitudeJump,  // turned faster than AhrsLimits::max_rate_deg_s since the previous sample
};
[[nodiscard]] std::string_view to_string(Problem p);  // "position jump", ...

// A GNSS fix as the safety monitor needs it (the app fills it from GGA).
struct GnssFix {
  Stamp sensor;                // fix time (UTC); 0 = unknown: the jump check is skipped
  std::optional<int> quality;  // GGA fix quality; nullopt when the field was empty
  std::optional<int> satellites;
  std::optional<double> hdop;
  double lat_deg = 0.0;
  double lon_deg = 0.0;
};

struct Attitude {
  Stamp sensor;  // sample time; 0 = unknown: the rate check is skipped
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double yaw_deg = 0.0;
};

// Checks each sample and keeps the first problem seen since the last take(), so that a single bad sample
// between two frames still reaches the monitor.
class GnssCheck {
 public:
  explicit GnssCheck(const GnssLimits& limits) : limits_(limits) {}
  Problem check(const GnssFix& fix);
  // The first problem since the previous take() (None if every sample was plausible); clears it.
  [[nodiscard]] Problem take();

 private:
  GnssLimits limits_;
  std::optional<GnssFix> last_;  // the previous finite fix, plausible or not (a jump is reported once)
  Problem pending_ = Problem::None;
};

class AhrsCheck {
 public:
  explicit AhrsCheck(const AhrsLimits& limits) : limits_(limits) {}
  Problem check(const Attitude& a);
  [[nodiscard]] Problem take();

 private:
  AhrsLimits limits_;
  std::optional<Attitude> last_;  // the previous finite sample, plausible or not
  Problem pending_ = Problem::None;
};

}  // namespace fieldguard::output::safety
