#include "sim/session.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <vector>

#include "fieldguard/drivers/scip_session.hpp"
#include "fieldguard/io/byte_log.hpp"
#include "nav_encode.hpp"
#include "scip_sensor.hpp"
#include "sim/raycaster.hpp"
#include "sim/rng.hpp"

namespace fieldguard::sim {

namespace {

constexpr std::uint64_t kGnssStream = 0x6e55;
constexpr std::uint64_t kAhrsStream = 0xa385;
constexpr std::uint64_t kScanStream = 0x5c1b;
constexpr double kSerialBytesPerS = 115200.0 / 10.0;  // 8N1 at 115200 baud
// Crystal errors of the sensors' own clocks (typical +-50 ppm parts), and their counters at time 0.
constexpr double kAhrsDriftPpm = 20.0;
constexpr std::uint64_t kAhrsFineAtZero = 3'600'000'000ULL;  // 100 h after power-on: wraps after ~7 min
constexpr double kScanDriftPpm = -35.0;
constexpr std::uint64_t kScanMsAtZero = 16'700'000;  // wraps (24 bits) after ~77 s

std::int64_t to_ns(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }

// v with `decimals` digits after the point.
std::string fmt(int decimals, double v) { return tools::fixed_text(decimals, v); }

// Exact "s.nnnnnnnnn" of a Unix time in ns.
std::string stamp_text(std::int64_t ns) {
  char buf[40];
  const int n = std::snprintf(buf, sizeof buf, "%lld.%09lld", static_cast<long long>(ns / 1000000000),
                              static_cast<long long>(ns % 1000000000));
  return {buf, static_cast<std::size_t>(std::max(n, 0))};
}

std::string vec_text(Vec3 v) { return "[" + fmt(4, v.x) + ", " + fmt(4, v.y) + ", " + fmt(4, v.z) + "]"; }

double wrap_deg(double a) {
  a = std::fmod(a, 360.0);
  if (a <= -180.0) a += 360.0;
  if (a > 180.0) a -= 360.0;
  return a;
}

// A byte log whose records must come in time order (as record writes them).
class Log {
 public:
  bool open(const std::string& path, const std::string& source, std::string& error) {
    auto w = io::ByteLogWriter::create(path, source);
    if (!w) {
      error = w.error();
      return false;
    }
    writer_.emplace(std::move(*w));
    path_ = path;
    return true;
  }
  bool write(std::int64_t host_ns, io::Direction dir, const void* data, std::size_t n, std::string& error) {
    host_ns = std::max(host_ns, last_ns_ + 1);  // a host clock never runs backwards within one reader thread
    last_ns_ = host_ns;
    const auto* b = static_cast<const std::uint8_t*>(data);
    if (!writer_->write(Stamp{host_ns}, dir, ByteSpan(b, n))) {
      error = "cannot write " + path_;
      return false;
    }
    return true;
  }
  bool close(std::string& error) {
    if (!writer_->flush()) {
      error = "cannot write " + path_;
      return false;
    }
    writer_.reset();
    return true;
  }

 private:
  std::optional<io::ByteLogWriter> writer_;
  std::string path_;
  std::int64_t last_ns_ = 0;
};

std::string target_name(const Scene& scene, std::int64_t target) {
  if (target == RayCaster::kNone) return "none";
  if (target == RayCaster::kTerrain) return "terrain";
  if (target >= 0 && static_cast<std::size_t>(target) < scene.objects.size())
    return scene.objects[static_cast<std::size_t>(target)].id;
  if (target >= 0 && static_cast<std::size_t>(target) < scene.objects.size() + scene.crops.size()) return "crop";
  return "body";
}

// Gauss-Markov noise: correlated over tau_s, standard deviation sigma.
class Markov {
 public:
  Markov(double sigma, double tau_s, double dt_s) : sigma_(sigma), a_(std::exp(-dt_s / tau_s)) {}
  double next(Rng& rng) {
    if (!started_) {
      started_ = true;
      value_ = sigma_ * rng.normal();
    } else {
      value_ = a_ * value_ + std::sqrt(1.0 - a_ * a_) * sigma_ * rng.normal();
    }
    return value_;
  }

