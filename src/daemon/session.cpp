#include "daemon/session.hpp"

#include <pthread.h>

#include <algorithm>
#include <boost/asio/post.hpp>
#include <cstdio>
#include <optional>
#include <span>

#include "daemon/source_options.hpp"
#include "fieldguard/core/alloc_count.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"
#include "fieldguard/engine/stage_times.hpp"
#include "fieldguard/output/can_speed.hpp"
#include "fieldguard/perception/pipeline.hpp"
#include "fieldguard/sync/synchronizer.hpp"

namespace fieldguard::app {
namespace {

namespace safety = output::safety;

constexpr auto kStatusEvery = std::chrono::seconds(1);

sync::SensorKind kind_of(safety::Sensor s) {
  switch (s) {
    case safety::Sensor::Lidar: return sync::SensorKind::Lidar3d;
    case safety::Sensor::Scan2d: return sync::SensorKind::Scan2d;
    case safety::Sensor::Gnss: return sync::SensorKind::Gnss;
    case safety::Sensor::Ahrs: return sync::SensorKind::Ahrs;
  }
  return sync::SensorKind::Lidar3d;
}

// Whether the configuration switches the sensor's source on (the 3D LiDAR always is).
bool enabled(const Config& cfg, safety::Sensor s) {
  switch (s) {
    case safety::Sensor::Lidar: return true;
    case safety::Sensor::Scan2d: return cfg.scan2d.enabled;
    case safety::Sensor::Gnss: return cfg.gnss.serial.enabled;
    case safety::Sensor::Ahrs: return cfg.ahrs.serial.enabled;
  }
  return true;
}

}  // namespace

Session::Session(boost::asio::io_context& io, Config cfg, CanLink& link, SystemdNotifier& notify, bool& ready)
    : io_(io),
      cfg_(std::move(cfg)),
      notify_(notify),
      ready_(ready),
      stage_(cfg_, link),
      fusion_(cfg_, FusionInputs::enabled_in(cfg_)),
      detectors_(cfg_, static_cast<std::size_t>(cfg_.pipeline.workers)),
      pool_(pool_params(cfg_, io, waker_), [this](FrameJob& j, DetectedFrame& d) { process(j, d); }),
      submitted_(pool_.slots()) {
  waker_->session = this;
}

Session::~Session() {
  stop();
  waker_->session = nullptr;  // a wake-up still queued on the io thread finds nobody
}

std::uint16_t Session::lidar_port(lidar3d::Channel channel) const {
  const auto& u = udp_[static_cast<std::size_t>(channel)];
  return u ? u->local_port() : 0;
}

void Session::start() {
  const Stamp now = wall_clock_now();
  // The ports of the configured model; all three while it is to be found out (auto).
  const lidar3d::Model model = cfg_.lidar.model;
  struct Listen {
    lidar3d::Channel channel;
    std::uint16_t port;
    lidar3d::Family family;
  };
  const std::array<Listen, 3> channels = {{
      {lidar3d::Channel::VelodyneData, cfg_.lidar.data_port, lidar3d::Family::Velodyne},
      {lidar3d::Channel::Msop, cfg_.lidar.msop_port, lidar3d::Family::RoboSense},
      {lidar3d::Channel::Difop, cfg_.lidar.difop_port, lidar3d::Family::RoboSense},
  }};
  std::string ports;
  for (const auto& [channel, port, family] : channels) {
    if (!lidar3d::listens_for(model, family)) continue;
    io::UdpReceiverOptions o;
    o.port = port;
    auto& u = udp_[static_cast<std::size_t>(channel)];
    u = std::make_unique<io::UdpReceiver>(io_, o, [this, c = channel](const io::UdpDatagram& d) { on_datagram(c, d); });
    u->start();
    static constexpr std::array<const char*, 3> kNames = {"Velodyne data", "RS-32 MSOP", "RS-32 DIFOP"};
    ports += (ports.empty() ? "" : ", ") + std::to_string(u->local_port()) + " (" +
             kNames[static_cast<std::size_t>(channel)] + ")";
  }
  if (view_wanted_) {
    view_ = std::make_unique<LiveView>(cfg_);  // throws when the recording or the port cannot be opened
    if (!cfg_.view.mcap_path.empty()) {
      log_->info("recording to {} (MCAP, files of at most {} MB, the newest {} kept)", cfg_.view.mcap_path,
                 cfg_.view.mcap_max_mb, cfg_.view.mcap_max_files);
    }
    if (const auto port = view_->port()) {
      log_->info("live view on http://{}:{}/ (status page; Foxglove: ws://{}:{})", cfg_.view.address, *port,
                 cfg_.view.address, *port);
    }
  }
  log_->info("listening for the 3D LiDAR on udp port {}, model {}; {}", ports, lidar3d::to_string(model),
             fusion_.fused() ? "frames fused from every enabled sensor at " + std::to_string(cfg_.sync.rate_hz) + " Hz"
                             : std::string("one frame per rotation"));
  if (cfg_.scan2d.enabled) {
    const io::ScipSourceOptions so = scip_source_options(cfg_.scan2d);
    scip_ = std::make_unique<io::ScipSource>(
        io_, so,
        [this](const scip::Scan& scan, const scip::Geometry&, Stamp t) {
          heard(safety::Sensor::Scan2d, t);
          fusion_.scan(scan, t, jobs_);
          submit_jobs();
        },
        [this](bool trouble, const std::string& w) {
          log_->log(trouble ? spdlog::level::warn : spdlog::level::info, "scan2d: {}", w);
        });
    scip_->start();
  }
  // GNSS and AHRS count as heard when their bytes arrive; the bytes go to the frame maker.
  auto serial = [&](const SerialConfig& c, safety::Sensor s, const char* name) {
    if (!c.enabled) return;
    serial_.push_back(std::make_unique<io::SerialReader>(
        io_, serial_options(c),
        [this, s](ByteSpan bytes, Stamp t) {
          heard(s, t);
          if (s == safety::Sensor::Gnss) {
            fusion_.gnss(bytes, t, jobs_);
          } else {
            fusion_.ahrs(bytes, t, jobs_);
          }
          submit_jobs();
        },
        [this, name](io::SerialState st, const std::string& why) {
          // Open is good news; closed (lost, cannot open) and silent are what an operator must see.
          log_->log(st == io::SerialState::Open ? spdlog::level::info : spdlog::level::warn, "{}: {}", name, why);
        }));
    serial_.back()->start();
  };
  serial(cfg_.gnss.serial, safety::Sensor::Gnss, "gnss");
  serial(cfg_.ahrs.serial, safety::Sensor::Ahrs, "ahrs");
  if (cfg_.can.speed != SpeedInput::None) start_speed_input();
  stage_.tick(now, 0);
}

void Session::start_speed_input() {
  const bool ccvs1 = cfg_.can.speed == SpeedInput::Ccvs1;
  const std::uint32_t pgn = ccvs1 ? output::kPgnCcvs1 : output::kPgnIsoWheelBasedSpeed;
  // The PGN sits in bits 8..25 of the 29-bit identifier; any priority, any sender.
  const std::vector<io::CanFilter> filters{io::CanFilter{pgn << 8, 0x03FFFF00}};
  auto fd = io::CanReader::open_socket(cfg_.can.interface, filters);
  if (!fd) {
    log_->warn("tractor speed ({}): {}; the stop zone keeps its full-speed length", ccvs1 ? "CCVS1" : "ISO wheel-based",
               fd.error());
    return;
  }
  can_in_ = std::make_unique<io::CanReader>(
      io_, *fd, filters, [this, ccvs1](std::uint32_t id, std::span<const std::uint8_t> data, Stamp t) {
        auto v = output::decode_speed(id, data);
        const auto want = ccvs1 ? output::SpeedSource::Ccvs1 : output::SpeedSource::IsoWheelBased;
        if (v && v->source == want) {
          stage_.vehicle_speed(v->speed_mps, t);
        } else if (!v && v.error() != output::SpeedError::OtherPgn && speed_errors_++ == 0) {
          log_->warn("tractor speed: {} (counted; the zone keeps its full-speed length while no speed is known)",
                     output::to_string(v.error()));
        }
      });
  can_in_->start();
  log_->info("reading the tractor's speed ({}) on {}", ccvs1 ? "CCVS1" : "ISO wheel-based", cfg_.can.interface);
}

void Session::stop() {
  if (stopped_) return;
  stopped_ = true;
  for (auto& u : udp_) {
    if (u) u->stop();
  }
  if (scip_) scip_->stop();
  if (can_in_) can_in_->stop();
  for (auto& s : serial_) s->stop();
  pool_.stop(sync::Drain::No);
  pool_.poll([this](const Pool::Result& r) { deliver(r); });
}

void Session::on_results() {
  const alloc::Scope frame_path(alloc::Path::Frame);
  pass_problems();
  pool_.poll([this](const Pool::Result& r) { deliver(r); });
}

void Session::on_tick(std::chrono::nanoseconds late) {
  // Periodic work (the status line, heartbeats, timeouts) is no frame's: not counted, but for the frames it
  // delivers and submits (their own scopes).
  const alloc::Scope periodic(alloc::Path::None);
  io_gap_.add(late.count());
  if (!worker_refusal_logged_) {
    if (std::string refused = pool_.thread_refusal(); !refused.empty()) {
      worker_refusal_logged_ = true;
      log_->warn(
          "realtime: the perception workers run without what the system refused ({}); detection goes on at "
          "normal priority",
          refused);
    }
  }
  pass_problems();
  pool_.poll([this](const Pool::Result& r) { deliver(r); });
  const Stamp now = wall_clock_now();
  // Frames still waiting for a late sensor go out at their timeout.
  fusion_.poll(now, jobs_);
  submit_jobs();
  stage_.tick(now, lost_);
  // A decision on the clock is progress unless rotations are stuck in the pipeline: then the watchdog
  // starves and systemd restarts a daemon whose workers no longer work.
  const bool stalled = !submitted_.empty() &&
                       static_cast<double>(now.ns - submitted_.front().ns) * 1e-9 > cfg_.safety.max_frame_interval_s;
  if (stalled != stalled_) {
    stalled_ = stalled;
    if (stalled) {
      log_->error("pipeline stalled: {} rotations waiting, the oldest for {:.3f} s; no watchdog pings",
                  submitted_.size(), static_cast<double>(now.ns - submitted_.front().ns) * 1e-9);
    } else {
      log_->warn("pipeline moving again");
    }
  }
  if (!heard_all_ && stage_.started()) {
    heard_all_ = true;
    log_->info("every required sensor heard: ready");
    if (!ready_) notify_.ready(status(now));
    ready_ = true;
    last_status_ = SteadyClock::now();
  } else if (SteadyClock::now() - last_status_ >= kStatusEvery) {
    last_status_ = SteadyClock::now();
    std::string line = status(now);
    notify_.status(line);
    if (view_ && stage_.last_decision()) {
      view_->status(*stage_.last_decision(), now, view_sensors(now), std::move(line));
      view_shown_ = std::pair(stage_.last_decision()->stop, stage_.last_decision()->reason);
    }
    // With the status, and only between frames: the pool's slots a burst filled (frames released together after
    // a sensor outage) give their buffers back; a steady stream reuses no more than one per worker.
    trimmed_slots_ +=
        pool_.trim_idle(static_cast<std::size_t>(cfg_.pipeline.workers), [](FrameJob& in, DetectedFrame& out) {
          in = FrameJob{};
          out = DetectedFrame{};
        });
    // So do the spare rotation and frame buffers none took in that second.
    trimmed_spares_ += fusion_.trim_spares();
  }
  if (!stalled && ready_) notify_.progress(SteadyClock::now());
  // A change of the decision between frames (a sensor gone silent) reaches the view at once, not with the status.
  if (const auto& d = stage_.last_decision(); view_ && d && view_shown_ != std::pair(d->stop, d->reason)) {
    view_shown_ = std::pair(d->stop, d->reason);
    view_->status(*d, now, view_sensors(now), status(now));
  }
}

std::vector<ViewSensor> Session::view_sensors(Stamp now) const {
  // Silence as the safety monitor judges it (every datagram of the 3D LiDAR counts, not only whole rotations).
  std::vector<ViewSensor> out;
  for (std::size_t i = 0; i < safety::kSensorCount; ++i) {
    const auto s = static_cast<safety::Sensor>(i);
    ViewSensor v;
    v.name = safety::to_string(s);
    v.rate_hz = health_.rate_hz(kind_of(s), now);
    const Stamp last = stage_.last_data(s);
    if (!enabled(cfg_, s)) {
      v.state = "off";
    } else if (last.ns == 0) {
      v.state = "never heard";
    } else if (const double age = static_cast<double>(now.ns - last.ns) * 1e-9; age > cfg_.safety.sensor(s).timeout_s) {
      char buf[48];
      std::snprintf(buf, sizeof buf, "silent %.1f s", age);
      v.state = buf;
    } else {
      v.state = "ok";
    }
    out.push_back(std::move(v));
  }
  return out;
}

std::string Session::status(Stamp now) const {
  // The decision first, as the operator reads it ("STOP obstacle 5.4 m ahead", "GO"); then what is wrong; then
  // the detail. Before the first decision the tractor is stopped: starting up.
  const auto& d = stage_.last_decision();
  std::string line = d ? safety::headline(*d, cfg_.safety.clear_frames) : std::string("STOP starting up");
  std::string faults;
  const auto fault = [&faults](const std::string& f) { faults += (faults.empty() ? "" : ", ") + f; };
  std::uint8_t off = 0;
  char buf[128];
  // Each sensor as the page lists it: silence as the safety monitor judges it.
  const std::vector<ViewSensor> sensors = view_sensors(now);
  for (std::size_t i = 0; i < sensors.size(); ++i) {
    const auto s = static_cast<safety::Sensor>(i);
    if (sensors[i].state == "off") {
      off = static_cast<std::uint8_t>(off | sync::bit(kind_of(s)));
    } else if (sensors[i].state != "ok") {
      fault(sensors[i].name + " " + sensors[i].state + (cfg_.safety.sensor(s).required ? "" : " (not required)"));
    }
  }
  if (stalled_) fault("pipeline stalled");
  if (const sync::Synchronizer* sy = fusion_.synchronizer()) {
    if (auto w = sy->waiting_for(now)) fault("sync waiting for " + std::string(sync::to_string(*w)));
  }
  if (!faults.empty()) line += " | " + faults;
  line += " | " + health_.sensors_line(now, off);
  std::snprintf(buf, sizeof buf, " | frames %llu, incomplete %llu",
                static_cast<unsigned long long>(stage_.counts().frames),
                static_cast<unsigned long long>(fusion_.stream().counters().partial_rotations));
  line += buf;
  if (latency_.count() > 0) {
    std::snprintf(buf, sizeof buf, " | latency p99 %.2f ms (max %.2f), io gap max %.2f ms, %llu late",
                  static_cast<double>(latency_.quantile_ns(0.99)) * 1e-6, static_cast<double>(latency_.max_ns()) * 1e-6,
                  static_cast<double>(io_gap_.max_ns()) * 1e-6, static_cast<unsigned long long>(late_));
    line += buf;
  }
  if (!timed_.empty()) {
    // The last rotations' detection times (one worker's, per rotation): headroom against the frame period.
    std::vector<float> v(timed_.size());
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = timed_[i].total_us;
    const float worst = *std::max_element(v.begin(), v.end());
    std::snprintf(buf, sizeof buf, " | detection %.1f ms (max %.1f) over %zu rotations",
                  static_cast<double>(median_of(v)) * 1e-3, static_cast<double>(worst) * 1e-3, v.size());
    line += buf;
  }
  return line;
}

void Session::print_summary() const {
  const auto& c = stage_.counts();
  const auto pc = pool_.counters();
  const auto& sc = fusion_.stream().counters();
  const auto u = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
  std::printf("run summary: %s\n", cfg_.source_file.c_str());
  std::printf("  frames            %llu decided, %llu lost\n", u(c.frames), u(lost_));
  std::printf("  stop decisions    %llu stop, %llu go, %llu changes\n", u(c.stop_frames), u(c.go_frames), u(c.changes));
  if (cfg_.perception.hold.enabled) std::printf("  held obstacles    %llu (from fragments)\n", u(held_));
  std::printf("  j1939             %s\n", j1939_summary(stage_.link()).c_str());
  std::printf(
      "  pool              %llu submitted, %llu dropped, %llu refused, %llu failed; after bursts %llu slots and %llu "
      "spare buffers gave their memory back\n",
      u(pc.submitted), u(pc.dropped), u(pc.refused), u(pc.failed), u(trimmed_slots_), u(trimmed_spares_));
  std::printf("  3d lidar          %llu packets, %llu decoded, %llu bad length, %llu full rotations, %llu partial\n",
              u(sc.data_packets), u(sc.decoded), u(bad_length_), u(sc.full_rotations), u(sc.partial_rotations));
  const lidar3d::Stream& stream = fusion_.stream();
  std::printf("  3d lidar model    %s (%s); %llu refused, %llu of another family, %llu DIFOP\n",
              stream.model() ? std::string(lidar3d::to_string(*stream.model())).c_str() : "undecided",
              stream.reason().c_str(), u(sc.refused), u(sc.other_family), u(sc.info_packets));
  if (const sync::Synchronizer* sy = fusion_.synchronizer()) {
    const auto& ac = sy->assembler().counters();
    const auto& fc = fusion_.counts();
    std::printf(
        "  fused frames      %llu: %llu complete, %llu timed out, %llu overflowed, %llu late rotations dropped\n",
        u(ac.frames), u(ac.complete), u(ac.timed_out), u(ac.overflowed), u(ac.late_rotations));
    std::printf("  lacking           %llu lidar3d, %llu scan2d, %llu gnss, %llu ahrs\n", u(ac.missing[0]),
                u(ac.missing[1]), u(ac.missing[2]), u(ac.missing[3]));
    std::printf("  samples           %llu scans, %llu gnss sentences, %llu ahrs messages; errors %llu, %llu, %llu\n",
                u(fc.scans), u(fc.gnss), u(fc.ahrs), u(fc.scan_errors), u(fc.gnss_errors), u(fc.ahrs_errors));
  }
  const auto ms = [](std::int64_t ns) { return static_cast<double>(ns) * 1e-6; };
  std::printf(
      "  latency           median %.3f ms, p99 %.3f ms, max %.3f ms over %llu frames (last LiDAR "
      "packet to stop request); %llu late (over %.1f ms)\n",
      ms(latency_.quantile_ns(0.5)), ms(latency_.quantile_ns(0.99)), ms(latency_.max_ns()), u(latency_.count()),
      u(late_), cfg_.realtime.latency_budget_ms);
  if (parts_[0].count() > 0) {
    std::string line = "  latency parts    ";
    for (std::size_t i = 0; i < parts_.size(); ++i) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s %s %.3f, %.3f", i == 0 ? "" : ";", kLatencyParts[i],
                    ms(parts_[i].quantile_ns(0.5)), ms(parts_[i].quantile_ns(0.99)));
      line += buf;
    }
    std::printf("%s (median, p99 ms)\n", line.c_str());
  }
  if (view_) {
    const LiveViewCounts v = view_->counts();
    std::printf(
        "  view              %llu frames, %llu not shown (queue full); mcap %llu frames, %llu files, %.1f MB%s; "
        "server %llu connections, %llu refused, %llu messages sent, %llu dropped, %llu bad client messages\n",
        u(v.frames), u(v.dropped), u(v.mcap.frames), u(v.mcap.files), static_cast<double>(v.mcap.bytes) * 1e-6,
        v.mcap_errors != 0 ? " (failed)" : "", u(v.server.connections), u(v.server.refused), u(v.server.sent),
        u(v.server.dropped), u(v.server.bad_messages));
  }
  std::printf("  io loop           longest gap %.3f ms (a due timer waited that long for the io thread)\n",
              ms(io_gap_.max_ns()));
  if (alloc::enabled()) {
    if (warm_frame_allocs_) {
      std::printf(
          "  allocations       frame path %llu, sensor samples %llu, over the %llu frames after the first %llu "
          "(once warm)\n",
          u(alloc::count(alloc::Path::Frame) - *warm_frame_allocs_),
          u(alloc::count(alloc::Path::Samples) - *warm_sample_allocs_), u(stage_.counts().frames - warm_frames_),
          u(warm_frames_));
    } else {
      std::printf("  allocations       n/a (fewer than %llu frames decided)\n", u(kWarmFrames));
    }
  }
  if (!timed_.empty()) {
    const std::vector<perception::StageTimes> last(timed_.begin(), timed_.end());
    std::printf("  pipeline time     %s (the last %zu rotations); worst %.3f ms of all %llu\n",
                stage_times_line(last).c_str(), last.size(), static_cast<double>(worst_us_) * 1e-3, u(timed_count_));
  }
}

