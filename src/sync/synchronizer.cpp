// Samples -> mapped times -> frames (synchronizer.hpp).

#include "fieldguard/sync/synchronizer.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace fieldguard::sync {
namespace {

constexpr std::int64_t kHourNs = 3'600'000'000'000LL;
constexpr std::int64_t kDayNs = 86'400'000'000'000LL;

std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  std::int64_t q = a / b;
  if ((a % b != 0) && ((a < 0) != (b < 0))) --q;
  return q;
}

// Days since 1970-01-01 of a civil date (proleptic Gregorian; H. Hinnant's days_from_civil algorithm).
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = floor_div(y, 400);
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? static_cast<unsigned>(-3) : 9U)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

// Start of the period (hour, day) that puts `offset_in_period` nearest to `near`.
std::int64_t nearest_period_start(std::int64_t offset_in_period, std::int64_t period, std::int64_t near) {
  std::int64_t start = floor_div(near, period) * period;
  const std::int64_t t = start + offset_in_period;
  if (t - near > period / 2) start -= period;
  if (near - t > period / 2) start += period;
  return start;
}

std::optional<double> utc_of(const nmea::Sentence& s) {
  if (const auto* g = std::get_if<nmea::Gga>(&s)) return g->utc_seconds_of_day;
  if (const auto* r = std::get_if<nmea::Rmc>(&s)) return r->utc_seconds_of_day;
  return std::nullopt;
}

}  // namespace

Synchronizer::Synchronizer(const SyncParams& params)
    : params_(params),
      assembler_(params.assembler),
      health_(params.rate_window_s),
      lidar_clock_(kVelodyneMicrosPastHour, params.lidar_clock),
      scan_clock_(kScipMillis, params.scan_clock),
      gnss_clock_(kNmeaNanosOfDay, params.gnss_clock),
      ahrs_clock_(kXsensSampleTimeFine, params.ahrs_clock) {
  if (!(params_.untimed_pairing_s > 0.0)) throw std::invalid_argument("sync: untimed_pairing_s must be positive");
  if (!(params_.waiting_grace_s >= 0.0)) throw std::invalid_argument("sync: waiting_grace_s must not be negative");
}

SensorClock& Synchronizer::clock_of(SensorKind k) {
  switch (k) {
    case SensorKind::Lidar3d: return lidar_clock_;
    case SensorKind::Scan2d: return scan_clock_;
    case SensorKind::Gnss: return gnss_clock_;
    case SensorKind::Ahrs: return ahrs_clock_;
  }
  throw std::logic_error("sync: unknown sensor kind");
}

const SensorClock& Synchronizer::clock(SensorKind k) const { return const_cast<Synchronizer*>(this)->clock_of(k); }

void Synchronizer::note(SensorKind k, const Mapping& m, Stamp host) {
  health_.sample(k, host);
  if (m.suspect) ++health_.errors(k).suspect;
  if (m.jumped) ++health_.errors(k).clock_jumps;
}

void Synchronizer::push_lidar(LidarFrame&& rotation) {
  if (rotation.sensor_stamp.ns <= 0) {
    health_.sample(SensorKind::Lidar3d, rotation.host_stamp);
    ++health_.errors(SensorKind::Lidar3d).untimed;
    return;
  }
  // Back to what the sensor sent, microseconds past the hour, so the clock model sees the sensor's own counter.
  const std::int64_t in_hour = rotation.sensor_stamp.ns - floor_div(rotation.sensor_stamp.ns, kHourNs) * kHourNs;
  const auto raw_us = static_cast<std::uint64_t>(in_hour / 1000);
  WrapUnwrapper& u = lidar_clock_.unwrapper();
  if (lidar_clock_.model().pairs() == 0 && u.wraps() == 0) {
    u.seed_base(nearest_period_start(in_hour, kHourNs, rotation.host_stamp.ns) / 1000);
  }
  const std::int64_t sensor_ns = u.unwrap_ns(raw_us) + in_hour % 1000;
  const Mapping m = lidar_clock_.model().observe(sensor_ns, rotation.host_stamp);
  note(SensorKind::Lidar3d, m, rotation.host_stamp);
  LidarRotation r;
  r.index = rotation.index;
  r.start = m.mapped;
  float last = 0.F;
  for (const LidarPoint& p : rotation.points) last = std::max(last, p.time_s);
  r.end = Stamp{r.start.ns + static_cast<std::int64_t>(std::llround(static_cast<double>(last) * 1e9))};
  r.host = rotation.host_stamp;
  r.last_host = rotation.last_host_stamp;
  r.partial = rotation.partial;
  r.points = std::move(rotation.points);
  const std::uint64_t late = assembler_.counters().late_rotations;
  assembler_.add_rotation(std::move(r));
  health_.errors(SensorKind::Lidar3d).late += assembler_.counters().late_rotations - late;
}

