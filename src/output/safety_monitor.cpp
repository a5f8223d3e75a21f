#include "fieldguard/output/safety_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace fieldguard::output::safety {

std::string_view to_string(Reason r) {
  switch (r) {
    case Reason::None: return "none";
    case Reason::ObstacleInZone: return "obstacle in zone";
    case Reason::SensorFault: return "sensor fault";
    case Reason::PipelineLate: return "pipeline late";
    case Reason::StartingUp: return "starting up";
    case Reason::ImplausibleData: return "implausible data";
    case Reason::NoAddress: return "no CAN address";
  }
  return "unknown reason";
}

namespace {

constexpr double kNever = std::numeric_limits<double>::infinity();

// Oriented footprints may sit this much inside the points they were fitted to (float arithmetic); the
// refinement gives the benefit of the doubt to the zone, never to the obstacle.
constexpr double kObbSlack_m = 0.01;

bool finite_box(const perception::Obstacle& o) {
  for (std::size_t i = 0; i < 2; ++i) {
    if (!std::isfinite(o.min[i]) || !std::isfinite(o.max[i])) return false;
  }
  return true;
}

bool usable_obb(const perception::Obstacle& o) {
  return std::isfinite(o.obb_center[0]) && std::isfinite(o.obb_center[1]) && std::isfinite(o.obb_length_m) &&
         std::isfinite(o.obb_width_m) && std::isfinite(o.obb_yaw_rad) && o.obb_length_m >= 0.F &&
         o.obb_width_m >= 0.F && (o.obb_length_m > 0.F || o.obb_width_m > 0.F);
}

// Separating-axis test of the oriented footprint against the zone rectangle.
bool obb_overlaps(const perception::Obstacle& o, const Zone& z) {
  const double hx = 0.5 * (z.x_max_m - z.x_min_m) + kObbSlack_m;
  const double hy = z.half_width_m + kObbSlack_m;
  const double dx = static_cast<double>(o.obb_center[0]) - 0.5 * (z.x_max_m + z.x_min_m);
  const double dy = static_cast<double>(o.obb_center[1]);
  const double hl = 0.5 * static_cast<double>(o.obb_length_m);
  const double hw = 0.5 * static_cast<double>(o.obb_width_m);
  const double c = std::cos(static_cast<double>(o.obb_yaw_rad));
  const double s = std::sin(static_cast<double>(o.obb_yaw_rad));
  // Zone axes x and y.
  if (std::abs(dx) > hx + std::abs(c) * hl + std::abs(s) * hw) return false;
  if (std::abs(dy) > hy + std::abs(s) * hl + std::abs(c) * hw) return false;
  // Footprint axes u = (c, s) and v = (-s, c).
  if (std::abs(dx * c + dy * s) > hl + hx * std::abs(c) + hy * std::abs(s)) return false;
  if (std::abs(-dx * s + dy * c) > hw + hx * std::abs(s) + hy * std::abs(c)) return false;
  return true;
}

std::string sensor_list(std::uint8_t mask) {
  std::string s;
  for (std::size_t i = 0; i < kSensorCount; ++i) {
    if ((mask & bit(static_cast<Sensor>(i))) == 0) continue;
    if (!s.empty()) s += ", ";
    s += to_string(static_cast<Sensor>(i));
  }
  return s;
}

// printf-style, so that the compiler checks every format against its arguments.
__attribute__((format(printf, 1, 2))) std::string fmt(const char* format, ...) {  // NOLINT(cert-dcl50-cpp)
  char buf[160];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buf, sizeof buf, format, args);  // NOLINT(clang-analyzer-valist.Uninitialized): va_start above
  va_end(args);
  return buf;
}

Reason highest(std::uint8_t reasons) {
  for (const Reason r : kReasonPriority) {
    if ((reasons & bit(r)) != 0) return r;
  }
  return Reason::None;
}

}  // namespace

bool overlaps(const perception::Obstacle& o, const Zone& z) {
  if (!finite_box(o)) return true;
  const bool aabb = static_cast<double>(o.max[0]) >= z.x_min_m && static_cast<double>(o.min[0]) <= z.x_max_m &&
                    static_cast<double>(o.max[1]) >= -z.half_width_m && static_cast<double>(o.min[1]) <= z.half_width_m;
  if (!aabb) return false;
  return !usable_obb(o) || obb_overlaps(o, z);
}