sync::PoolParams Session::pool_params(const Config& c, boost::asio::io_context& io, std::shared_ptr<Waker> waker) {
  sync::PoolParams p;
  p.workers = static_cast<std::size_t>(c.pipeline.workers);
  p.queue_capacity = static_cast<std::size_t>(c.pipeline.queue_capacity);
  p.drop = c.pipeline.drop == PipelineDrop::Oldest ? sync::DropPolicy::DropOldest : sync::DropPolicy::DropNewest;
  // Named so that `top -H`, a debugger and the stall test can tell the workers apart; scheduled below the io thread.
  p.worker = {"fg-perception", c.realtime.policy, c.realtime.worker_priority, c.realtime.worker_cpus};
  // A result ready: the io thread decides it now, not at the next tick of the output timer.
  p.on_result = [&io, waker = std::move(waker)] {
    if (waker->pending.exchange(true, std::memory_order_acq_rel)) return;  // a wake-up is already queued
    boost::asio::post(io, [waker] {
      waker->pending.store(false, std::memory_order_release);  // before polling: a later result posts again
      if (waker->session != nullptr) waker->session->on_results();
    });
  };
  return p;
}

void Session::process(FrameJob& j, DetectedFrame& d) {
  const alloc::Scope frame_path(alloc::Path::Frame);
  const DetectorSet::Lease detector(detectors_);
  detector->process(j, d, true, view_wanted_);
}