void Synchronizer::push_scan(scip::Scan&& scan, Stamp host) {
  const Mapping m = scan_clock_.observe_raw(scan.timestamp_ms, host);
  note(SensorKind::Scan2d, m, host);
  const std::uint64_t late = assembler_.counters().late_samples;
  assembler_.add_scan(TimedScan{m.mapped, host, std::move(scan)});
  health_.errors(SensorKind::Scan2d).late += assembler_.counters().late_samples - late;
}

void Synchronizer::push_gnss(nmea::Sentence&& sentence, Stamp host) {
  Stamp time;
  if (const auto utc = utc_of(sentence); utc && *utc >= 0.0 && *utc < 86'401.0) {
    const auto ns_of_day = static_cast<std::int64_t>(std::llround(*utc * 1e9));
    WrapUnwrapper& u = gnss_clock_.unwrapper();
    if (gnss_clock_.model().pairs() == 0 && u.wraps() == 0) {
      // The date from RMC when the first sentence carries it, otherwise the UTC day nearest the host clock.
      const auto* rmc = std::get_if<nmea::Rmc>(&sentence);
      if (rmc != nullptr && rmc->year && rmc->month && rmc->day) {
        u.seed_base(days_from_civil(*rmc->year, static_cast<unsigned>(*rmc->month), static_cast<unsigned>(*rmc->day)) *
                    kDayNs);
      } else {
        u.seed_base(nearest_period_start(ns_of_day, kDayNs, host.ns));
      }
    }
    const std::int64_t sensor_ns = u.unwrap_ns(static_cast<std::uint64_t>(ns_of_day));
    const Mapping m = gnss_clock_.model().observe(sensor_ns, host);
    note(SensorKind::Gnss, m, host);
    time = m.mapped;
    // A PPS-synchronised 3D LiDAR keeps UTC too, and its packets reach the host within a millisecond: its
    // model maps UTC onto the host clock without the receiver's output latency (tens of ms after the epoch,
    // unknown, which the GNSS's own lower envelope would add to every fix and so shift every position back
    // along the track by speed x latency).
    // Only while the two agree to within a receiver's latency: a LiDAR without PPS counts from its power-on.
    if (params_.gnss_utc_via_lidar && lidar_clock_.model().has_model()) {
      const Stamp via = lidar_clock_.model().map(sensor_ns);
      const double latency_s = static_cast<double>(m.mapped.ns - via.ns) * 1e-9;
      if (latency_s > -0.05 && latency_s < params_.max_gnss_latency_s) {
        time = via;
        ++gnss_via_lidar_;
      }
    }
    last_fix_time_ = time;
    last_fix_host_ = host;
  } else {
    // VTG/HDT/THS carry no time: they belong to the epoch of the fix just before them.
    health_.sample(SensorKind::Gnss, host);
    const auto pairing = static_cast<std::int64_t>(std::llround(params_.untimed_pairing_s * 1e9));
    if (!last_fix_host_ || host.ns - last_fix_host_->ns > pairing || host < *last_fix_host_) {
      ++health_.errors(SensorKind::Gnss).untimed;
      return;
    }
    time = *last_fix_time_;
  }
  const std::uint64_t late = assembler_.counters().late_samples;
  assembler_.add_gnss(TimedGnss{time, host, std::move(sentence)});
  health_.errors(SensorKind::Gnss).late += assembler_.counters().late_samples - late;
}

void Synchronizer::push_ahrs(xsens::MtData2&& data, Stamp host) {
  if (!data.sample_time_fine) {
    health_.sample(SensorKind::Ahrs, host);
    ++health_.errors(SensorKind::Ahrs).untimed;
    return;
  }
  const Mapping m = ahrs_clock_.observe_raw(*data.sample_time_fine, host);
  note(SensorKind::Ahrs, m, host);
  const std::uint64_t late = assembler_.counters().late_samples;
  assembler_.add_attitude(TimedAttitude{m.mapped, host, std::move(data)});
  health_.errors(SensorKind::Ahrs).late += assembler_.counters().late_samples - late;
}

void Synchronizer::poll(Stamp now, std::vector<SyncedFrame>& out) { assembler_.poll(now, out); }
void Synchronizer::finish(std::vector<SyncedFrame>& out) { assembler_.finish(out); }

std::optional<SensorKind> Synchronizer::waiting_for(Stamp now) const {
  if (const auto end = assembler_.oldest_pending_end()) {
    const auto grace = static_cast<std::int64_t>(std::llround(params_.waiting_grace_s * 1e9));
    if (now.ns - end->ns > grace) return assembler_.waiting_for();
    return std::nullopt;
  }
  const auto age = health_.age_s(SensorKind::Lidar3d, now);
  if (!age || *age > 2.0 / params_.assembler.rate_hz) return SensorKind::Lidar3d;
  return std::nullopt;
}

std::string Synchronizer::status(Stamp now) const {
  const AssemblerCounters& c = assembler_.counters();
  return health_.status_line(now, waiting_for(now), c.frames, c.frames - c.complete);
}

}  // namespace fieldguard::sync