Monitor::Monitor(const Params& params) : params_(params) {
  const auto problems = validate(params);
  if (!problems.empty()) {
    std::string m = "invalid safety parameters:";
    for (const auto& p : problems) m += " " + p.key + ": " + p.message + ";";
    throw std::invalid_argument(m);
  }
  zone_ = zone_for(std::nullopt);
}

Zone Monitor::zone_for(std::optional<double> speed_mps) const {
  const bool known = speed_mps && std::isfinite(*speed_mps);
  const ZoneParams& z = params_.zone;
  return {z.rear_x_m, z.front_x_m + zone_length_m(z, known ? speed_mps : std::nullopt), z.half_width_m, known};
}

void Monitor::check_frame(const FrameInput& f, Stamp now) {
  zone_ = zone_for(f.speed_mps);
  obstacles_in_zone_ = 0;
  unplaceable_ = 0;
  const perception::Obstacle* nearest = nullptr;  // in the zone, smallest x
  for (const auto& o : f.obstacles) {
    if (!overlaps(o, zone_)) continue;
    ++obstacles_in_zone_;
    if (!finite_box(o)) {
      ++unplaceable_;
    } else if (nearest == nullptr || o.min[0] < nearest->min[0]) {
      nearest = &o;
    }
  }
  obstacle_latched_ = obstacles_in_zone_ > 0;
  if (obstacle_latched_) {
    // Kept as numbers: the text is made only when an event needs it, not on every frame.
    nearest_in_zone_.reset();
    if (nearest != nullptr) nearest_in_zone_ = {nearest->min[0], nearest->max[0], nearest->min[1], nearest->max[1]};
    obstacle_zone_ = zone_;
    obstacle_speed_kmh_ = zone_.speed_known ? std::abs(*f.speed_mps) * 3.6 : 0.0;
  }
  const double latency_s = f.data_end.ns == 0 ? kNever : static_cast<double>(now.ns - f.data_end.ns) * 1e-9;
  // A frame whose data are stamped after the decision is as doubtful as a late one.
  frame_late_latched_ = !(latency_s <= params_.pipeline_deadline_s && latency_s >= -params_.pipeline_deadline_s);
  if (frame_late_latched_) late_latency_s_ = latency_s;
  last_frame_ = now;
}

