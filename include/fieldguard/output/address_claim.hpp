#pragma once
// J1939-81 / ISO 11783-5 address claiming for one controller application (us), pure: frames in, frames out, time
// given. The daemon and replay drive it the same way, whatever the bus (SocketCAN, the candump sink).
//
//   start()       Address Claimed for the preferred address; other messages wait hold_s (250 ms), the time
//                 another node has to contest the address.
//   a contest     an Address Claimed for our address from another NAME: the lower NAME keeps it. Winning, we
//                 claim again; losing, an arbitrary-address-capable NAME claims the next address of the
//                 self-configurable range no one has claimed, otherwise (or with none left) it sends Cannot
//                 Claim (Address Claimed from the null address 254) and transmits nothing more.
//   a request     for Address Claimed (PGN 59904 asking for 60928), to global or to our address: our claim
//                 again, or Cannot Claim after a pseudo-random 0-153 ms when we have no address; nothing
//                 before start() or while bus-off.
//   bus-off       nothing goes out; on recovery the address is claimed again.
// Every Address Claimed seen is remembered by address, so that another node's address can be found by its NAME.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/output/can_frame.hpp"
#include "fieldguard/output/j1939.hpp"

namespace fieldguard::output::j1939 {

struct ClaimParams {
  Name name;
  std::uint8_t preferred_address = 0x80;
  // Where an arbitrary-address-capable node goes after losing its address: J1939's self-configurable range.
  std::uint8_t first_arbitrary = 128;
  std::uint8_t last_arbitrary = 247;
  double hold_s = 0.25;

  [[nodiscard]] std::vector<std::string> validate() const;
};

enum class ClaimState : std::uint8_t {
  NotStarted,   // before start(): silent
  Claiming,     // claim sent, waiting hold_s for a contest
  Claimed,      // the address is ours: other messages may go out
  CannotClaim,  // lost it and found none: silent but for Cannot Claim
  BusOff,       // the controller is off the bus
};
[[nodiscard]] const char* to_string(ClaimState s);

class AddressClaimer {
 public:
  struct Counters {
    std::uint64_t claims_sent = 0;
    std::uint64_t contests_won = 0;
    std::uint64_t contests_lost = 0;
    std::uint64_t requests_answered = 0;
  };

  explicit AddressClaimer(const ClaimParams& params);  // throws std::invalid_argument when invalid

  void start(double now_s, std::vector<CanFrame>& out);
  // A frame from the bus (not one of ours).
  void receive(const CanFrame& f, double now_s, std::vector<CanFrame>& out);
  // Time passing: the claim becomes ours after hold_s; a delayed Cannot Claim goes out.
  void tick(double now_s, std::vector<CanFrame>& out);
  void bus_off();
  void bus_recovered(double now_s, std::vector<CanFrame>& out);

  [[nodiscard]] ClaimState state() const { return state_; }
  [[nodiscard]] bool may_transmit() const { return state_ == ClaimState::Claimed; }
  // The address we hold or are claiming; nullopt when we have none.
  [[nodiscard]] std::optional<std::uint8_t> address() const;
  [[nodiscard]] std::uint64_t name() const { return name_; }
  // The address `name` last claimed on the bus, while no one else took it since; nullopt otherwise.
  [[nodiscard]] std::optional<std::uint8_t> address_of(std::uint64_t name) const;
  [[nodiscard]] const Counters& counters() const { return counters_; }
  // Seconds until tick() has something to do (hold_s ending, a delayed answer); nullopt when nothing is due.
  [[nodiscard]] std::optional<double> next_due(double now_s) const;

 private:
  // Claiming or Claimed: an address is ours to defend and to answer requests with.
  [[nodiscard]] bool holding() const { return state_ == ClaimState::Claiming || state_ == ClaimState::Claimed; }
  void claim(std::uint8_t address, double now_s, std::vector<CanFrame>& out);
  void lose(double now_s, std::vector<CanFrame>& out);
  [[nodiscard]] double answer_delay_s();

  ClaimParams params_;
  std::uint64_t name_;
  ClaimState state_ = ClaimState::NotStarted;
  std::uint8_t address_ = kNullAddress;
  double claimed_at_s_ = 0.0;
  std::optional<double> cannot_claim_due_s_;
  std::uint32_t answer_seed_;
  std::array<std::optional<std::uint64_t>, 254> claimed_by_{};  // others' NAMEs by address 0..253
  Counters counters_;
};

}  // namespace fieldguard::output::j1939
