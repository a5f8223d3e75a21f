#include "fieldguard/engine/can_link.hpp"

#include <fmt/format.h>

#include "fieldguard/core/version.hpp"
#include "fieldguard/engine/logging.hpp"

namespace fieldguard::app {
namespace {

namespace j1939 = output::j1939;

constexpr std::int64_t kSendErrorShownNs = 2'000'000'000;  // a DTC for lost frames stays this long after the last

double seconds(Stamp t) { return static_cast<double>(t.ns) * 1e-9; }

}  // namespace

j1939::NodeParams CanLink::node_params(const CanConfig& cfg) {
  j1939::NodeParams p;
  p.claim.name = cfg.j1939.name;
  p.claim.preferred_address = cfg.params.source_address;
  p.software_id = version_string();
  p.component_id = cfg.j1939.component_id;
  return p;
}

CanLink::CanLink(const CanConfig& cfg, output::CanSink& bus)
    : cfg_(cfg),
      bus_(bus),
      encoder_(cfg.params),
      schedule_(encoder_, *this, nanos_from_seconds(cfg.heartbeat_period_s)) {
  if (cfg.j1939.address_claim) node_.emplace(node_params(cfg));
  out_.reserve(32);
  pass_.reserve(output::kMaxObstacleMessages + 4);
}

void CanLink::reconfigure(const CanConfig& cfg) {
  const j1939::NodeParams fresh = node_params(cfg);
  const j1939::NodeParams old = node_params(cfg_);
  const bool same_node = cfg.j1939.address_claim == cfg_.j1939.address_claim && fresh.claim.name == old.claim.name &&
                         fresh.claim.preferred_address == old.claim.preferred_address &&
                         fresh.component_id == old.component_id;
  std::optional<j1939::Node> node;
  if (!same_node && cfg.j1939.address_claim) node.emplace(fresh);  // throws before anything changed
  encoder_.reconfigure(cfg.params);
  schedule_.set_period(nanos_from_seconds(cfg.heartbeat_period_s));
  if (!same_node) {
    node_ = std::move(node);
    started_ = false;
  }
  cfg_ = cfg;
}

void CanLink::note_state() {
  if (!node_) return;
  const auto& c = node_->claimer();
  const auto address = c.address();
  if (c.state() == logged_ && address == logged_address_) return;
  const auto log = logger("can");
  const std::string at = address ? fmt::format("0x{:02X}", *address) : std::string("none");
  switch (c.state()) {
    case j1939::ClaimState::NotStarted: break;
    case j1939::ClaimState::Claiming:
      if (logged_address_ && address != logged_address_) {
        log->warn("J1939: address 0x{:02X} lost to a NAME of higher priority; claiming {}", *logged_address_, at);
      }
      break;
    case j1939::ClaimState::Claimed: log->info("J1939: address {} claimed (NAME 0x{:016X})", at, c.name()); break;
    case j1939::ClaimState::CannotClaim:
      log->error("J1939: cannot claim an address (lost 0x{:02X}, none free): nothing goes on the bus but Cannot Claim",
                 logged_address_.value_or(j1939::kNullAddress));
      break;
    case j1939::ClaimState::BusOff: log->warn("J1939: bus off; the address is claimed again on recovery"); break;
  }
  logged_ = c.state();
  logged_address_ = address;
}

void CanLink::flush(Stamp t) {
  note_state();
  if (out_.empty()) return;
  bus_.write(out_, t);
  out_.clear();
}

void CanLink::start(Stamp t) {
  if (started_) return;
  started_ = true;
  if (!node_) return;
  node_->start(seconds(t), out_);
  flush(t);
}

void CanLink::advance(Stamp t) {
  if (!node_) return;
  node_->tick(seconds(t), out_);
  flush(t);
}

void CanLink::receive(const output::CanFrame& f, Stamp t) {
  ++counts_.received;
  if (!node_) return;
  node_->tick(seconds(t), out_);
  node_->receive(f, seconds(t), out_);
  flush(t);
}

void CanLink::decided(const output::safety::Decision& d, Stamp t) {
  if (!node_) return;
  advance(t);
  const output::CanSinkStats& s = bus_.stats();
  const std::uint64_t lost = s.dropped + s.write_errors;
  if (lost != lost_seen_ || s.bus_off) send_error_ns_ = t.ns;
  lost_seen_ = lost;
  j1939::BusFaults faults;
  faults.send_errors = send_error_ns_ && t.ns - *send_error_ns_ <= kSendErrorShownNs;
  faults.address_conflict = node_->address_conflict(seconds(t));
  // DM2 changes only with DM1 (a DTC active or no longer): not made again on every decision.
  if (node_->set_dm1(diagnostics_.update(d, faults), seconds(t), out_)) {
    node_->set_dm2(diagnostics_.previously_active());
  }
  flush(t);
}

void CanLink::bus_off(Stamp t) {
  if (!node_) return;
  node_->bus_off();
  send_error_ns_ = t.ns;
  note_state();
}

void CanLink::bus_recovered(Stamp t) {
  if (!node_) return;
  node_->bus_recovered(seconds(t), out_);
  flush(t);
}

Nanos CanLink::claim_hold() const { return node_ ? nanos_from_seconds(node_params(cfg_).claim.hold_s) : Nanos{0}; }

bool CanLink::no_address() const { return node_ && node_->claimer().state() == j1939::ClaimState::CannotClaim; }

void CanLink::write(std::span<const output::CanFrame> frames, Stamp t) {
  if (!node_) {
    bus_.write(frames, t);
    return;
  }
  advance(t);
  if (!node_->may_transmit()) {
    counts_.withheld += frames.size();
    return;
  }
  const std::uint8_t source = *node_->claimer().address();
  std::optional<std::uint8_t> controller;
  if (cfg_.j1939.controller_name) controller = node_->claimer().address_of(*cfg_.j1939.controller_name);
  pass_.assign(frames.begin(), frames.end());
  for (auto& f : pass_) {
    const output::J1939Fields j = output::j1939_fields(f.id);  // j1939_id takes the destination of PDU1 PGNs only
    f.id = output::j1939_id(j.priority, j.pgn, source, controller.value_or(j.destination));
  }
  bus_.write(pass_, t);
}

std::string j1939_summary(const CanLink& link) {
  const j1939::Node* n = link.node();
  if (n == nullptr) return "off (can.j1939.address_claim: false): sent from the configured address unclaimed";
  const auto& c = n->counters();
  const auto& claimer = n->claimer();
  const auto address = claimer.address();
  std::string where = address ? fmt::format("address 0x{:02X} {}", *address, j1939::to_string(claimer.state()))
                              : std::string(j1939::to_string(claimer.state()));
  return fmt::format(
      "{}, {} DM1, {} of {} requests answered, {} NACK, {} contests won, {} lost, {} address violations, {} frames "
      "withheld",
      where, c.dm1_sent, c.requests_answered, c.requests, c.nacks_sent, claimer.counters().contests_won,
      claimer.counters().contests_lost, c.address_violations, link.counts().withheld);
}

}  // namespace fieldguard::app
