#include "fieldguard/output/address_claim.hpp"

#include <algorithm>
#include <stdexcept>

namespace fieldguard::output::j1939 {

namespace {

constexpr double kMaxAnswerDelayS = 0.153;  // J1939-81: Cannot Claim in answer to a request, 0 to 153 ms later

}  // namespace

std::vector<std::string> ClaimParams::validate() const {
  std::vector<std::string> problems;
  for (const auto& p : name.validate()) problems.push_back("name." + p);
  if (preferred_address > kMaxUnicastAddress) {
    problems.emplace_back("preferred_address: must be 0x00..0xFD (0xFE is the null address, 0xFF global)");
  }
  if (first_arbitrary > last_arbitrary || last_arbitrary > kMaxUnicastAddress) {
    problems.emplace_back("arbitrary range: first <= last <= 0xFD");
  }
  if (!(hold_s >= 0.0 && hold_s <= 5.0)) problems.emplace_back("hold_s: 0..5 s (J1939-81: 0.25)");
  return problems;
}

const char* to_string(ClaimState s) {
  switch (s) {
    case ClaimState::NotStarted: return "not started";
    case ClaimState::Claiming: return "claiming";
    case ClaimState::Claimed: return "claimed";
    case ClaimState::CannotClaim: return "cannot claim";
    case ClaimState::BusOff: return "bus off";
  }
  return "?";
}

AddressClaimer::AddressClaimer(const ClaimParams& params)
    : params_(params), name_(params.name.value()), answer_seed_(params.name.identity_number | 1U) {
  const auto problems = params.validate();
  if (!problems.empty()) {
    std::string msg = "invalid address claim parameters:";
    for (const auto& p : problems) msg += "\n  " + p;
    throw std::invalid_argument(msg);
  }
}

std::optional<std::uint8_t> AddressClaimer::address() const {
  if (holding() || state_ == ClaimState::BusOff) {
    if (address_ <= kMaxUnicastAddress) return address_;
  }
  return std::nullopt;
}

std::optional<std::uint8_t> AddressClaimer::address_of(std::uint64_t name) const {
  for (std::size_t a = 0; a < claimed_by_.size(); ++a) {
    if (claimed_by_[a] == name) return static_cast<std::uint8_t>(a);
  }
  return std::nullopt;
}

void AddressClaimer::claim(std::uint8_t address, double now_s, std::vector<CanFrame>& out) {
  address_ = address;
  state_ = ClaimState::Claiming;
  claimed_at_s_ = now_s;
  cannot_claim_due_s_.reset();
  out.push_back(address_claimed(name_, address_));
  ++counters_.claims_sent;
}

void AddressClaimer::start(double now_s, std::vector<CanFrame>& out) {
  if (state_ != ClaimState::NotStarted) return;
  claim(params_.preferred_address, now_s, out);
}

void AddressClaimer::lose(double now_s, std::vector<CanFrame>& out) {
  ++counters_.contests_lost;
  if (params_.name.arbitrary_address_capable) {
    // The next address of the range after the lost one, round the range once, that no one has claimed.
    const int first = params_.first_arbitrary;
    const int span = params_.last_arbitrary - first + 1;
    const int from = address_ >= first && address_ <= params_.last_arbitrary ? address_ - first + 1 : 0;
    for (int k = 0; k < span; ++k) {
      const auto a = static_cast<std::uint8_t>(first + (from + k) % span);
      if (a != address_ && !claimed_by_[a]) {
        claim(a, now_s, out);
        return;
      }
    }
  }
  state_ = ClaimState::CannotClaim;
  address_ = kNullAddress;
  out.push_back(cannot_claim(name_));
}

double AddressClaimer::answer_delay_s() {
  // A pseudo-random draw (xorshift32 seeded from our identity number): nodes answering the same request spread
  // their Cannot Claim over the 153 ms instead of colliding.
  answer_seed_ ^= answer_seed_ << 13U;
  answer_seed_ ^= answer_seed_ >> 17U;
  answer_seed_ ^= answer_seed_ << 5U;
  return kMaxAnswerDelayS * static_cast<double>(answer_seed_ % 1001U) / 1000.0;
}

void AddressClaimer::receive(const CanFrame& f, double now_s, std::vector<CanFrame>& out) {
  const J1939Fields j = j1939_fields(f.id);
  if (j.pgn == kPgnAddressClaimed && f.len == 8) {
    const std::uint64_t other = name_from_bytes(std::span<const std::uint8_t, 8>(f.data.data(), 8));
    if (j.source > kMaxUnicastAddress || other == name_) return;  // a Cannot Claim; or our own NAME echoed
    for (auto& n : claimed_by_) {
      if (n == other) n.reset();  // that NAME moved
    }
    claimed_by_[j.source] = other;
    if (!holding() || j.source != address_) return;
    if (name_ < other) {  // ours has priority: claim again, the other node must yield
      ++counters_.contests_won;
      out.push_back(address_claimed(name_, address_));
      ++counters_.claims_sent;
      claimed_by_[j.source].reset();
      return;
    }
    lose(now_s, out);
    return;
  }
  if (j.pgn == kPgnRequest) {
    const auto pgn = requested_pgn(std::span<const std::uint8_t>(f.data.data(), f.len));
    if (!pgn || *pgn != kPgnAddressClaimed) return;
    const bool to_us = j.destination == kGlobalAddress || (holding() && j.destination == address_);
    if (!to_us) return;
    if (holding()) {
      out.push_back(address_claimed(name_, address_));
      ++counters_.requests_answered;
    } else if (state_ == ClaimState::CannotClaim && !cannot_claim_due_s_) {
      cannot_claim_due_s_ = now_s + answer_delay_s();
    }
  }
}

void AddressClaimer::tick(double now_s, std::vector<CanFrame>& out) {
  if (state_ == ClaimState::Claiming && now_s - claimed_at_s_ >= params_.hold_s) state_ = ClaimState::Claimed;
  if (state_ == ClaimState::CannotClaim && cannot_claim_due_s_ && now_s >= *cannot_claim_due_s_) {
    cannot_claim_due_s_.reset();
    out.push_back(cannot_claim(name_));
    ++counters_.requests_answered;
  }
}

std::optional<double> AddressClaimer::next_due(double now_s) const {
  if (state_ == ClaimState::Claiming) return std::max(0.0, claimed_at_s_ + params_.hold_s - now_s);
  if (state_ == ClaimState::CannotClaim && cannot_claim_due_s_) return std::max(0.0, *cannot_claim_due_s_ - now_s);
  return std::nullopt;
}

void AddressClaimer::bus_off() {
  if (holding()) state_ = ClaimState::BusOff;
}

void AddressClaimer::bus_recovered(double now_s, std::vector<CanFrame>& out) {
  if (state_ != ClaimState::BusOff) return;
  // Another node may have taken the address while we were off: its claim is in the table, and then we claim it
  // anyway and let the NAMEs decide (the other node answers our claim with its own if it has priority).
  claim(address_, now_s, out);
}

}  // namespace fieldguard::output::j1939
