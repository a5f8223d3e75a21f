#pragma once
// One configuration's worth of daemon (`fieldguard run`): its live sources, its frame maker, its worker pool
// and its output stage, all on one io_context. A reload replaces the whole session; the CAN sink outlives it.
// Thread contract: everything here runs on the io thread, but process(), which the pool's workers call.

#include <array>
#include <atomic>
#include <boost/asio/io_context.hpp>
#include <boost/circular_buffer.hpp>
#include <chrono>
#include <cstdint>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "daemon/live_view.hpp"
#include "daemon/run_stage.hpp"
#include "daemon/systemd_notify.hpp"
#include "fieldguard/config/config.hpp"
#include "fieldguard/core/latency_stats.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/engine/logging.hpp"
#include "fieldguard/io/can_reader.hpp"
#include "fieldguard/io/scip_source.hpp"
#include "fieldguard/io/serial_reader.hpp"
#include "fieldguard/io/udp_receiver.hpp"
#include "fieldguard/perception/obstacle_hold.hpp"
#include "fieldguard/sync/health.hpp"
#include "fieldguard/sync/ordered_pool.hpp"

namespace fieldguard::app {

// A frame's latency in its parts, each from the end of the one before: from its last LiDAR packet until the
// frame was whole (the synchronizer waiting for another sensor, and decoding), until the io thread handed it
// to the pool (assembly), until a worker took it up, compensation, detection, and back on the io thread to the
// write of its stop request (the safety monitor and the CAN frames).
inline constexpr const char* kLatencyParts[] = {"waiting for sensors", "io thread", "to a worker",
                                                "compensation",        "detection", "decision"};

class Session {
  using Pool = sync::OrderedPool<FrameJob, DetectedFrame>;
  using SteadyClock = std::chrono::steady_clock;

 public:
  // `ready`: READY=1 was sent (by this process, for any session): the watchdog is fed only from then on.
  Session(boost::asio::io_context& io, Config cfg, CanLink& link, SystemdNotifier& notify, bool& ready);
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  Session(Session&&) = delete;
  Session& operator=(Session&&) = delete;
  ~Session();

  // Throws std::system_error when the LiDAR's port cannot be bound.
  void start();

  // The tractor's speed off the bus sizes the stop zone. Without it (no SocketCAN, no interface) the zone
  // keeps its full-speed length: safe, so the daemon runs on and says why once.
  void start_speed_input();
  // Sources closed, queued rotations discarded, the workers joined (each finishes its rotation first).
  void stop();

  void shutdown() { stage_.shutdown(wall_clock_now()); }

  // The output timer, for what is periodic: a decision on the clock (timeouts), the CAN cycles due, frames
  // that waited for a late sensor past sync.timeout_s, the status. Finished frames do not wait for it:
  // on_results() decides them as soon as a worker is done (it polls here too, which finds nothing then).
  // `late`: how long after its expiry the timer ran: the longest such wait is the io loop's gap.
  void on_tick(std::chrono::nanoseconds late = {});

  [[nodiscard]] std::string status(Stamp now) const;
  // The live view's port (view.server, when on): the one the kernel chose for port 0.
  [[nodiscard]] std::optional<std::uint16_t> view_port() const { return view_ ? view_->port() : std::nullopt; }

  // Also what tools/fieldguard-load reads: keep the labels stable.
  void print_summary() const;

  [[nodiscard]] const Config& config() const { return cfg_; }
  // The port a channel of the 3D LiDAR is read on (lidar.data_port, msop_port, difop_port, or the one the kernel
  // chose for 0); 0 when the configured model does not listen on it.
  [[nodiscard]] std::uint16_t lidar_port(lidar3d::Channel channel = lidar3d::Channel::VelodyneData) const;
  [[nodiscard]] const LiveStageCounts& counts() const { return stage_.counts(); }

 private:
  // How a worker that finished a frame wakes the io thread: one asio post per burst of results (pending), to a
  // session that may have been replaced meanwhile (session: set and cleared on the io thread only).
  struct Waker {
    std::atomic<bool> pending{false};
    Session* session = nullptr;
  };
  static sync::PoolParams pool_params(const Config& c, boost::asio::io_context& io, std::shared_ptr<Waker> waker);
  // The io thread, woken by a worker: the finished frames in order, each decided and its CAN frames written.
  void on_results();

