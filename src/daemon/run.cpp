// `fieldguard run`: the daemon. The live sources, the frame maker (SensorFusion: rotations, or fused frames
// when a 2D LiDAR, GNSS or AHRS is enabled) and the output stage share one Boost.Asio io_context on the main
// thread (the io thread); compensation and perception run on an OrderedPool of pipeline.workers threads. A worker
// that finishes a frame wakes the io thread (session.hpp), which decides it and writes its CAN frames at once. A
// 5 ms timer on the io thread does what is periodic: the safety monitor's decision on the clock alone (a sensor
// that falls silent, a stalled pipeline), the heartbeats, frames that wait for a late sensor, the status.

#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "daemon/bus_listener.hpp"
#include "daemon/session.hpp"
#include "daemon/systemd_notify.hpp"
#include "fieldguard/config/config.hpp"
#include "fieldguard/core/alloc_count.hpp"
#include "fieldguard/core/exit_code.hpp"
#include "fieldguard/daemon/daemon.hpp"
#include "fieldguard/engine/can_link.hpp"
#include "fieldguard/engine/logging.hpp"
#include "fieldguard/output/can_sink.hpp"
#include "fieldguard/sync/threads.hpp"

namespace fieldguard::app {
namespace {

constexpr auto kTick = std::chrono::milliseconds(5);

using output::NullSink;  // can.sink: none

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

// The daemon's life: open() the configuration, the CAN sink and the first session; loop() on the io thread
// until a signal ends it (SIGHUP reloads: reload()); the summary on exit.
class Daemon {
 public:
  explicit Daemon(const RunOptions& opt) : opt_(opt) {}

  // The configuration, the sink and the first session. False (the message printed) when one is unusable.
  bool open();
  // The output timer and the signals on the io thread, until SIGTERM / SIGINT or a reload that fails twice.
  void loop();
  // Sources closed, the workers joined, the summary printed (unless quiet).
  void finish();

 private:
  std::unique_ptr<Session> open_session(const Config& cfg);
  void set_link(std::unique_ptr<output::CanSink> sink, const Config& cfg);
  void listen_if_node();
  void apply_realtime(const RealtimeConfig& rt);
  void arm_timer();
  void wait_signal();
  void reload();