Decision Monitor::update(const Input& in) {
  const std::uint8_t required = params_.required_mask();
  std::uint8_t silent = 0;
  std::uint8_t implausible = 0;
  std::array<double, kSensorCount> silence_s{};
  for (std::size_t i = 0; i < kSensorCount; ++i) {
    const auto s = static_cast<Sensor>(i);
    if ((required & bit(s)) == 0) continue;
    const SensorInput& si = in.sensors[i];
    silence_s[i] = si.last_data.ns == 0 ? kNever : static_cast<double>(in.now.ns - si.last_data.ns) * 1e-9;
    const double timeout = params_.sensors[i].timeout_s;
    // Data stamped more than a timeout after `now` come from a confused clock and cannot vouch for the sensor.
    if (!(silence_s[i] <= timeout && silence_s[i] >= -timeout)) silent = static_cast<std::uint8_t>(silent | bit(s));
    if (si.problem != Problem::None) implausible = static_cast<std::uint8_t>(implausible | bit(s));
  }
  if (!started_ && silent == 0 && implausible == 0) {
    started_ = true;
    last_frame_ = in.now;  // the pipeline's frame interval is counted from here
  }
  if (in.frame != nullptr) check_frame(*in.frame, in.now);
  const double gap_s = last_frame_.ns == 0 ? 0.0 : static_cast<double>(in.now.ns - last_frame_.ns) * 1e-9;
  const bool stalled = started_ && gap_s > params_.max_frame_interval_s;

  std::uint8_t reasons = 0;
  auto set = [&reasons](Reason r) { reasons = static_cast<std::uint8_t>(reasons | bit(r)); };
  if (!started_) set(Reason::StartingUp);
  if (started_ && silent != 0) set(Reason::SensorFault);
  if (implausible != 0) set(Reason::ImplausibleData);
  if (frame_late_latched_ || stalled) set(Reason::PipelineLate);
  if (obstacle_latched_) set(Reason::ObstacleInZone);
  if (in.no_address) set(Reason::NoAddress);

  if (reasons != 0) {
    clear_ = 0;
    stop_ = true;
    reason_ = highest(reasons);
    switch (reason_) {
      case Reason::SensorFault:
      case Reason::StartingUp: event_sensors_ = silent; break;
      case Reason::ImplausibleData: event_sensors_ = implausible; break;
      default: event_sensors_ = 0; break;
    }
  } else if (in.frame != nullptr) {
    clear_ = std::min(clear_ + 1, params_.clear_frames);
    if (stop_ && clear_ >= params_.clear_frames) {
      stop_ = false;
      reason_ = Reason::None;
      event_sensors_ = 0;
    }
  }

  Decision d;
  d.stop = stop_;
  d.reason = reason_;
  d.reasons = reasons;
  d.fault_sensors = silent;
  d.implausible_sensors = implausible;
  d.clear_frames = clear_;
  d.obstacles_in_zone = obstacles_in_zone_;
  d.unplaceable_obstacles = unplaceable_;
  if (obstacle_latched_ && nearest_in_zone_) d.nearest_m = (*nearest_in_zone_)[0];
  d.zone = zone_;
  if (!first_ && stop_ == event_stop_ && reason_ == event_reason_ && event_sensors_ == event_sensors_sent_) return d;

  Event e;
  e.at = in.now;
  e.stop = stop_;
  e.reason = reason_;
  e.first = first_;
  e.was_stop = first_ ? true : event_stop_;
  e.previous_reason = first_ ? Reason::None : event_reason_;
  e.reasons = reasons;
  e.sensors = event_sensors_;
  std::string detail;
  switch (reason_) {
    case Reason::None:
      detail = "every reason clear for " + std::to_string(clear_) + (clear_ == 1 ? " frame" : " frames");
      break;
    case Reason::ObstacleInZone: detail = obstacle_text(); break;
    case Reason::StartingUp:
      // Waiting for a sensor, for plausible data from one, or (every sensor heard and plausible) for the clear
      // frames that make the first go.
      if (silent != 0) {
        detail = "waiting for " + sensor_list(silent);
      } else if (implausible != 0) {
        detail = "waiting for plausible data from " + sensor_list(implausible);
      } else {
        detail = fmt("every required sensor heard, clear %d of %d frames", clear_, params_.clear_frames);
      }
      break;
    case Reason::SensorFault:
      for (std::size_t i = 0; i < kSensorCount; ++i) {
        if ((silent & bit(static_cast<Sensor>(i))) == 0) continue;
        if (!detail.empty()) detail += ", ";
        detail += std::string(to_string(static_cast<Sensor>(i)));
        detail += silence_s[i] == kNever ? std::string(" never heard")
                  : silence_s[i] < 0.0
                      ? fmt(" data stamped %.3f s ahead of the monitor's clock", -silence_s[i])
                      : fmt(" silent %.3f s (timeout %.3f s)", silence_s[i], params_.sensors[i].timeout_s);
      }
      break;
    case Reason::ImplausibleData:
      for (std::size_t i = 0; i < kSensorCount; ++i) {
        if ((implausible & bit(static_cast<Sensor>(i))) == 0) continue;
        if (!detail.empty()) detail += ", ";
        detail += std::string(to_string(static_cast<Sensor>(i))) + " " + std::string(to_string(in.sensors[i].problem));
      }
      break;
    case Reason::NoAddress:
      detail = "another node holds our J1939 address and no other is free: nothing we send reaches the controller";
      break;
    case Reason::PipelineLate:
      if (!frame_late_latched_) {
        detail = fmt("no frame for %.3f s (limit %.3f s)", gap_s, params_.max_frame_interval_s);
      } else if (late_latency_s_ == kNever) {
        detail = "the frame has no data time";
      } else {
        detail =
            fmt("frame decided %.3f s after its data (deadline %.3f s)", late_latency_s_, params_.pipeline_deadline_s);
      }
      break;
  }
  std::string text = stop_ ? "stop: " : "go: ";
  if (stop_ && !first_ && event_stop_ && reason_ != event_reason_) {
    text += std::string(to_string(reason_)) + " (was " + std::string(to_string(event_reason_)) + "): ";
  } else if (stop_) {
    text += std::string(to_string(reason_)) + ": ";
  }
  text += detail;
  std::string also;
  for (const Reason r : kReasonPriority) {
    if (r == reason_ || (reasons & bit(r)) == 0) continue;
    also += (also.empty() ? "" : ", ") + std::string(to_string(r));
  }
  if (!also.empty()) text += "; also " + also;
  e.text = std::move(text);
  d.event = std::move(e);
  first_ = false;
  event_stop_ = stop_;
  event_reason_ = reason_;
  event_sensors_sent_ = event_sensors_;
  return d;
}