  void process(FrameJob& j, DetectedFrame& d);  // over the slot's earlier result (OrderedPool::ProcessInto)

  void heard(output::safety::Sensor s, Stamp t);
  // Each sensor's state and rate, for the live view's page and the status line's faults.
  [[nodiscard]] std::vector<ViewSensor> view_sensors(Stamp now) const;

  void on_datagram(lidar3d::Channel channel, const io::UdpDatagram& d);
  // Implausible GNSS / AHRS samples decoded since the last decision go to the next one.
  void pass_problems();
  void submit_jobs();
  void deliver(const Pool::Result& r);

  boost::asio::io_context& io_;
  const Config cfg_;
  const bool view_wanted_ = LiveView::wanted(cfg_);  // the workers keep each frame's labelled points for it
  SystemdNotifier& notify_;
  bool& ready_;
  std::shared_ptr<spdlog::logger> log_ = logger("run");
  LiveStage stage_;
  perception::ObstacleHold hold_{cfg_.perception.hold};
  std::uint64_t held_ = 0;  // obstacles the hold reported
  SensorFusion fusion_;
  sync::HealthMonitor health_;
  DetectorSet detectors_;
  std::shared_ptr<Waker> waker_ = std::make_shared<Waker>();
  Pool pool_;
  std::array<std::unique_ptr<io::UdpReceiver>, 3> udp_;  // by lidar3d::Channel
  std::unique_ptr<io::ScipSource> scip_;
  std::unique_ptr<io::CanReader> can_in_;
  std::uint64_t speed_errors_ = 0;
  std::vector<std::unique_ptr<io::SerialReader>> serial_;
  std::vector<FrameJob> jobs_;
  // Rings, not deques: a frame pushes and pops without allocating. A frame outstanding holds a pool slot, so the
  // slots bound the submit times kept.
  boost::circular_buffer<Stamp> submitted_;  // submit times of the rotations not yet delivered, oldest first
  // The detection times of the status and the summary: the last 5 s at 10 Hz.
  static constexpr std::size_t kTimedRotations = 50;
  boost::circular_buffer<perception::StageTimes> timed_ =
      boost::circular_buffer<perception::StageTimes>(kTimedRotations);  // the last rotations', oldest first
  float worst_us_ = 0.F;                                                // the longest process() of the run
  std::uint64_t timed_count_ = 0;                                       // rotations delivered
  std::uint64_t lost_ = 0;                                              // rotations dropped, refused or failed
  std::uint64_t bad_length_ = 0;
  std::uint64_t refused_ = 0;       // MSOP of other RoboSense models
  std::uint64_t other_family_ = 0;  // packets of the LiDAR family not in use
  bool model_logged_ = false;       // the line saying which 3D LiDAR it is and why
  bool heard_all_ = false;
  bool stalled_ = false;
  LatencyStats latency_;  // per frame: last packet's kernel receive time to its stop request's write
  LatencyStats io_gap_;   // per tick: how late the output timer ran
  // latency_ in its parts, per frame, named by kLatencyParts.
  std::array<LatencyStats, std::size(kLatencyParts)> parts_;
  std::uint64_t late_ = 0;  // frames over realtime.latency_budget_ms
  bool worker_refusal_logged_ = false;
  // Allocations counted (core/alloc_count.hpp) when the kWarmFrames-th frame was decided: the summary's are those
  // after it, once warm.
  static constexpr std::uint64_t kWarmFrames = 10;
  std::optional<std::uint64_t> warm_frame_allocs_, warm_sample_allocs_;
  std::uint64_t warm_frames_ = 0;  // frames decided when they were taken
  bool stopped_ = false;
  SteadyClock::time_point last_status_{};
  std::uint64_t trimmed_slots_ = 0;   // pool slots whose buffers went back (OrderedPool::trim_idle)
  std::uint64_t trimmed_spares_ = 0;  // spare buffers freed (SensorFusion::trim_spares)
  std::unique_ptr<LiveView> view_;    // view: the recording and the live server; made by start()
  std::optional<std::pair<bool, output::safety::Reason>> view_shown_;  // the decision view_ last had from a tick
};

}  // namespace fieldguard::app
