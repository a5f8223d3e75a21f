#pragma once
// fieldguard as one J1939 / ISO 11783 controller application, pure (frames in, frames out, time given): the
// address claim (address_claim.hpp), the answers to requests, and the diagnostic messages. The daemon and replay
// drive it the same way whatever the bus; every frame it returns is to be sent at the `now` of the call.
//
//   requests (PGN 59904) to global or to our address, answered once the address is ours:
//     Address Claimed      the claimer's answer (also while claiming, and Cannot Claim without an address);
//     Software Identification (65242), Component Identification (65259, when configured), DM1, DM2: the message;
//     any other PGN        a NACK (Acknowledgement 59392) when the request was to us alone; J1939-21 asks for no
//                          answer to a global request for a PGN we do not send.
//   DM1 every dm1_period_s (1 s) with the active DTCs, or with none (lamps off) once they clear; a change of the
//     DTCs goes out at once, and a change within a second of the previous change-triggered DM1 at the end of that
//     second (J1939-73: one state change per second, so an intermittent fault cannot flood the bus).
//   a message over 8 bytes (DM1 with two DTCs or more, the identifications) goes by BAM: the announcement at once,
//     the packets bam_gap_s (50 ms, J1939-21's minimum) apart, one BAM at a time (a newer message of the same PGN
//     waiting replaces the older).
//   another node transmitting with our address (anything but Address Claimed): J1939-81's address violation; we
//     claim again (once a second at most) and report it (address_conflict()).

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/output/address_claim.hpp"
#include "fieldguard/output/can_frame.hpp"
#include "fieldguard/output/j1939.hpp"

namespace fieldguard::output::j1939 {

struct NodeParams {
  ClaimParams claim;
  std::string software_id = "fieldguard";  // one field (J1939-71: fields end with '*', which we add)
  std::string component_id;                // "make*model*serial number*unit number" (a '*' closes each field)
  double dm1_period_s = 1.0;
  double bam_gap_s = 0.05;

  [[nodiscard]] std::vector<std::string> validate() const;
};

class Node {
 public:
  struct Counters {
    std::uint64_t requests = 0;           // for us (to global or to our address), any PGN
    std::uint64_t requests_answered = 0;  // with the message requested (Address Claimed counted by the claimer)
    std::uint64_t nacks_sent = 0;
    std::uint64_t requests_unanswered = 0;  // arrived while we had no address to answer from
    std::uint64_t dm1_sent = 0;
    std::uint64_t dm2_sent = 0;
    std::uint64_t bam_sent = 0;  // multi-packet messages, each counted once
    std::uint64_t address_violations = 0;
  };

  explicit Node(const NodeParams& params);  // throws std::invalid_argument when invalid

  void start(double now_s, std::vector<CanFrame>& out);
  // A frame from the bus (not one of ours).
  void receive(const CanFrame& f, double now_s, std::vector<CanFrame>& out);
  // Time passing: the claim's hold, DM1's period, the next BAM packet.
  void tick(double now_s, std::vector<CanFrame>& out);
  // The active DTCs as the daemon sees them now (Diagnostics::update); a change is sent as the rate limit allows.
  // True when they changed.
  bool set_dm1(const DiagnosticMessage& dm1, double now_s, std::vector<CanFrame>& out);
  // The previously active DTCs, sent on request.
  void set_dm2(const DiagnosticMessage& dm2) { dm2_ = dm2; }
  void bus_off() {
    claimer_.bus_off();
    bam_packets_.clear();
  }
  void bus_recovered(double now_s, std::vector<CanFrame>& out) { claimer_.bus_recovered(now_s, out); }

  [[nodiscard]] const AddressClaimer& claimer() const { return claimer_; }
  [[nodiscard]] bool may_transmit() const { return claimer_.may_transmit(); }
  // Another node used our address within the last 2 s.
  [[nodiscard]] bool address_conflict(double now_s) const;
  [[nodiscard]] const Counters& counters() const { return counters_; }

  static constexpr std::uint8_t kDiagnosticPriority = 6;
  static constexpr std::uint8_t kTransportPriority = 7;

 private:
  void send(std::uint32_t pgn, std::vector<std::uint8_t> data, double now_s, std::vector<CanFrame>& out);
  void send_dm1(double now_s, std::vector<CanFrame>& out);
  void answer(std::uint32_t pgn, std::uint8_t requester, bool to_us_alone, double now_s, std::vector<CanFrame>& out);
  void nack(std::uint32_t pgn, std::uint8_t requester, bool to_us_alone, std::vector<CanFrame>& out);
  void next_bam(double now_s, std::vector<CanFrame>& out);
  [[nodiscard]] std::uint8_t source() const;

  NodeParams params_;
  AddressClaimer claimer_;
  DiagnosticMessage dm1_;
  DiagnosticMessage dm2_;
  std::optional<double> dm1_due_s_;      // the periodic DM1
  std::optional<double> change_sent_s_;  // the last DM1 a change sent
  bool change_waiting_ = false;          // a change held back by the rate limit
  std::deque<CanFrame> bam_packets_;     // of the BAM under way
  double bam_next_s_ = 0.0;
  struct Waiting {
    std::uint32_t pgn;
    std::vector<std::uint8_t> data;
  };
  std::vector<Waiting> bam_waiting_;  // one per PGN
  std::optional<double> violation_at_s_;
  std::optional<double> reclaimed_at_s_;
  Counters counters_;
};

}  // namespace fieldguard::output::j1939
