#pragma once
// The daemon's faults as J1939-73 diagnostic trouble codes (DM1), for the operator's terminal. Pure: a safety
// decision in, the active DTCs out, with each DTC's occurrence count kept from update to update.
//
// SPNs in J1939's proprietary range (520192-524287, 0x7F000-0x7FFFF), FMIs from J1939-73's list:
//   520192 + sensor (0 3D LiDAR, 1 2D LiDAR, 2 GNSS, 3 AHRS): FMI 9 "abnormal update rate" while the sensor is
//            silent past its timeout, FMI 2 "data erratic, intermittent or incorrect" while its data is implausible;
//   520200   the pipeline: FMI 9 while frames come late or not at all.
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
inline constexpr std::uint8_t kFmiErratic = 2;
inline constexpr std::uint8_t kFmiAbnormalUpdateRate = 9;

[[nodiscard]] constexpr std::uint32_t sensor_spn(safety::Sensor s) {
  return kSpnFirstProprietary + static_cast<std::uint32_t>(s);
}

class Diagnostics {
 public:
  // The DM1 for `d`: its active DTCs in a fixed order (sensors, then the pipeline), each with how many times it
  // became active since the daemon started (126 at most, as J1939-73 counts).
  [[nodiscard]] DiagnosticMessage update(const safety::Decision& d);

 private:
  static constexpr std::size_t kCodes = 2 * safety::kSensorCount + 1;  // silent and implausible per sensor, pipeline
  std::array<bool, kCodes> active_{};
  std::array<std::uint8_t, kCodes> occurrences_{};
};

}  // namespace fieldguard::output::j1939
