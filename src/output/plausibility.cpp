#include "fieldguard/output/plausibility.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace fieldguard::output::safety {

std::string_view to_string(Problem p) {
  switch (p) {
    case Problem::None: return "plausible";
    case Problem::NotFinite: return "not a number";
    case Problem::NoFix: return "no fix";
    case Problem::FixNotAccepted: return "fix quality not accepted";
    case Problem::TooFewSatellites: return "too few satellites";
    case Problem::HdopTooHigh: return "HDOP too high";
    case Problem::OutOfRange: return "value out of range";
    case Problem::PositionJump: return "position jump";
    case Problem::TimeWentBack: return "time went back";
    case Problem::RollBeyondLimit: return "roll beyond limit";
    case Problem::PitchBeyondLimit: return "pitch beyond limit";
    case Problem::AttitudeJump: return "attitude jump";
  }
  return "unknown problem";
}

namespace {

// Keeps the first problem since the previous take().
Problem remember(Problem& pending, Problem p) {
  if (pending == Problem::None) pending = p;
  return p;
}

Problem take_pending(Problem& pending) {
  const Problem p = pending;
  pending = Problem::None;
  return p;
}

// Seconds from a to b, or nullopt when either time is unknown.
std::optional<double> seconds_between(Stamp a, Stamp b) {
  if (a.ns == 0 || b.ns == 0) return std::nullopt;
  return static_cast<double>(b.ns - a.ns) * 1e-9;
}

// Smallest angle between two headings (degrees, 0..180): yaw wraps at +-180.
double angle_diff_deg(double a, double b) {
  const double d = std::fmod(std::abs(a - b), 360.0);
  return d > 180.0 ? 360.0 - d : d;
}

// Distance between two fixes (m), locally flat: fine over the metres between two fixes of one tractor.
double ground_distance_m(const GnssFix& a, const GnssFix& b) {
  constexpr double kEarthRadius_m = 6371000.0;
  constexpr double kRad = std::numbers::pi / 180.0;
  const double mean_lat = 0.5 * (a.lat_deg + b.lat_deg) * kRad;
  double dlon = b.lon_deg - a.lon_deg;
  if (dlon > 180.0) dlon -= 360.0;
  if (dlon < -180.0) dlon += 360.0;
  const double dx = dlon * kRad * std::cos(mean_lat) * kEarthRadius_m;
  const double dy = (b.lat_deg - a.lat_deg) * kRad * kEarthRadius_m;
  return std::hypot(dx, dy);
}

Problem check_gnss(const GnssLimits& lim, const GnssFix& f, const std::optional<GnssFix>& last) {
  if (!std::isfinite(f.lat_deg) || !std::isfinite(f.lon_deg) || (f.hdop && !std::isfinite(*f.hdop))) {
    return Problem::NotFinite;
  }
  if (!f.quality || *f.quality == 0) return Problem::NoFix;
  if (*f.quality < 0 || *f.quality > 15 || (lim.accepted_fix_mask & (1U << static_cast<unsigned>(*f.quality))) == 0) {
    return Problem::FixNotAccepted;
  }
  if (std::abs(f.lat_deg) > 90.0 || std::abs(f.lon_deg) > 180.0) return Problem::OutOfRange;
  if (lim.min_satellites > 0 && (!f.satellites || *f.satellites < lim.min_satellites)) return Problem::TooFewSatellites;
  if (lim.max_hdop > 0.0 && (!f.hdop || *f.hdop > lim.max_hdop)) return Problem::HdopTooHigh;
  if (last) {
    if (const auto dt = seconds_between(last->sensor, f.sensor)) {
      if (*dt < 0.0) return Problem::TimeWentBack;
      // Equal times are a repeated fix; nothing to compare.
      if (*dt > 0.0 && ground_distance_m(*last, f) > lim.max_speed_mps * *dt) return Problem::PositionJump;
    }
  }
  return Problem::None;
}

Problem check_ahrs(const AhrsLimits& lim, const Attitude& a, const std::optional<Attitude>& last) {
  if (!std::isfinite(a.roll_deg) || !std::isfinite(a.pitch_deg) || !std::isfinite(a.yaw_deg)) return Problem::NotFinite;
  if (std::abs(a.roll_deg) > 180.0 || std::abs(a.pitch_deg) > 90.0 || std::abs(a.yaw_deg) > 360.0) {
    return Problem::OutOfRange;
  }
  if (std::abs(a.roll_deg) > lim.max_roll_deg) return Problem::RollBeyondLimit;
  if (std::abs(a.pitch_deg) > lim.max_pitch_deg) return Problem::PitchBeyondLimit;
  if (last) {
    if (const auto dt = seconds_between(last->sensor, a.sensor)) {
      if (*dt < 0.0) return Problem::TimeWentBack;
      if (*dt > 0.0) {
        const double turned = std::max({std::abs(a.roll_deg - last->roll_deg), std::abs(a.pitch_deg - last->pitch_deg),
                                        angle_diff_deg(a.yaw_deg, last->yaw_deg)});
        if (turned > lim.max_rate_deg_s * *dt) return Problem::AttitudeJump;
      }
    }
  }
  return Problem::None;
}

}  // namespace

Problem GnssCheck::check(const GnssFix& fix) {
  const Problem p = check_gnss(limits_, fix, last_);
  // Only fixes with a position to compare with are kept; a jump then shows once, not on every later fix.
  const bool comparable = std::isfinite(fix.lat_deg) && std::isfinite(fix.lon_deg) && fix.quality && *fix.quality > 0 &&
                          std::abs(fix.lat_deg) <= 90.0 && std::abs(fix.lon_deg) <= 180.0;
  if (comparable && (p != Problem::TimeWentBack)) last_ = fix;
  return remember(pending_, p);
}

Problem GnssCheck::take() { return take_pending(pending_); }

Problem AhrsCheck::check(const Attitude& a) {
  const Problem p = check_ahrs(limits_, a, last_);
  if (p != Problem::NotFinite && p != Problem::OutOfRange && p != Problem::TimeWentBack) last_ = a;
  return remember(pending_, p);
}

Problem AhrsCheck::take() { return take_pending(pending_); }

}  // namespace fieldguard::output::safety