void Session::heard(safety::Sensor s, Stamp t) {
  stage_.sensor_data(s, t);
  health_.sample(kind_of(s), t);
}

void Session::on_datagram(lidar3d::Channel channel, const io::UdpDatagram& d) {
  const alloc::Scope frame_path(alloc::Path::Frame);
  const lidar3d::Stream& stream = fusion_.stream();
  const auto before = stream.counters().rotations();
  const lidar3d::Outcome outcome = fusion_.lidar(channel, d.payload, d.host_time, jobs_);
  switch (outcome) {
    case lidar3d::Outcome::Data:
      // Only data of the sensor in use keeps it alive: another sensor's packets, or a DIFOP alone, do not.
      stage_.sensor_data(safety::Sensor::Lidar, d.host_time);
      if (!model_logged_ && stream.model()) {
        model_logged_ = true;
        log_->info("3D LiDAR: {} ({})", lidar3d::to_string(*stream.model()), stream.reason());
      }
      break;
    case lidar3d::Outcome::BadLength:
      if (bad_length_++ == 0) {
        log_->warn("3D LiDAR: a {}-byte datagram is not a packet of its port (counted)", d.payload.size());
      }
      break;
    case lidar3d::Outcome::Refused:
      if (refused_++ == 0 && stream.refused_as()) {
        const lidar3d::MsopIdentity& id = *stream.refused_as();
        log_->error("3D LiDAR: MSOP packets of {} ({}): only the RS-LiDAR-32 is supported; refused (counted)",
                    id.name.empty() ? "an unknown sensor" : "an " + id.name, id.detail);
      }
      break;
    case lidar3d::Outcome::OtherFamily:
      if (other_family_++ == 0) {
        log_->warn("3D LiDAR: packets of another sensor family than the {} in use (counted and dropped)",
                   stream.model() ? lidar3d::to_string(*stream.model()) : "one");
      }
      break;
    default: break;
  }
  if (stream.counters().rotations() != before) health_.sample(sync::SensorKind::Lidar3d, d.host_time);
  submit_jobs();
}

