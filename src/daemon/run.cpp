// `fieldguard run`: the daemon. The live sources, the frame maker (SensorFusion: rotations, or fused frames
// when a 2D LiDAR, GNSS or AHRS is enabled) and the output stage share one Boost.Asio io_context on the main
// thread (the io thread); compensation and perception run on an OrderedPool of pipeline.workers threads. A
// 5 ms timer on the io thread collects finished frames in order, lets the safety monitor decide on them and,
// between frames, on the clock alone, and sends the CAN frames that are due.

#include <pthread.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/core/exit_code.hpp"
#include "fieldguard/daemon/daemon.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/engine/logging.hpp"
#include "daemon/run_stage.hpp"
#include "fieldguard/engine/samples.hpp"
#include "fieldguard/engine/stage_times.hpp"
#include "daemon/systemd_notify.hpp"
#include "daemon/source_options.hpp"
#include "fieldguard/config/config.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"
#include "fieldguard/io/can_reader.hpp"
#include "fieldguard/io/scip_source.hpp"
#include "fieldguard/io/serial_reader.hpp"
#include "fieldguard/io/udp_receiver.hpp"
#include "fieldguard/output/can_sink.hpp"
#include "fieldguard/output/can_speed.hpp"
#include "fieldguard/perception/obstacle_hold.hpp"
#include "fieldguard/perception/pipeline.hpp"
#include "fieldguard/sync/health.hpp"
#include "fieldguard/sync/ordered_pool.hpp"
#include "fieldguard/sync/synchronizer.hpp"

namespace fieldguard::app {
namespace {

namespace safety = output::safety;
using SteadyClock = std::chrono::steady_clock;


constexpr auto kTick = std::chrono::milliseconds(5);
constexpr auto kStatusEvery = std::chrono::seconds(1);

// can.sink: none. Frames are counted and go nowhere.
class NullSink final : public output::CanSink {
 public:
  void write(std::span<const output::CanFrame> frames, Stamp) override { stats_.sent += frames.size(); }
  [[nodiscard]] const output::CanSinkStats& stats() const override { return stats_; }

 private:
  output::CanSinkStats stats_;
};

// What the sink was made from: a reload keeps the open sink (and its log file) when this is unchanged.
struct SinkKey {
  CanSinkKind kind = CanSinkKind::None;
  std::string interface;
  std::string path;
  bool operator==(const SinkKey&) const = default;
};

SinkKey sink_key(const Config& cfg, const std::optional<std::string>& can_log) {
  if (can_log) return {CanSinkKind::Candump, cfg.can.interface, *can_log};
  return {cfg.can.sink, cfg.can.interface, cfg.can.sink == CanSinkKind::Candump ? cfg.can.log_path : std::string()};
}

// Throws std::runtime_error / std::invalid_argument naming what failed.
std::unique_ptr<output::CanSink> make_sink(const SinkKey& k) {
  switch (k.kind) {
    case CanSinkKind::Candump: return std::make_unique<output::CandumpLogSink>(k.path, k.interface);
    case CanSinkKind::SocketCan: {
      auto s = output::SocketCanSink::open(k.interface);
      if (!s) throw std::runtime_error(s.error());
      return std::make_unique<output::SocketCanSink>(std::move(s).value());
    }
    case CanSinkKind::None: break;
  }
  return std::make_unique<NullSink>();
}

using Pool = sync::OrderedPool<FrameJob, DetectedFrame>;

sync::SensorKind kind_of(safety::Sensor s) {
  switch (s) {
    case safety::Sensor::Lidar: return sync::SensorKind::Lidar3d;
    case safety::Sensor::Scan2d: return sync::SensorKind::Scan2d;
    case safety::Sensor::Gnss: return sync::SensorKind::Gnss;
    case safety::Sensor::Ahrs: return sync::SensorKind::Ahrs;
  }
  return sync::SensorKind::Lidar3d;
}

// One configuration's worth of daemon: its sources, its worker pool and its output stage. A reload replaces
// the whole session; the CAN sink outlives it.
class Session {
 public:
  // `ready`: READY=1 was sent (by this process, for any session): the watchdog is fed only from then on.
  Session(boost::asio::io_context& io, Config cfg, output::CanSink& sink, SystemdNotifier& notify, bool& ready)
      : io_(io),
        cfg_(std::move(cfg)),
        notify_(notify),
        ready_(ready),
        stage_(cfg_, sink),
        fusion_(cfg_, FusionInputs::enabled_in(cfg_)),
        detectors_(cfg_, static_cast<std::size_t>(cfg_.pipeline.workers)),
        pool_(pool_params(cfg_), [this](FrameJob& j) { return process(j); }) {}
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  Session(Session&&) = delete;
  Session& operator=(Session&&) = delete;
  ~Session() { stop(); }

