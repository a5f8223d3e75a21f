#pragma once
// The configuration of the pipeline's worker pool (`pipeline:`), the threads' scheduling (`realtime:`) and of
// the CAN output (`can:`): plain values
// with defaults, filled and checked by the config loader (src/app/config_pipeline.cpp, config_can.cpp).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/output/can_encoder.hpp"
#include "fieldguard/output/j1939.hpp"
#include "fieldguard/sync/threads.hpp"

namespace fieldguard::app {

enum class PipelineDrop : std::uint8_t { Oldest, Newest };

// The lock-free hand-off from the io thread to the perception workers (sync::OrderedPool).
struct PipelineConfig {
  int workers = 1;                           // perception threads, 1..64
  int queue_capacity = 8;                    // rotations waiting for a worker, 1..4096
  PipelineDrop drop = PipelineDrop::Oldest;  // live, a full queue drops (and counts) this one; replay never drops
};

// How the daemon's threads are scheduled (`realtime:`). Each setting is optional: one the system refuses is
// logged once and the daemon runs on without it.
struct RealtimeConfig {
  sync::SchedPolicy policy =
      sync::SchedPolicy::Other;     // fifo | rr: real-time scheduling for the io thread and the workers
  int io_priority = 50;             // 1..99, under fifo | rr
  int worker_priority = 40;         // 1..99, under fifo | rr
  std::vector<int> io_cpus;         // CPU affinity of the io thread; empty: any
  std::vector<int> worker_cpus;     // CPU affinity of the perception workers; empty: any
  bool lock_memory = false;         // mlockall(MCL_CURRENT | MCL_FUTURE)
  double latency_budget_ms = 10.0;  // a frame decided later than this after it was whole counts as late
};

enum class CanSinkKind : std::uint8_t { SocketCan, Candump, None };

// The tractor's speed read off the bus (output/can_speed.hpp) to size the stop zone.
enum class SpeedInput : std::uint8_t { None, Ccvs1, IsoWheelBased };

// fieldguard as a J1939 / ISO 11783 node (`can.j1939`): its NAME, the address claim, the controller found by NAME.
struct J1939Config {
  bool address_claim = true;  // claim can.source_address before sending (J1939-81); false: send from it unclaimed
  output::j1939::Name name = default_name();
  std::optional<std::uint64_t> controller_name;  // the controller's address from its Address Claimed, when heard
  std::string component_id;                      // Component Identification (PGN 65259): make*model*serial*unit*

  static output::j1939::Name default_name() {
    output::j1939::Name n;
    n.function = 0xFF;  // "not available": the integrator assigns one
    n.industry_group = output::j1939::kIndustryGroupAgricultural;
    n.arbitrary_address_capable = true;
    return n;
  }
};

struct CanConfig {
  CanSinkKind sink = CanSinkKind::SocketCan;
  std::string interface = "can0";       // the SocketCAN interface; also the interface name written in a candump log
  std::string log_path;                 // sink candump: the log file (relative paths from the config file's folder)
  output::CanParams params;             // source and controller addresses, obstacle messages per frame
  double heartbeat_period_s = 0.1;      // heartbeat (and repeated stop request) period
  SpeedInput speed = SpeedInput::None;  // read from `interface` (SocketCAN) by the daemon
  double speed_timeout_s = 0.5;         // an older speed is unknown: the zone has its full-speed length
  J1939Config j1939;
};

// What the daemon shows of what it sees (`view:`): an MCAP recording of its frames and a live server for
// Foxglove (the Foxglove WebSocket protocol) and a browser (the status page), both off by default. Neither can
// slow detection: frames reach them through a bounded queue, and a frame that finds it full is dropped there
// (counted), never held up.
struct ViewConfig {
  // The recording (writers/mcap_recorder.hpp): a series of MCAP files of at most max_mb each, the newest
  // max_files kept. "" = none; a relative path is taken from the config file's folder.
  std::string mcap_path;
  std::string mcap_compression = "zstd";  // zstd | lz4 | none
  int mcap_max_mb = 1024;
  int mcap_max_files = 8;
  // The server: HTTP (status page) and the Foxglove WebSocket protocol on one port.
  bool server = false;
  std::string address = "127.0.0.1";  // localhost unless the integrator opens it to the vehicle's network
  std::uint16_t port = 8765;          // Foxglove's default
  int max_clients = 4;
  int client_queue = 64;  // messages waiting for one client; beyond, that client's oldest are dropped (counted)
  int queue_frames = 2;   // frames waiting for the view's thread; beyond, a frame is not shown (counted)
};

}  // namespace fieldguard::app
