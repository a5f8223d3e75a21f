#pragma once
// What the daemon shows of what it sees (`view:` of the configuration): the MCAP recording and the live server
// (view_server.hpp), fed from one thread of their own. The io thread hands each decided frame over by copying it
// into a free slot of a small ring (view.queue_frames); when none is free the frame is not shown (counted), so
// neither a slow disk nor a slow client can delay a decision. Encoding (JSON, base64, compression) happens on the
// view's thread. Once warm the copy allocates nothing (the slots keep their buffers).
// Thread contract: frame(), sensors() and counts() on the io thread; the rest is the view thread's.

#include <atomic>
#include <boost/lockfree/spsc_queue.hpp>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <semaphore>
#include <string>
#include <thread>
#include <vector>

#include "daemon/view_server.hpp"
#include "fieldguard/config/config.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/output/safety_monitor.hpp"
#include "fieldguard/writers/foxglove_json.hpp"
#include "fieldguard/writers/frame_messages.hpp"
#include "fieldguard/writers/mcap_recorder.hpp"

namespace fieldguard::app {

// One sensor as the status page and the /health channel list it.
using ViewSensor = foxglove::SensorState;

struct LiveViewCounts {
  std::uint64_t frames = 0;   // handed to the view
  std::uint64_t dropped = 0;  // found no free slot: not shown, not recorded
  McapRecorderStats mcap;
  std::uint64_t mcap_errors = 0;  // 1 once the recording failed (it stops then; detection does not)
  ViewServerCounts server;
};

class LiveView {
 public:
  // Opens the recording (cfg.view.mcap_path) and binds the server (cfg.view.server). Throws std::runtime_error
  // naming what failed.
  explicit LiveView(const Config& cfg);
  ~LiveView();
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  // Whether `cfg` asks for anything to be shown.
  [[nodiscard]] static bool wanted(const Config& cfg) { return !cfg.view.mcap_path.empty() || cfg.view.server; }

  // A decided frame (its labelled points in d.labelled). Never waits.
  void frame(const DetectedFrame& d, const output::safety::Decision& decision);
  // The decision as it stands between frames (a sensor gone silent stops the tractor with no frame to carry it),
  // the sensors and the status line, for the page and the /safety/decision channel. Never waits.
  void status(const output::safety::Decision& decision, Stamp now, std::vector<ViewSensor> sensors,
              std::string status_line);

  [[nodiscard]] LiveViewCounts counts() const;
  [[nodiscard]] std::optional<std::uint16_t> port() const;
  [[nodiscard]] const std::string& mcap_error() const { return mcap_error_; }  // read after the thread stopped

 private:
  struct Slot {
    LidarFrame frame;
    std::vector<perception::Obstacle> obstacles;
    std::vector<perception::LabeledPoint> labelled;
    std::optional<FusionInfo> fusion;
    output::safety::Decision decision;
  };
  void loop();
  void show(Slot& s);
  void show_status();  // the status() handed over, on the view thread
  // One message to the recording (when `record`) and to the server's subscribers.
  void send(Topic topic, std::int64_t t, std::string_view json, bool record);
  [[nodiscard]] std::string page_json();

  const Config cfg_;
  std::vector<Slot> slots_;
  boost::lockfree::spsc_queue<std::size_t> ready_;  // io thread -> view thread
  boost::lockfree::spsc_queue<std::size_t> free_;   // view thread -> io thread
  std::counting_semaphore<> wake_{0};
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> frames_{0};
  std::atomic<std::uint64_t> dropped_{0};
  // The view thread's.
  FrameEncoder encoder_;
  std::optional<McapRecorder> mcap_;
  std::string mcap_error_;
  std::atomic<bool> mcap_failed_{false};
  std::unique_ptr<ViewServer> server_;
  std::int64_t last_picture_ns_ = 0;
  // The page: the newest decision shown (a frame's or status()'s), its frame and time.
  output::safety::Decision page_decision_;
  std::uint64_t page_frame_ = 0;
  Stamp page_stamp_;
  std::size_t page_obstacles_ = 0;
  std::string message_;                // scratch
  std::int64_t last_decision_ns_ = 0;  // /safety/decision's newest log time
  // Shared with the io thread (status()).
  mutable std::mutex status_mutex_;
  bool status_pending_ = false;
  output::safety::Decision status_decision_;
  Stamp status_stamp_;
  std::vector<ViewSensor> sensors_;
  std::string status_line_;
  std::atomic<std::uint64_t> mcap_frames_{0};
  std::atomic<std::uint64_t> mcap_messages_{0};
  std::atomic<std::uint64_t> mcap_bytes_{0};
  std::atomic<std::uint64_t> mcap_files_{0};
  std::thread thread_;  // last: started once everything above exists
};

}  // namespace fieldguard::app