  // Throws std::system_error when the LiDAR's port cannot be bound.
  void start() {
    const Stamp now = wall_clock_now();
    io::UdpReceiverOptions o;
    o.port = cfg_.lidar.data_port;
    udp_ = std::make_unique<io::UdpReceiver>(io_, o, [this](const io::UdpDatagram& d) { on_datagram(d); });
    udp_->start();
    log_->info("listening for the 3D LiDAR on udp port {}; {}", udp_->local_port(),
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
          [this](const std::string& w) { log_->info("scan2d: {}", w); });
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
          [this, name](io::SerialState, const std::string& why) { log_->info("{}: {}", name, why); }));
      serial_.back()->start();
    };
    serial(cfg_.gnss.serial, safety::Sensor::Gnss, "gnss");
    serial(cfg_.ahrs.serial, safety::Sensor::Ahrs, "ahrs");
    if (cfg_.can.speed != SpeedInput::None) start_speed_input();
    stage_.tick(now, 0);
  }

  // The tractor's speed off the bus sizes the stop zone. Without it (no SocketCAN, no interface) the zone
  // keeps its full-speed length: safe, so the daemon runs on and says why once.
  void start_speed_input() {
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
  // Sources closed, queued rotations discarded, the workers joined (each finishes its rotation first).
  void stop() {
    if (stopped_) return;
    stopped_ = true;
    if (udp_) udp_->stop();
    if (scip_) scip_->stop();
    if (can_in_) can_in_->stop();
    for (auto& s : serial_) s->stop();
    pool_.stop(sync::Drain::No);
    pool_.poll([this](const Pool::Result& r) { deliver(r); });
  }

  void shutdown() { stage_.shutdown(wall_clock_now()); }

  // The output timer: finished rotations in order, then a decision on the clock and the CAN cycles due.
  void on_tick() {
    pass_problems();
    pool_.poll([this](const Pool::Result& r) { deliver(r); });
    const Stamp now = wall_clock_now();
    // Frames still waiting for a late sensor go out at their timeout.
    fusion_.poll(now, jobs_);
    submit_jobs();
    stage_.tick(now, lost_);
    // A decision on the clock is progress unless rotations are stuck in the pipeline: then the watchdog
    // starves and systemd restarts a daemon whose workers no longer work.
    const bool stalled = !submitted_.empty() && static_cast<double>(now.ns - submitted_.front().ns) * 1e-9 >
                                                     cfg_.safety.max_frame_interval_s;
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
      notify_.status(status(now));
    }
    if (!stalled && ready_) notify_.progress(SteadyClock::now());
  }

  [[nodiscard]] std::string status(Stamp now) const {
    std::optional<sync::SensorKind> waiting;
    for (std::size_t i = 0; i < safety::kSensorCount && !waiting; ++i) {
      const auto s = static_cast<safety::Sensor>(i);
      const auto& p = cfg_.safety.sensor(s);
      const auto age = health_.age_s(kind_of(s), now);
      if (p.required && (!age || *age > p.timeout_s)) waiting = kind_of(s);
    }
    std::string line = health_.status_line(now, waiting, stage_.counts().frames, fusion_.stream().counters().partial_rotations);
    if (const auto& d = stage_.last_decision()) {
      line += d->stop ? " | STOP " + std::string(safety::to_string(d->reason)) : " | GO";
    }
    if (const sync::Synchronizer* sy = fusion_.synchronizer()) {
      if (auto w = sy->waiting_for(now)) line += " | sync waiting for " + std::string(sync::to_string(*w));
    }
    if (stalled_) line += " | pipeline stalled";
    if (!timed_.empty()) {
      // The last rotations' detection times (one worker's, per rotation): headroom against the frame period.
      std::vector<float> v(timed_.size());
      for (std::size_t i = 0; i < v.size(); ++i) v[i] = timed_[i].total_us;
      const float worst = *std::max_element(v.begin(), v.end());
      char buf[96];
      std::snprintf(buf, sizeof buf, " | detection %.1f ms (max %.1f) over %zu rotations",
                    static_cast<double>(median_of(v)) * 1e-3, static_cast<double>(worst) * 1e-3, v.size());
      line += buf;
    }
    return line;
  }

  // Also what tools/fieldguard-load reads: keep the labels stable.
  void print_summary() const {
    const auto& c = stage_.counts();
    const auto pc = pool_.counters();
    const auto& sc = fusion_.stream().counters();
    const auto u = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
    std::printf("run summary: %s\n", cfg_.source_file.c_str());
    std::printf("  frames            %llu decided, %llu lost\n", u(c.frames), u(lost_));
    std::printf("  stop decisions    %llu stop, %llu go, %llu changes\n", u(c.stop_frames), u(c.go_frames), u(c.changes));
    if (cfg_.perception.hold.enabled) std::printf("  held obstacles    %llu (from fragments)\n", u(held_));
    std::printf("  pool              %llu submitted, %llu dropped, %llu refused, %llu failed\n", u(pc.submitted),
                u(pc.dropped), u(pc.refused), u(pc.failed));
    std::printf("  3d lidar          %llu packets, %llu decoded, %llu bad length, %llu full rotations, %llu partial\n",
                u(sc.packets), u(sc.decoded), u(bad_length_), u(sc.full_rotations), u(sc.partial_rotations));
    if (const sync::Synchronizer* sy = fusion_.synchronizer()) {
      const auto& ac = sy->assembler().counters();
      const auto& fc = fusion_.counts();
      std::printf("  fused frames      %llu: %llu complete, %llu timed out, %llu overflowed, %llu late rotations dropped\n",
                  u(ac.frames), u(ac.complete), u(ac.timed_out), u(ac.overflowed), u(ac.late_rotations));
      std::printf("  lacking           %llu lidar3d, %llu scan2d, %llu gnss, %llu ahrs\n", u(ac.missing[0]), u(ac.missing[1]),
                  u(ac.missing[2]), u(ac.missing[3]));
      std::printf("  samples           %llu scans, %llu gnss sentences, %llu ahrs messages; errors %llu, %llu, %llu\n",
                  u(fc.scans), u(fc.gnss), u(fc.ahrs), u(fc.scan_errors), u(fc.gnss_errors), u(fc.ahrs_errors));
    }
    if (!timed_.empty()) {
      const std::vector<perception::StageTimes> last(timed_.begin(), timed_.end());
      std::printf("  pipeline time     %s (the last %zu rotations); worst %.3f ms of all %llu\n",
                  stage_times_line(last).c_str(), last.size(), static_cast<double>(worst_us_) * 1e-3, u(timed_count_));
    }
  }

  [[nodiscard]] const Config& config() const { return cfg_; }

 private:
  static sync::PoolParams pool_params(const Config& c) {
    sync::PoolParams p;
    p.workers = static_cast<std::size_t>(c.pipeline.workers);
    p.queue_capacity = static_cast<std::size_t>(c.pipeline.queue_capacity);
    p.drop = c.pipeline.drop == PipelineDrop::Oldest ? sync::DropPolicy::DropOldest : sync::DropPolicy::DropNewest;
    return p;
  }

  DetectedFrame process(FrameJob& j) {
    // Named so that `top -H`, a debugger and the stall test can tell the workers apart.
    thread_local bool named = false;
    if (!named) {
      named = true;
      pthread_setname_np(pthread_self(), "fg-perception");
    }
    const DetectorSet::Lease detector(detectors_);
    return detector->process(j);
  }

  void heard(safety::Sensor s, Stamp t) {
    stage_.sensor_data(s, t);
    health_.sample(kind_of(s), t);
  }

  void on_datagram(const io::UdpDatagram& d) {
    stage_.sensor_data(safety::Sensor::Lidar, d.host_time);
    if (d.payload.size() != velodyne::kDataPacketSize) {
      if (bad_length_++ == 0) log_->warn("3D LiDAR: a {}-byte datagram is not a data packet (counted)", d.payload.size());
      return;
    }
    const auto rotations = [this] {
      return fusion_.stream().counters().full_rotations + fusion_.stream().counters().partial_rotations;
    };
    const auto before = rotations();
    fusion_.lidar(d.payload, d.host_time, jobs_);
    if (rotations() != before) health_.sample(sync::SensorKind::Lidar3d, d.host_time);
    submit_jobs();
  }
  // Implausible GNSS / AHRS samples decoded since the last decision go to the next one.
  void pass_problems() {
    const auto p = fusion_.take_problems();
    if (p.gnss != safety::Problem::None) stage_.sensor_problem(safety::Sensor::Gnss, p.gnss);
    if (p.ahrs != safety::Problem::None) stage_.sensor_problem(safety::Sensor::Ahrs, p.ahrs);
  }
  void submit_jobs() {
    for (auto& j : jobs_) {
      if (pool_.submit(j)) {
        submitted_.push_back(wall_clock_now());
      } else {
        ++lost_;
      }
    }
    jobs_.clear();
  }
  void deliver(const Pool::Result& r) {
    if (!submitted_.empty()) submitted_.pop_front();
    // Stopping: what the workers finish now must not follow the last STOP onto the bus.
    if (stopped_) return;
    if (r.outcome != sync::Outcome::Processed || r.output == nullptr) {
      ++lost_;
      if (r.outcome == sync::Outcome::Failed) {
        log_->error("frame {}: detection failed: {}", r.input->synced ? r.input->synced->seq : r.input->rotation.index,
                    r.error ? *r.error : "?");
      }
      return;
    }
    pass_problems();
    const perception::StageTimes& t = r.output->result.times;
    if (timed_.size() == kTimedRotations) timed_.pop_front();
    timed_.push_back(t);
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
    if (ready_) notify_.progress(SteadyClock::now());
  }

  boost::asio::io_context& io_;
  const Config cfg_;
  SystemdNotifier& notify_;
  bool& ready_;
  std::shared_ptr<spdlog::logger> log_ = logger("run");
  LiveStage stage_;
  perception::ObstacleHold hold_{cfg_.perception.hold};
  std::uint64_t held_ = 0;  // obstacles the hold reported
  SensorFusion fusion_;
  sync::HealthMonitor health_;
  DetectorSet detectors_;
  Pool pool_;
  std::unique_ptr<io::UdpReceiver> udp_;
  std::unique_ptr<io::ScipSource> scip_;
  std::unique_ptr<io::CanReader> can_in_;
  std::uint64_t speed_errors_ = 0;
  std::vector<std::unique_ptr<io::SerialReader>> serial_;
  std::vector<FrameJob> jobs_;
  std::deque<Stamp> submitted_;  // submit times of the rotations not yet delivered, oldest first
  // The detection times of the status and the summary: the last 5 s at 10 Hz.
  static constexpr std::size_t kTimedRotations = 50;
  std::deque<perception::StageTimes> timed_;  // Pipeline::process()'s of the last rotations delivered, oldest first
  float worst_us_ = 0.F;                       // the longest process() of the run
  std::uint64_t timed_count_ = 0;              // rotations delivered
  std::uint64_t lost_ = 0;       // rotations dropped, refused or failed
  std::uint64_t bad_length_ = 0;
  bool heard_all_ = false;
  bool stalled_ = false;
  bool stopped_ = false;
  SteadyClock::time_point last_status_{};
};

}  // namespace

