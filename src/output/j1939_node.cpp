#include "fieldguard/output/j1939_node.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace fieldguard::output::j1939 {

namespace {

constexpr double kConflictShownS = 2.0;  // address_conflict() after the last violation
constexpr double kReclaimEveryS = 1.0;   // at most one claim a second in answer to violations

}  // namespace

std::vector<std::string> NodeParams::validate() const {
  std::vector<std::string> problems = claim.validate();
  if (!(dm1_period_s >= 0.1 && dm1_period_s <= 10.0)) problems.emplace_back("dm1_period_s: 0.1..10 s (J1939-73: 1)");
  if (!(bam_gap_s >= 0.05 && bam_gap_s <= 0.2)) problems.emplace_back("bam_gap_s: 0.05..0.2 s (J1939-21)");
  // Software identification: a count byte and the field with its '*'.
  if (software_id.empty() || software_id.size() + 2 > kMaxTransportBytes ||
      software_id.find('*') != std::string::npos) {
    problems.emplace_back("software_id: 1..1783 characters, no '*'");
  }
  if (component_id.size() + 1 > kMaxTransportBytes) problems.emplace_back("component_id: at most 1784 characters");
  return problems;
}

Node::Node(const NodeParams& params) : params_(params), claimer_(params.claim) {
  const auto problems = params.validate();
  if (!problems.empty()) {
    std::string msg = "invalid J1939 node parameters:";
    for (const auto& p : problems) msg += "\n  " + p;
    throw std::invalid_argument(msg);
  }
}

std::uint8_t Node::source() const { return claimer_.address().value_or(kNullAddress); }

void Node::start(double now_s, std::vector<CanFrame>& out) {
  claimer_.start(now_s, out);
  dm1_due_s_ = now_s + params_.claim.hold_s;  // the first DM1 as soon as the address is ours
}

bool Node::address_conflict(double now_s) const {
  return violation_at_s_ && now_s - *violation_at_s_ <= kConflictShownS;
}

void Node::receive(const CanFrame& f, double now_s, std::vector<CanFrame>& out) {
  const J1939Fields j = j1939_fields(f.id);
  if (j.pgn != kPgnAddressClaimed && claimer_.may_transmit() && j.source == source()) {
    ++counters_.address_violations;
    violation_at_s_ = now_s;
    if (!reclaimed_at_s_ || now_s - *reclaimed_at_s_ >= kReclaimEveryS) {
      reclaimed_at_s_ = now_s;
      out.push_back(address_claimed(claimer_.name(), source()));
    }
  }
  const std::uint8_t before = source();
  claimer_.receive(f, now_s, out);
  if (source() != before) {
    // A new address (or none): a BAM under way from the old one is abandoned, its message sent again later.
    bam_packets_.clear();
  }
  if (j.pgn != kPgnRequest) return;
  const auto pgn = requested_pgn(std::span<const std::uint8_t>(f.data.data(), f.len));
  if (!pgn || *pgn == kPgnAddressClaimed) return;  // malformed, or the claimer's
  const bool to_us_alone = claimer_.address() && j.destination == *claimer_.address();
  if (!to_us_alone && j.destination != kGlobalAddress) return;
  ++counters_.requests;
  if (!claimer_.may_transmit() || j.source > kMaxUnicastAddress) {
    // No address to answer from yet (or lost), or a requester without one: nothing may go out.
    ++counters_.requests_unanswered;
    return;
  }
  answer(*pgn, j.source, to_us_alone, now_s, out);
}

