#pragma once
// The daemon's faults as J1939-73 diagnostic trouble codes (DM1), for the operator's terminal. Pure: a safety
// decision in, the active DTCs out, with each DTC's occurrence count kept from update to update.
//
// SPNs in J1939's proprietary range (520192-524287, 0x7F000-0x7FFFF), FMIs from J1939-73's list:
//   520192 + sensor (0 3D LiDAR, 1 2D LiDAR, 2 GNSS, 3 AHRS): FMI 9 "abnormal update rate" while the sensor is
//            silent past its timeout, FMI 2 "data erratic, intermittent or incorrect" while its data is implausible;
//   520200   the pipeline: FMI 9 while frames come late or not at all;
//   520201   the CAN output: FMI 12 "bad intelligent device" while frames cannot be sent (bus-off, write errors,
//            a full queue), FMI 31 "condition exists" while another node transmits with our address (J1939-81's
//            address violation). With no address at all nothing can be sent, DM1 included: the log and the status
//            say so instead.
// Lamps: amber warning on while any DTC is active; red stop on while one of them stops the tractor (every one
// does today: the safety monitor stops for each). Nothing is reported while the daemon is starting up (sensors
// not yet heard are the start-up, not a fault; the stop request says so).

#include <array>
#include <cstdint>

#include "fieldguard/output/j1939.hpp"
#include "fieldguard/output/safety_monitor.hpp"

namespace fieldguard::output::j1939 {

inline constexpr std::uint32_t kSpnFirstProprietary = 520192;
inline constexpr std::uint32_t kSpnPipeline = kSpnFirstProprietary + 8;
inline constexpr std::uint32_t kSpnCanOutput = kSpnFirstProprietary + 9;
inline constexpr std::uint8_t kFmiErratic = 2;
inline constexpr std::uint8_t kFmiAbnormalUpdateRate = 9;
inline constexpr std::uint8_t kFmiBadDevice = 12;
inline constexpr std::uint8_t kFmiConditionExists = 31;

// What the CAN side knows about itself, next to the safety decision.
struct BusFaults {
  bool send_errors = false;       // frames lost since the previous update (bus-off, write errors, full queue)
  bool address_conflict = false;  // Node::address_conflict()
};

[[nodiscard]] constexpr std::uint32_t sensor_spn(safety::Sensor s) {
  return kSpnFirstProprietary + static_cast<std::uint32_t>(s);
}

class Diagnostics {
 public:
  // The DM1 for `d`: its active DTCs in a fixed order (sensors, then the pipeline), each with how many times it
  // became active since the daemon started (126 at most, as J1939-73 counts).
  [[nodiscard]] DiagnosticMessage update(const safety::Decision& d, const BusFaults& bus = {});
  // DM2: the DTCs active at some time since the start and not now, with their counts; lamps off.
  [[nodiscard]] DiagnosticMessage previously_active() const;

 private:
  // Silent and implausible per sensor, the pipeline, the CAN output's two.
  static constexpr std::size_t kCodes = 2 * safety::kSensorCount + 3;
  [[nodiscard]] static Dtc code(std::size_t k);
  std::array<bool, kCodes> active_{};
  std::array<std::uint8_t, kCodes> occurrences_{};
};

}  // namespace fieldguard::output::j1939
