#pragma once
// What stands between the output stage and the bus, the same in replay and the daemon: the encoder (its alive
// counters), the schedule (its cycle), and fieldguard as a J1939 node (can.j1939: the address claim, answers to
// requests, DM1 from the safety decisions). The daemon keeps one link for its whole life, so a configuration
// reload neither restarts the alive counters nor the cycle of the stop request nor claims the address again
// (unless the NAME or the address changed).
//
// The link is the schedule's sink: it lets our messages through only while the address is ours (they are
// withheld, and counted, during the claim's 250 ms and without an address), and writes into each the address
// we hold (another after a lost contest) and the controller's address found by its NAME. Every frame goes to the
// bus in time order: the node is brought up to a frame's time before the frame goes out.
// Thread-compatible: one output thread.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fieldguard/config/config_output.hpp"
#include "fieldguard/core/time.hpp"
#include "fieldguard/output/can_encoder.hpp"
#include "fieldguard/output/can_frame.hpp"
#include "fieldguard/output/can_schedule.hpp"
#include "fieldguard/output/can_sink.hpp"
#include "fieldguard/output/diagnostics.hpp"
#include "fieldguard/output/j1939_node.hpp"
#include "fieldguard/output/safety_monitor.hpp"

namespace fieldguard::app {

struct CanLinkCounts {
  std::uint64_t withheld = 0;  // our messages not sent: no address yet (the claim's hold) or none at all
  std::uint64_t received = 0;  // frames from the bus handed to the node
};

class CanLink final : public output::CanSink {
 public:
  // `bus` must outlive the link. Throws std::invalid_argument for parameters the loader should have refused.
  CanLink(const CanConfig& cfg, output::CanSink& bus);
  ~CanLink() override = default;
  CanLink(const CanLink&) = delete;
  CanLink& operator=(const CanLink&) = delete;
  CanLink(CanLink&&) = delete;
  CanLink& operator=(CanLink&&) = delete;

  // A reloaded configuration: the encoder and the schedule take the new values and keep their counters and
  // cycle; the node is kept unless its NAME, address or claiming changed (then a new one claims at the next
  // start()). Throws std::invalid_argument like the constructor (the link is then unchanged).
  void reconfigure(const CanConfig& cfg);

  // The address claim (once; again after a reconfigure that made a new node).
  void start(Stamp t);
  // A frame from the bus (not ours).
  void receive(const output::CanFrame& f, Stamp t);
  // The node's time-driven work up to `t` (the claim's hold, DM1, BAM packets).
  void advance(Stamp t);
  // A safety decision at `t`: the DM1 it makes.
  void decided(const output::safety::Decision& d, Stamp t);
  void bus_off(Stamp t);
  void bus_recovered(Stamp t);

  // How long the claim holds everything else back (0 without a node).
  [[nodiscard]] Nanos claim_hold() const;
  // No J1939 address to send from: the safety monitor's "no address".
  [[nodiscard]] bool no_address() const;
  [[nodiscard]] output::CanSchedule& schedule() { return schedule_; }
  [[nodiscard]] const output::j1939::Node* node() const { return node_ ? &*node_ : nullptr; }
  [[nodiscard]] const CanLinkCounts& counts() const { return counts_; }

  // The schedule's frames: through the gate to the bus.
  void write(std::span<const output::CanFrame> frames, Stamp t) override;
  [[nodiscard]] const output::CanSinkStats& stats() const override { return bus_.stats(); }

 private:
  [[nodiscard]] static output::j1939::NodeParams node_params(const CanConfig& cfg);
  void flush(Stamp t);
  void note_state();  // logs each change of the claim's state once

  CanConfig cfg_;
  output::CanSink& bus_;
  output::CanEncoder encoder_;
  output::CanSchedule schedule_;
  std::optional<output::j1939::Node> node_;
  output::j1939::Diagnostics diagnostics_;
  bool started_ = false;
  output::j1939::ClaimState logged_ = output::j1939::ClaimState::NotStarted;
  std::optional<std::uint8_t> logged_address_;
  std::uint64_t lost_seen_ = 0;                // the bus's dropped + write errors at the last decision
  std::optional<std::int64_t> send_error_ns_;  // when frames were last lost
  std::vector<output::CanFrame> out_;          // the node's frames, reused
  std::vector<output::CanFrame> pass_;         // our frames through the gate, reused
  CanLinkCounts counts_;
};

// The exit summary's `j1939` line: "address 0x80 claimed, 12 DM1 (2 multi-packet), 0 of 0 requests answered, 0
// NACK, 0 address violations, 6 frames withheld", or why there is no node.
[[nodiscard]] std::string j1939_summary(const CanLink& link);

}  // namespace fieldguard::app