void Node::answer(std::uint32_t pgn, std::uint8_t requester, bool to_us_alone, double now_s,
                  std::vector<CanFrame>& out) {
  switch (pgn) {
    case kPgnSoftwareId: {
      std::vector<std::uint8_t> data{1};  // one field
      data.insert(data.end(), params_.software_id.begin(), params_.software_id.end());
      data.push_back('*');
      send(pgn, std::move(data), now_s, out);
      break;
    }
    case kPgnComponentId:
      if (params_.component_id.empty()) {  // none configured: as for a PGN we do not send
        nack(pgn, requester, to_us_alone, out);
        return;
      }
      send(pgn, std::vector<std::uint8_t>(params_.component_id.begin(), params_.component_id.end()), now_s, out);
      break;
    case kPgnDm1: send_dm1(now_s, out); break;
    case kPgnDm2:
      send(pgn, encode_diagnostic(dm2_), now_s, out);
      ++counters_.dm2_sent;
      break;
    default: nack(pgn, requester, to_us_alone, out); return;
  }
  ++counters_.requests_answered;
}

void Node::nack(std::uint32_t pgn, std::uint8_t requester, bool to_us_alone, std::vector<CanFrame>& out) {
  if (!to_us_alone) return;  // J1939-21: a global request for what we do not send goes unanswered
  out.push_back(acknowledgement(AckControl::Nack, pgn, requester, source()));
  ++counters_.nacks_sent;
}

void Node::send(std::uint32_t pgn, std::vector<std::uint8_t> data, double now_s, std::vector<CanFrame>& out) {
  if (data.size() <= 8) {
    CanFrame f;
    f.id = j1939_id(kDiagnosticPriority, pgn, source(), kGlobalAddress);
    f.len = 8;
    f.data.fill(0xFF);
    std::copy(data.begin(), data.end(), f.data.begin());
    out.push_back(f);
    return;
  }
  auto same = [pgn](const Waiting& w) { return w.pgn == pgn; };
  if (auto it = std::find_if(bam_waiting_.begin(), bam_waiting_.end(), same); it != bam_waiting_.end()) {
    it->data = std::move(data);
  } else {
    bam_waiting_.push_back({pgn, std::move(data)});
  }
  next_bam(now_s, out);
}

void Node::next_bam(double now_s, std::vector<CanFrame>& out) {
  if (!bam_packets_.empty() || bam_waiting_.empty() || !claimer_.may_transmit()) return;
  const Waiting w = std::move(bam_waiting_.front());
  bam_waiting_.erase(bam_waiting_.begin());
  auto frames = bam_frames(kTransportPriority, w.pgn, source(), w.data);
  out.push_back(frames.front());
  bam_packets_.assign(frames.begin() + 1, frames.end());
  bam_next_s_ = now_s + params_.bam_gap_s;
  ++counters_.bam_sent;
}

void Node::send_dm1(double now_s, std::vector<CanFrame>& out) {
  send(kPgnDm1, encode_diagnostic(dm1_), now_s, out);
  ++counters_.dm1_sent;
}

bool Node::set_dm1(const DiagnosticMessage& dm1, double now_s, std::vector<CanFrame>& out) {
  if (dm1.lamps == dm1_.lamps && dm1.dtcs == dm1_.dtcs) return false;
  dm1_ = dm1;
  change_waiting_ = true;
  tick(now_s, out);
  return true;
}

void Node::tick(double now_s, std::vector<CanFrame>& out) {
  const std::uint8_t before = source();
  claimer_.tick(now_s, out);
  if (source() != before) bam_packets_.clear();
  if (!claimer_.may_transmit()) return;
  if (!bam_packets_.empty() && now_s >= bam_next_s_) {
    out.push_back(bam_packets_.front());
    bam_packets_.pop_front();
    bam_next_s_ = now_s + params_.bam_gap_s;
  }
  const bool change_due = change_waiting_ && (!change_sent_s_ || now_s - *change_sent_s_ >= params_.dm1_period_s);
  const bool period_due = dm1_due_s_ && now_s >= *dm1_due_s_;
  if (change_due || period_due) {
    if (change_due) {
      change_sent_s_ = now_s;
      change_waiting_ = false;
    }
    send_dm1(now_s, out);
    dm1_due_s_ = now_s + params_.dm1_period_s;
  }
  next_bam(now_s, out);
}

}  // namespace fieldguard::output::j1939
