// Per-sensor health and the status line (health.hpp).

#include "fieldguard/sync/health.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace fieldguard::sync {

HealthMonitor::HealthMonitor(double rate_window_s) {
  if (!(rate_window_s > 0.0 && rate_window_s <= 3600.0)) {
    throw std::invalid_argument("health: rate_window_s must be in (0, 3600]");
  }
  window_ns_ = static_cast<std::int64_t>(std::llround(rate_window_s * 1e9));
}

void HealthMonitor::sample(SensorKind k, Stamp host) {
  SensorHealth& h = sensors_[index(k)];
  ++h.samples;
  if (!h.last_host || *h.last_host < host) h.last_host = host;
  auto& recent = tracks_[index(k)].recent;
  if (recent.full()) recent.set_capacity(2 * recent.capacity());
  recent.push_back(host.ns);
  // Keep the window behind the newest time; the bound also caps memory for a sensor flooding the link.
  const std::int64_t newest = h.last_host->ns;
  while (!recent.empty() && (recent.front() <= newest - window_ns_ || recent.size() > 100'000)) recent.pop_front();
}

std::optional<double> HealthMonitor::age_s(SensorKind k, Stamp now) const {
  const SensorHealth& h = sensors_[index(k)];
  if (!h.last_host) return std::nullopt;
  return static_cast<double>(now.ns - h.last_host->ns) * 1e-9;
}

double HealthMonitor::rate_hz(SensorKind k, Stamp now) const {
  const auto& recent = tracks_[index(k)].recent;
  const auto n = std::count_if(recent.begin(), recent.end(),
                               [&](std::int64_t t) { return t > now.ns - window_ns_ && t <= now.ns; });
  return static_cast<double>(n) / (static_cast<double>(window_ns_) * 1e-9);
}

std::string HealthMonitor::sensors_line(Stamp now, std::uint8_t off) const {
  std::string s;
  char buf[48];
  for (SensorKind k : kAllSensors) {
    if (k != SensorKind::Lidar3d) s += ", ";
    s += to_string(k);
    if ((off & bit(k)) != 0) {
      s += " off";
      continue;
    }
    if (!sensors_[index(k)].last_host) {
      s += " never heard";
    } else {
      std::snprintf(buf, sizeof buf, " %.1f Hz", rate_hz(k, now));
      s += buf;
    }
    if (const std::uint64_t e = sensors_[index(k)].errors.total(); e > 0) {
      std::snprintf(buf, sizeof buf, " err %llu", static_cast<unsigned long long>(e));
      s += buf;
    }
  }
  return s;
}

std::string HealthMonitor::status_line(Stamp now, std::optional<SensorKind> waiting, std::uint64_t frames,
                                       std::uint64_t incomplete) const {
  std::string s;
  char buf[96];
  if (waiting) {
    s += "waiting for ";
    s += to_string(*waiting);
    if (const auto age = age_s(*waiting, now)) {
      std::snprintf(buf, sizeof buf, " (silent %.1f s)", *age);
      s += buf;
    } else {
      s += " (never heard)";
    }
  } else {
    s += "ok";
  }
  s += " | ";
  s += sensors_line(now, 0);
  std::snprintf(buf, sizeof buf, " | frames %llu, incomplete %llu", static_cast<unsigned long long>(frames),
                static_cast<unsigned long long>(incomplete));
  s += buf;
  return s;
}

}  // namespace fieldguard::sync