 private:
  double sigma_;
  double a_;
  double value_ = 0.0;
  bool started_ = false;
};

struct Context {
  const Scene& scene;
  const SessionSettings& s;
  FieldPlacement place;
  std::ofstream& truth;
  SessionCounts& counts;
  std::string& error;
};

bool write_gnss(Context& c) {
  Log log;
  if (!log.open(c.s.dir + "/gnss.log", "gnss /dev/ttyUSB0 115200 (fieldguard-sim)", c.error)) return false;
  Rng rng(c.s.seed, kGnssStream);
  const double dt = 1.0 / c.s.gnss_rate_hz;
  Markov ex(c.s.gnss_sigma_m, 3.0, dt);
  Markov ey(c.s.gnss_sigma_m, 3.0, dt);
  Markov ez(2.0 * c.s.gnss_sigma_m, 3.0, dt);
  for (std::uint64_t k = 0;; ++k) {
    const double t = static_cast<double>(k) * dt;
    if (t >= c.s.duration_s) break;
    const std::int64_t utc_ns = c.s.start_time_ns + to_ns(t);
    const SensorPose pose = c.scene.pose_at(t);
    const VehiclePose v = vehicle_pose(c.scene, pose);
    const Vec3 antenna = v.origin + v.rot * c.s.antenna;
    const Geodetic truth = c.place.to_geodetic(antenna);
    const Geodetic meas = c.place.to_geodetic(antenna + Vec3{ex.next(rng), ey.next(rng), ez.next(rng)});
    const double speed = c.scene.travel_at(t).second;
    const double heading_true = std::fmod(c.s.field_heading_deg + 360.0, 360.0);
    const double heading_meas = std::fmod(heading_true + c.s.heading_sigma_deg * rng.normal() + 360.0, 360.0);
    tools::GnssEpoch epoch;
    epoch.utc_ns = utc_ns;
    epoch.lat_deg = meas.lat_deg;
    epoch.lon_deg = meas.lon_deg;
    epoch.h_m = meas.h_m;
    epoch.geoid_separation_m = c.s.geoid_separation_m;
    epoch.satellites = 16 + static_cast<int>(rng.uniform() * 5.0);
    epoch.speed_mps = std::max(0.0, speed + 0.02 * rng.normal());
    if (speed > 0.1) epoch.course_deg = heading_true;
    epoch.heading_deg = heading_meas;
    const std::vector<std::string> sentences = tools::nmea_epoch(epoch);
    // The receiver prints its solution 20-40 ms after the epoch, then the bytes cross the serial line.
    double host_s = t + 0.020 + 0.020 * rng.uniform();
    for (const std::string& line : sentences) {
      host_s += static_cast<double>(line.size()) / kSerialBytesPerS;
      if (!log.write(c.s.start_time_ns + to_ns(host_s), io::Direction::FromSensor, line.data(), line.size(), c.error))
        return false;
    }
    c.truth << "{\"sensor\": \"gnss\", \"stamp\": " << stamp_text(utc_ns)
            << ", \"antenna\": {\"lat_deg\": " << fmt(10, truth.lat_deg) << ", \"lon_deg\": " << fmt(10, truth.lon_deg)
            << ", \"h_m\": " << fmt(4, truth.h_m) << "}, \"antenna_world\": " << vec_text(antenna)
            << ", \"heading_deg\": " << fmt(3, heading_true) << ", \"speed_mps\": " << fmt(3, speed) << "}\n";
    ++c.counts.gnss_epochs;
  }
  return log.close(c.error);
}

bool write_ahrs(Context& c) {
  Log log;
  if (!log.open(c.s.dir + "/ahrs.log", "ahrs /dev/ttyUSB1 115200 (fieldguard-sim)", c.error)) return false;
  Rng rng(c.s.seed, kAhrsStream);
  const double dt = 1.0 / c.s.ahrs_rate_hz;
  for (std::uint64_t k = 0;; ++k) {
    const double t = static_cast<double>(k) * dt;
    if (t >= c.s.duration_s) break;
    const SensorPose pose = c.scene.pose_at(t);
    const double yaw = wrap_deg(c.place.enu_yaw_deg());
    const auto counter = static_cast<std::uint16_t>(k & 0xFFFFU);
    const auto fine = static_cast<std::uint32_t>(
        (kAhrsFineAtZero + static_cast<std::uint64_t>(std::llround(t * (1.0 + kAhrsDriftPpm * 1e-6) * 10000.0))) &
        0xFFFFFFFFULL);
    tools::AhrsSample sample;
    sample.packet_counter = counter;
    sample.sample_time_fine = fine;
    sample.roll_deg = pose.roll_deg + c.s.ahrs_sigma_deg * rng.normal();
    sample.pitch_deg = pose.pitch_deg + c.s.ahrs_sigma_deg * rng.normal();
    sample.yaw_deg = wrap_deg(yaw + 0.1 * rng.normal());
    const std::vector<std::uint8_t> frame = tools::mtdata2_frame(sample);
    const double host_s = t + static_cast<double>(frame.size()) / kSerialBytesPerS + 0.001 + 0.001 * rng.uniform();
    if (!log.write(c.s.start_time_ns + to_ns(host_s), io::Direction::FromSensor, frame.data(), frame.size(), c.error))
      return false;
    const VehiclePose v = vehicle_pose(c.scene, pose);
    c.truth << "{\"sensor\": \"ahrs\", \"stamp\": " << stamp_text(c.s.start_time_ns + to_ns(t))
            << ", \"packet_counter\": " << counter << ", \"sample_time_fine\": " << fine
            << ", \"roll_deg\": " << fmt(4, pose.roll_deg) << ", \"pitch_deg\": " << fmt(4, pose.pitch_deg)
            << ", \"yaw_deg\": " << fmt(4, yaw) << ", \"vehicle_world\": " << vec_text(v.origin) << "}\n";
    ++c.counts.ahrs_samples;
  }
  return log.close(c.error);
}

bool write_scan2d(Context& c) {
  Log log;
  if (!log.open(c.s.dir + "/scan2d.log", "scan2d scip 192.168.0.10:10940 (fieldguard-sim)", c.error)) return false;
  Rng rng(c.s.seed, kScanStream);
  const Scene& scene = c.scene;
  const MotionParams& m = scene.motion;
  // The scanner in the LiDAR's sensor frame (the body is there) and its rays in that frame.
  const Vec3 origin_s = c.s.scan2d.position - Vec3{m.lidar_forward_m, 0.0, m.sensor_height_m};
  const Mat3 mount =
      attitude(c.s.scan2d.roll_deg * kDegToRad, c.s.scan2d.pitch_deg * kDegToRad, c.s.scan2d.yaw_deg * kDegToRad);
  std::vector<Vec3> dirs(utm30::kSteps);
  std::vector<CastHit> body(utm30::kSteps);
  for (int i = 0; i < utm30::kSteps; ++i) {
    const double a = (i - utm30::kFrontStep) * utm30::kStepDeg * kDegToRad;  // counter-clockwise, 0 ahead
    dirs[static_cast<std::size_t>(i)] = {std::cos(a), std::sin(a), 0.0};
    const Ray ray{origin_s, mount * dirs[static_cast<std::size_t>(i)]};
    CastHit& h = body[static_cast<std::size_t>(i)];
    h.range_m = utm30::kMaxRangeM;
    Span span;
    for (const Primitive& p : scene.body) {
      if (intersect(p, ray, h.range_m, span) && span.t_in > 0.0) {
        h.range_m = span.t_in;
        h.target = static_cast<std::int64_t>(scene.objects.size() + scene.crops.size());
        h.cos_incidence = std::abs(dot(span.normal, ray.dir));
      }
    }
  }

  // Start-up as the daemon's own client runs it (SCIP2.0, VV, PP, II, BM, MD), answered by the sensor.
  scip::Session client;
  tools::ScipSensor sensor;
  double host_s = -0.5;
  std::string send = client.connect();
  while (!send.empty()) {
    if (!log.write(c.s.start_time_ns + to_ns(host_s), io::Direction::ToSensor, send.data(), send.size(), c.error))
      return false;
    std::string line = send;
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    const std::string reply = sensor.reply(line);
    host_s += 0.002 + 0.001 * rng.uniform();
    if (!log.write(c.s.start_time_ns + to_ns(host_s), io::Direction::FromSensor, reply.data(), reply.size(), c.error))
      return false;
    const scip::SessionEvents ev =
        client.on_bytes(ByteSpan(reinterpret_cast<const std::uint8_t*>(reply.data()), reply.size()));
    if (!ev.refusals.empty()) {
      c.error = "the simulated scanner refused the client's start-up";
      return false;
    }
    send = ev.send;
    host_s += 0.001;
  }
  if (!sensor.streaming()) {
    c.error = "the client's start-up did not start MD streaming";
    return false;
  }

  RayCaster caster(scene);
  SceneObject moving;
  std::vector<Aabb> swept(scene.objects.size());
  std::vector<std::uint32_t> ranges(static_cast<std::size_t>(sensor.last_step() - sensor.first_step() + 1));
  const double step_s = utm30::kScanPeriodS / 1440.0;
  for (std::uint64_t j = 0;; ++j) {
    const double t0 = static_cast<double>(j) * utm30::kScanPeriodS;
    if (t0 >= c.s.duration_s) break;
    const double t_mid = t0 + 0.5 * (utm30::kSteps - 1) * step_s;
    for (std::size_t i = 0; i < scene.objects.size(); ++i) swept[i] = scene.objects[i].bounds;
    const SceneObject* moving_ptr = nullptr;
    if (scene.pedestrian) {
      scene.pedestrian->parts_at(t_mid, scene.terrain, moving.parts);
      moving.bounds = Aabb{};
      for (const Primitive& p : moving.parts) moving.bounds.add(bounds(p));
      swept[scene.pedestrian_index] = moving.bounds;
      moving_ptr = &moving;
    }
    const SensorPose mid = scene.pose_at(t_mid);
    const Vec3 scanner_mid = mid.position + mid.rot * origin_s;
    caster.prepare(scanner_mid, std::abs(m.speed_mps) * utm30::kScanPeriodS + 0.1, swept);
    double front_range = 0.0;
    std::int64_t front_target = RayCaster::kNone;
    for (int i = sensor.first_step(); i <= sensor.last_step(); ++i) {
      const SensorPose p = scene.pose_at(t0 + i * step_s);
      SensorPose sp;
      sp.position = p.position + p.rot * origin_s;
      sp.rot = p.rot * mount;
      const auto idx = static_cast<std::size_t>(i);
      const CastHit hit = caster.cast(sp, dirs[idx], body[idx], rng, moving_ptr);
      const double noise = rng.normal();
      const double u_drop = rng.uniform();
      std::uint32_t value = 1;  // no echo (an error code below DMIN)
      if (hit.target != RayCaster::kNone && hit.range_m < utm30::kMaxRangeM) {
        const double p_drop = 0.003 + (hit.cos_incidence < 0.05 ? 0.5 : 0.0);
        const double r = hit.range_m + c.s.scan2d_sigma_m * noise;
        if (u_drop >= p_drop && r >= 0.023) value = static_cast<std::uint32_t>(std::lround(r * 1000.0));
      }
      ranges[static_cast<std::size_t>(i - sensor.first_step())] = value;
      if (i == utm30::kFrontStep) {
        front_range = hit.range_m;
        front_target = hit.target;
      }
    }
    const auto ms = static_cast<std::uint32_t>(
        (kScanMsAtZero + static_cast<std::uint64_t>(std::floor(t0 * (1.0 + kScanDriftPpm * 1e-6) * 1000.0))) &
        0xFFFFFFU);
    const std::string reply = sensor.scan(ranges, {}, ms);
    // Sent when the last step is measured (18.75 ms into the 25 ms turn); 1-3 ms through the network stack.
    const double host = t0 + utm30::kSteps * step_s + 0.001 + 0.002 * rng.uniform();
    if (!log.write(c.s.start_time_ns + to_ns(host), io::Direction::FromSensor, reply.data(), reply.size(), c.error))
      return false;
    const SensorPose p0 = scene.pose_at(t0);
    c.truth << "{\"sensor\": \"scan2d\", \"stamp\": " << stamp_text(c.s.start_time_ns + to_ns(t0))
            << ", \"timestamp_ms\": " << ms << ", \"scanner_world\": " << vec_text(p0.position + p0.rot * origin_s)
            << ", \"roll_deg\": " << fmt(4, p0.roll_deg) << ", \"pitch_deg\": " << fmt(4, p0.pitch_deg)
            << ", \"front_range_m\": " << fmt(4, front_range) << ", \"front_target\": \""
            << target_name(scene, front_target) << "\"}\n";
    ++c.counts.scans;
  }
  return log.close(c.error);
}

}  // namespace

VehiclePose vehicle_pose(const Scene& scene, const SensorPose& sensor) {
  // The sensor's axes are the vehicle's (the simulator mounts it level and straight ahead).
  const Vec3 lidar{scene.motion.lidar_forward_m, 0.0, scene.motion.sensor_height_m};
  return {sensor.position - sensor.rot * lidar, sensor.rot};
}

bool write_session(const Scene& scene, const SessionSettings& s, SessionCounts& counts, std::string& error) {
  std::error_code ec;
  std::filesystem::create_directories(s.dir, ec);
  if (ec) {
    error = "cannot create " + s.dir + ": " + ec.message();
    return false;
  }
  const std::string truth_path = s.dir + "/pose.truth.jsonl";
  std::ofstream truth(truth_path, std::ios::binary | std::ios::trunc);
  if (!truth) {
    error = "cannot create " + truth_path;
    return false;
  }
  Context c{scene, s, FieldPlacement(s.origin, s.field_heading_deg), truth, counts, error};
  // The header: where the field is, how the sensors sit, and the real objects in world and geodetic terms.
  truth << "{\"session\": {\"start\": " << stamp_text(s.start_time_ns) << ", \"duration_s\": " << fmt(6, s.duration_s)
        << ", \"origin\": {\"lat_deg\": " << fmt(8, s.origin.lat_deg) << ", \"lon_deg\": " << fmt(8, s.origin.lon_deg)
        << ", \"h_m\": " << fmt(3, s.origin.h_m) << "}, \"field_heading_deg\": " << fmt(3, s.field_heading_deg)
        << ", \"ahrs_yaw_deg\": " << fmt(3, wrap_deg(c.place.enu_yaw_deg()))
        << ", \"geoid_separation_m\": " << fmt(3, s.geoid_separation_m)
        << ", \"antenna_vehicle\": " << vec_text(s.antenna)
        << ", \"lidar_vehicle\": " << vec_text({scene.motion.lidar_forward_m, 0.0, scene.motion.sensor_height_m})
        << ", \"scan2d_vehicle\": " << vec_text(s.scan2d.position)
        << ", \"scan2d_rpy_deg\": " << vec_text({s.scan2d.roll_deg, s.scan2d.pitch_deg, s.scan2d.yaw_deg})
        << ", \"objects\": [";
  bool first = true;
  for (const SceneObject& o : scene.objects) {
    if (is_terrain(o.cls) || (scene.pedestrian && &o == &scene.objects[scene.pedestrian_index])) continue;
    const Vec3 centre = o.bounds.center();
    const Geodetic g = c.place.to_geodetic({centre.x, centre.y, o.bounds.min.z});
    truth << (first ? "" : ", ") << "{\"id\": \"" << o.id << "\", \"class\": \"" << to_string(o.cls)
          << "\", \"world_min\": " << vec_text(o.bounds.min) << ", \"world_max\": " << vec_text(o.bounds.max)
          << ", \"base_lat_deg\": " << fmt(10, g.lat_deg) << ", \"base_lon_deg\": " << fmt(10, g.lon_deg)
          << ", \"base_h_m\": " << fmt(4, g.h_m) << "}";
    first = false;
  }
  truth << "]}}\n";
  if (!write_gnss(c) || !write_ahrs(c) || !write_scan2d(c)) return false;
  truth.close();
  if (!truth) {
    error = "cannot write " + truth_path;
    return false;
  }
  return true;
}

}  // namespace fieldguard::sim