std::string headline(const Decision& d, int clear_frames_needed) {
  if (!d.stop) return "GO";
  std::string h = "STOP ";
  switch (d.reason) {
    case Reason::None: h += "holding"; break;  // not produced by the monitor: a stop always has a reason
    case Reason::ObstacleInZone:
      if (d.obstacles_in_zone == 0) {
        h += fmt("obstacle gone, clear %d of %d frames", d.clear_frames, clear_frames_needed);
      } else if (d.nearest_m) {
        h += fmt("obstacle %.1f m ahead", static_cast<double>(std::max(*d.nearest_m, 0.F)));
      } else {
        h += "obstacle in the zone (box not finite)";
      }
      break;
    case Reason::SensorFault:
      h += d.fault_sensors != 0
               ? sensor_list(d.fault_sensors) + " silent"
               : fmt("sensor fault cleared, clear %d of %d frames", d.clear_frames, clear_frames_needed);
      break;
    case Reason::ImplausibleData:
      h += d.implausible_sensors != 0
               ? sensor_list(d.implausible_sensors) + " implausible"
               : fmt("implausible data cleared, clear %d of %d frames", d.clear_frames, clear_frames_needed);
      break;
    case Reason::StartingUp:
      h += "starting up";
      if (d.fault_sensors != 0) {
        h += ": waiting for " + sensor_list(d.fault_sensors);
      } else if (d.implausible_sensors != 0) {
        h += ": " + sensor_list(d.implausible_sensors) + " implausible";
      } else {
        h += fmt(", clear %d of %d frames", d.clear_frames, clear_frames_needed);
      }
      break;
    case Reason::PipelineLate: h += "pipeline late"; break;
    case Reason::NoAddress: h += "no CAN address"; break;
  }
  return h;
}

Severity severity(Reason r) {
  switch (r) {
    case Reason::None:
    case Reason::ObstacleInZone:
    case Reason::StartingUp: return Severity::Info;
    case Reason::SensorFault:
    case Reason::ImplausibleData:
    case Reason::PipelineLate: return Severity::Warning;
    case Reason::NoAddress: return Severity::Error;
  }
  return Severity::Error;
}

std::string Monitor::obstacle_text() const {
  std::string t = std::to_string(obstacles_in_zone_) + (obstacles_in_zone_ == 1 ? " obstacle" : " obstacles");
  if (nearest_in_zone_) {
    const auto& b = *nearest_in_zone_;
    t += fmt(", nearest box x %.2f..%.2f m, y %.2f..%.2f m", static_cast<double>(b[0]), static_cast<double>(b[1]),
             static_cast<double>(b[2]), static_cast<double>(b[3]));
  }
  if (unplaceable_ > 0) t += ", " + std::to_string(unplaceable_) + " with a non-finite box";
  t += fmt("; zone x %.2f..%.2f m, |y| <= %.2f m", obstacle_zone_.x_min_m, obstacle_zone_.x_max_m,
           obstacle_zone_.half_width_m);
  t += obstacle_zone_.speed_known ? fmt(" at %.1f km/h", obstacle_speed_kmh_) : std::string(" (speed unknown)");
  return t;
}

}  // namespace fieldguard::output::safety