void Session::pass_problems() {
  const auto p = fusion_.take_problems();
  if (p.gnss != safety::Problem::None) stage_.sensor_problem(safety::Sensor::Gnss, p.gnss);
  if (p.ahrs != safety::Problem::None) stage_.sensor_problem(safety::Sensor::Ahrs, p.ahrs);
}

void Session::submit_jobs() {
  const alloc::Scope frame_path(alloc::Path::Frame);
  for (auto& j : jobs_) {
    if (pool_.submit(j)) {
      submitted_.push_back(wall_clock_now());
      fusion_.recycle(j);  // the slot's earlier job, handed back
    } else {
      ++lost_;
    }
  }
  jobs_.clear();
}

void Session::deliver(const Pool::Result& r) {
  const alloc::Scope frame_path(alloc::Path::Frame);
  Stamp submitted;  // results come in submit order
  if (!submitted_.empty()) {
    submitted = submitted_.front();
    submitted_.pop_front();
  }
  // Stopping: what the workers finish now must not follow the last STOP onto the bus.
  if (stopped_) return;
  if (r.outcome != sync::Outcome::Processed || r.output == nullptr) {
    ++lost_;
    if (r.outcome == sync::Outcome::Failed) {
      log_->error("frame {}: detection failed: {}", r.input->synced ? r.input->synced->seq : r.input->rotation.index,
                  r.error != nullptr ? *r.error : "?");
    }
    return;
  }
  pass_problems();
  const perception::StageTimes& t = r.output->result.times;
  timed_.push_back(t);  // over the oldest once full
  worst_us_ = std::max(worst_us_, t.total_us);
  ++timed_count_;
  // Frame to frame, so here in frame order (obstacle_hold.hpp); a rotation lost in between only ages what it
  // remembers. A fused frame levelled in full gives its pose, and what the hold remembers is moved by the
  // travel and turning since; otherwise the tractor's speed from the bus, when known, widens its gate by the
  // distance driven.
  const Stamp now = wall_clock_now();
  const std::optional<perception::FramePose> pose =
      r.output->fusion ? detection_pose(*r.output->fusion, cfg_.lidar.mounting) : std::nullopt;
  held_ += hold_.apply(r.output->frame.host_stamp.ns, r.output->result, stage_.speed_at(now), pose);
  stage_.frame(r.output->frame, r.output->result, r.input->complete, now, lost_);
  // From the kernel's receive time of the frame's last 3D LiDAR packet to the write of its stop request (just done):
  // decoding, any wait of the synchronizer for another sensor, the hand-off to a worker, compensation, detection,
  // the hand-back and the safety monitor.
  const Stamp written = wall_clock_now();
  const std::int64_t latency_ns = written.ns - r.input->last_packet.ns;
  latency_.add(latency_ns);
  if (submitted.ns != 0) {  // its parts, in kLatencyParts' order
    const Stamp at[] = {r.input->last_packet,  r.input->complete,  submitted, r.output->started,
                        r.output->compensated, r.output->finished, written};
    for (std::size_t i = 0; i < parts_.size(); ++i) parts_[i].add(at[i + 1].ns - at[i].ns);
  }
  if (static_cast<double>(latency_ns) * 1e-6 > cfg_.realtime.latency_budget_ms && late_++ == 0) {
    log_->warn(
        "frame decided {:.3f} ms after its last LiDAR packet, over realtime.latency_budget_ms {} (counted; this "
        "is said once)",
        static_cast<double>(latency_ns) * 1e-6, cfg_.realtime.latency_budget_ms);
  }
  // After the stop request is written, so that showing a frame is never part of deciding it.
  if (view_ && stage_.last_decision()) {
    view_->frame(*r.output, *stage_.last_decision());
    view_shown_ = std::pair(stage_.last_decision()->stop, stage_.last_decision()->reason);
  }
  if (ready_) notify_.progress(SteadyClock::now());
  if (!warm_frame_allocs_ && stage_.counts().frames >= kWarmFrames) {
    warm_frame_allocs_ = alloc::count(alloc::Path::Frame);
    warm_sample_allocs_ = alloc::count(alloc::Path::Samples);
    warm_frames_ = stage_.counts().frames;
  }
}

}  // namespace fieldguard::app