  const RunOptions& opt_;
  std::shared_ptr<spdlog::logger> log_ = logger("run");
  boost::asio::io_context io_;
  boost::asio::steady_timer timer_{io_};
  boost::asio::signal_set signals_{io_, SIGINT, SIGTERM, SIGHUP};
  SystemdNotifier notify_ = SystemdNotifier::from_environment();
  SinkKey key_;
  std::unique_ptr<output::CanSink> sink_;
  std::unique_ptr<CanLink> link_;  // outlives the sessions: alive counters, the stop request's cycle, the address
  std::unique_ptr<BusListener> listener_;  // on a SocketCAN bus: what the J1939 node hears
  bool filter_problem_logged_ = false;
  std::unique_ptr<Session> session_;
  bool ready_ = false;  // READY=1 sent, by any session of this process
  bool io_refusal_logged_ = false;
  bool memory_locked_ = false;  // mlockall tried
};

bool Daemon::open() {
  // Before any thread or buffer: the buffers a sensor outage makes the daemon hold go back afterwards.
  if (std::string refused = sync::give_large_blocks_back(); !refused.empty() && sync::kGlibcMalloc) {
    log_->warn("memory: large blocks may stay resident after they are freed ({})", refused);
  }
  auto loaded = load_config_file(opt_.config);
  if (!loaded.ok()) {
    for (const auto& issue : loaded.issues) std::fprintf(stderr, "%s\n", issue.to_string().c_str());
    std::fprintf(stderr, "fieldguard run: invalid configuration %s\n", opt_.config.c_str());
    return false;
  }
  if (opt_.mcap_out) loaded.config.view.mcap_path = *opt_.mcap_out;
  key_ = sink_key(loaded.config, opt_.can_log);
  try {
    set_link(make_sink(key_), loaded.config);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fieldguard run: CAN output: %s\n", e.what());
    return false;
  }
  try {
    session_ = open_session(loaded.config);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fieldguard run: %s\n", e.what());
    return false;
  }
  return true;
}

// The io thread (this one) gets the configuration's scheduling before the session's workers are created; what
// the system refuses is said once per run, and the daemon goes on without it.
void Daemon::apply_realtime(const RealtimeConfig& rt) {
  const sync::ThreadSettings io{"fg-io", rt.policy, rt.io_priority, rt.io_cpus};
  if (std::string refused = sync::apply_to_this_thread(io); !refused.empty()) {
    if (!io_refusal_logged_) {
      log_->warn("realtime: the io thread runs without what the system refused ({}); it goes on at normal priority",
                 refused);
    }
    io_refusal_logged_ = true;
  } else if (rt.policy != sync::SchedPolicy::Other) {
    log_->info("realtime: io thread {}, perception workers {}", sync::describe(io),
               sync::describe({"", rt.policy, rt.worker_priority, {}}));
  }
  if (rt.lock_memory && !memory_locked_) {
    if (std::string refused = sync::lock_all_memory(); !refused.empty()) {
      log_->warn("realtime: memory not locked ({}); pages may fault in on the stop path", refused);
    } else {
      log_->info("realtime: memory locked");
    }
    memory_locked_ = true;  // tried once: a reload does not try (or say) it again
  }
}

std::unique_ptr<Session> Daemon::open_session(const Config& cfg) {
  apply_realtime(cfg.realtime);
  auto s = std::make_unique<Session>(io_, cfg, *link_, notify_, ready_);
  s->start();
  return s;
}

// A new sink and the link on it; on a SocketCAN bus the node hears requests and claims through the sink's socket.
void Daemon::set_link(std::unique_ptr<output::CanSink> sink, const Config& cfg) {
  auto link = std::make_unique<CanLink>(cfg.can, *sink);
  listener_.reset();
  link_ = std::move(link);
  sink_ = std::move(sink);
  listen_if_node();
}

// The listener once there is a node on a SocketCAN bus (also after a reload turned address_claim on).
void Daemon::listen_if_node() {
  auto* socket = dynamic_cast<output::SocketCanSink*>(sink_.get());
  if (listener_ || socket == nullptr || link_->node() == nullptr) return;
  try {
    listener_ = std::make_unique<BusListener>(io_, *socket, *link_);
  } catch (const std::exception& e) {
    log_->warn("J1939: {}; requests and claims from the bus go unheard", e.what());
  }
}

void Daemon::arm_timer() {
  timer_.expires_after(kTick);
  timer_.async_wait([this](const boost::system::error_code& ec) {
    if (ec) return;
    if (listener_) {
      listener_->deliver();  // what a write() read meanwhile
      if (!listener_->filter_problem().empty() && !filter_problem_logged_) {
        filter_problem_logged_ = true;
        log_->warn("J1939: the CAN socket refused its filters ({}); requests and claims go unheard",
                   listener_->filter_problem());
      }
    }
    session_->on_tick(std::chrono::steady_clock::now() - timer_.expiry());
    arm_timer();
  });
}

// SIGHUP: a configuration with errors is refused and the running one stays; a good one replaces the session
// (and the sink, when its kind, interface or file changed). Throws when even the previous configuration
// cannot be restarted.
void Daemon::reload() {
  const alloc::Scope not_a_frame(alloc::Path::None);  // a new session is built: no frame's work
  notify_.reloading();
  log_->info("SIGHUP: reloading {}", opt_.config);
  auto fresh = load_config_file(opt_.config);
  if (!fresh.ok()) {
    for (const auto& issue : fresh.issues) log_->error("{}", issue.to_string());
    log_->error("reload refused: {} has {} error(s); the running configuration stays", opt_.config,
                fresh.issues.size());
    notify_.reloaded(session_->status(wall_clock_now()));
    return;
  }
  if (opt_.mcap_out) fresh.config.view.mcap_path = *opt_.mcap_out;
  const Config old = session_->config();
  const SinkKey new_key = sink_key(fresh.config, opt_.can_log);
  session_.reset();
  try {
    if (!(new_key == key_)) {
      // Another bus: a new node on it, whose counters and claim start afresh.
      set_link(make_sink(new_key), fresh.config);
      key_ = new_key;
    } else {
      link_->reconfigure(fresh.config.can);
      listen_if_node();
    }
    session_ = open_session(fresh.config);
    log_->info("reloaded {}: starting again from STOP, starting up", opt_.config);
  } catch (const std::exception& e) {
    log_->error("reload failed: {}; going back to the previous configuration", e.what());
    session_.reset();
    if (key_ == sink_key(old, opt_.can_log)) link_->reconfigure(old.can);
    session_ = open_session(old);
  }
  notify_.reloaded(session_->status(wall_clock_now()));
}

void Daemon::wait_signal() {
  signals_.async_wait([this](const boost::system::error_code& ec, int sig) {
    if (ec) return;
    if (sig == SIGHUP) {
      try {
        reload();
      } catch (const std::exception& e) {
        // Even the previous configuration could not be restarted (its port was taken meanwhile).
        log_->critical("reload: {}; exiting", e.what());
        io_.stop();
        return;
      }
      wait_signal();
      return;
    }
    log_->info("{}: stopping", sig == SIGTERM ? "SIGTERM" : "SIGINT");
    notify_.stopping();
    session_->shutdown();
    timer_.cancel();
    io_.stop();
  });
}

void Daemon::loop() {
  arm_timer();
  wait_signal();
  // What the io thread does outside a frame's path and the periodic tick is decoding the other sensors' samples
  // (serial bytes, the 2D LiDAR's replies, the speed from the bus): counted as such (core/alloc_count.hpp).
  const alloc::Scope samples(alloc::Path::Samples);
  io_.run();
}

void Daemon::finish() {
  if (!session_) return;
  session_->stop();
  if (!opt_.quiet) session_->print_summary();
}

}  // namespace

int run_daemon(const RunOptions& opt) {
  Daemon daemon(opt);
  if (!daemon.open()) return kExitBadInput;
  daemon.loop();
  daemon.finish();
  return kExitOk;
}

}  // namespace fieldguard::app