int run_daemon(const RunOptions& opt) {
  const std::string& config_path = opt.config;
  const std::optional<std::string>& can_log = opt.can_log;
  const auto log = logger("run");
  auto loaded = load_config_file(config_path);
  if (!loaded.ok()) {
    for (const auto& issue : loaded.issues) std::fprintf(stderr, "%s\n", issue.to_string().c_str());
    std::fprintf(stderr, "fieldguard run: invalid configuration %s\n", config_path.c_str());
    return kExitBadInput;
  }

  SinkKey key = sink_key(loaded.config, can_log);
  std::unique_ptr<output::CanSink> sink;
  try {
    sink = make_sink(key);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fieldguard run: CAN output: %s\n", e.what());
    return kExitBadInput;
  }
  boost::asio::io_context io;
  SystemdNotifier notify = SystemdNotifier::from_environment();
  std::unique_ptr<Session> session;
  bool ready = false;
  auto open_session = [&](const Config& cfg) {
    auto s = std::make_unique<Session>(io, cfg, *sink, notify, ready);
    s->start();
    return s;
  };
  try {
    session = open_session(loaded.config);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fieldguard run: %s\n", e.what());
    return kExitBadInput;
  }

  boost::asio::steady_timer timer(io);
  std::function<void()> arm = [&] {
    timer.expires_after(kTick);
    timer.async_wait([&](const boost::system::error_code& ec) {
      if (ec) return;
      session->on_tick();
      arm();
    });
  };
  arm();

  auto reload = [&] {
    notify.reloading();
    log->info("SIGHUP: reloading {}", config_path);
    auto fresh = load_config_file(config_path);
    if (!fresh.ok()) {
      for (const auto& issue : fresh.issues) log->error("{}", issue.to_string());
      log->error("reload refused: {} has {} error(s); the running configuration stays", config_path,
                 fresh.issues.size());
      notify.reloaded(session->status(wall_clock_now()));
      return;
    }
    const Config old = session->config();
    const SinkKey new_key = sink_key(fresh.config, can_log);
    session.reset();
    try {
      if (!(new_key == key)) {
        auto s = make_sink(new_key);
        sink = std::move(s);
        key = new_key;
      }
      session = open_session(fresh.config);
      log->info("reloaded {}: starting again from STOP, starting up", config_path);
    } catch (const std::exception& e) {
      log->error("reload failed: {}; going back to the previous configuration", e.what());
      session.reset();
      session = open_session(old);
    }
    notify.reloaded(session->status(wall_clock_now()));
  };

  boost::asio::signal_set signals(io, SIGINT, SIGTERM, SIGHUP);
  std::function<void()> wait_signal = [&] {
    signals.async_wait([&](const boost::system::error_code& ec, int sig) {
      if (ec) return;
      if (sig == SIGHUP) {
        try {
          reload();
        } catch (const std::exception& e) {
          // Even the previous configuration could not be restarted (its port was taken meanwhile).
          log->critical("reload: {}; exiting", e.what());
          io.stop();
          return;
        }
        wait_signal();
        return;
      }
      log->info("{}: stopping", sig == SIGTERM ? "SIGTERM" : "SIGINT");
      notify.stopping();
      session->shutdown();
      timer.cancel();
      io.stop();
    });
  };
  wait_signal();
  io.run();

  if (session) {
    session->stop();
    if (!opt.quiet) session->print_summary();
  }
  return kExitOk;
}

}  // namespace fieldguard::app
