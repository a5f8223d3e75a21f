#pragma once
// The simulated LiDAR: an HDL-32E, a VLP-16 or an RS-LiDAR-32, in strongest or dual return, described by what the
// simulator needs to cast its rays and write its packets.
//
// All three put 12 data blocks of an azimuth and 32 three-byte returns ("slots") in a packet. A firing group is the
// firings that share a block azimuth: one block in strongest return; in dual return a pair of blocks, both holding
// the same 32 firings (each block one of their echoes), so that a dual packet covers half the time and azimuth.
// Every rotation starts with group 0 at azimuth 0, and a firing's azimuth is interpolated at its time: group g,
// slot s fires at (g + slot_fraction[s]) group durations into the rotation.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "sim/packet_encoder.hpp"

namespace fieldguard::sim {

enum class SensorModel : std::uint8_t { Hdl32e, Vlp16, Rs32 };
enum class ReturnMode : std::uint8_t { Strongest, Dual };

[[nodiscard]] std::optional<SensorModel> sensor_model(std::string_view name);  // hdl32e, vlp16, rs32
[[nodiscard]] std::optional<ReturnMode> return_mode(std::string_view name);    // strongest, dual
[[nodiscard]] std::string_view to_string(ReturnMode m);

struct Sensor {
  SensorModel model = SensorModel::Hdl32e;
  ReturnMode mode = ReturnMode::Strongest;
  std::string_view name;                        // as on the command line
  std::string_view label;                       // as in messages: HDL-32E, VLP-16, RS-LiDAR-32
  std::size_t lasers = 32;                      // slot s fires laser s % lasers
  std::array<double, kSlots> vertical_deg{};    // by slot, + up
  std::array<double, kSlots> horizontal_deg{};  // by slot, added to the firing azimuth (clockwise)
  std::array<std::int64_t, kSlots> slot_ns{};   // by slot: firing time after the group's first firing
  std::array<double, kSlots> slot_fraction{};   // the same in groups
  std::int64_t group_ns = 0;                    // one firing group
  double distance_unit_m = 0.002;
  double min_range_m = 0.0;       // nearer returns are not reported
  double optical_centre_m = 0.0;  // rays start this far from the rotation axis, along the firing azimuth
  std::uint16_t data_port = 0;
  std::uint16_t info_port = 0;  // device-info packets (RS-32 DIFOP): none when 0
  std::int64_t info_period_ns = 0;

  [[nodiscard]] bool dual() const { return mode == ReturnMode::Dual; }
  [[nodiscard]] std::size_t groups_per_packet() const { return dual() ? kBlocks / 2 : kBlocks; }
  [[nodiscard]] std::int64_t packet_ns() const { return group_ns * static_cast<std::int64_t>(groups_per_packet()); }
  // The packet's last firing after its first: the packet is sent (and recorded) then.
  [[nodiscard]] std::int64_t last_firing_ns() const;
  // Packets per rotation at a requested rate: the nearest whole number.
  [[nodiscard]] int packets_per_rotation(double rate_hz) const;

  // Whether the sensor spins at `rate_hz`, and the rule in words for --rate's message.
  [[nodiscard]] bool rate_supported(double rate_hz) const;
  [[nodiscard]] std::string rate_rule() const;

  [[nodiscard]] std::uint16_t encode_distance(double range_m) const {
    return sim::encode_distance(range_m, distance_unit_m);
  }
  // The two blocks of a dual-return pair, given a firing's echoes in range order (either may be none).
  [[nodiscard]] std::pair<EncodedReturn, EncodedReturn> dual_pair(EncodedReturn first, EncodedReturn last) const;
  // A data packet whose first firing is at `first_firing_unix_ns`.
  [[nodiscard]] PacketBytes encode(const PacketBlocks& blocks, std::int64_t first_firing_unix_ns) const;
  // A device-info packet sent at `unix_ns` by a sensor set to `rate_hz`.
  [[nodiscard]] PacketBytes encode_info(double rate_hz, std::int64_t unix_ns) const;
};

[[nodiscard]] Sensor make_sensor(SensorModel model, ReturnMode mode = ReturnMode::Strongest);

}  // namespace fieldguard::sim
