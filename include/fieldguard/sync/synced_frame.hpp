#pragma once
// The value sync hands to the worker pool: one frame of the configured rate (5 Hz by default) with everything
// the later stages need to put each point where it really was. All times are on the host clock, mapped from
// each sensor's own clock (clock_model.hpp).

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/core/time.hpp"
#include "fieldguard/drivers/nmea.hpp"
#include "fieldguard/drivers/scip_data.hpp"
#include "fieldguard/drivers/xsens_mtdata2.hpp"

namespace fieldguard::sync {

enum class SensorKind : std::uint8_t { Lidar3d = 0, Scan2d = 1, Gnss = 2, Ahrs = 3 };
inline constexpr std::size_t kSensorCount = 4;
inline constexpr std::array<SensorKind, kSensorCount> kAllSensors{SensorKind::Lidar3d, SensorKind::Scan2d,
                                                                  SensorKind::Gnss, SensorKind::Ahrs};
[[nodiscard]] constexpr std::string_view to_string(SensorKind k) {
  switch (k) {
    case SensorKind::Lidar3d: return "lidar3d";
    case SensorKind::Scan2d: return "scan2d";
    case SensorKind::Gnss: return "gnss";
    case SensorKind::Ahrs: return "ahrs";
  }
  return "?";
}
[[nodiscard]] constexpr std::uint8_t bit(SensorKind k) {
  return static_cast<std::uint8_t>(1U << static_cast<unsigned>(k));
}

// One 3D LiDAR rotation with its times mapped: point time_s is relative to `start`.
struct LidarRotation {
  std::uint64_t index = 0;  // the decoder's rotation index
  Stamp start;              // mapped time of the first firing
  Stamp end;                // mapped time of the last firing
  Stamp host;               // receive time of the first packet
  Stamp last_host;          // receive time of the packet carrying its last firing
  bool partial = false;
  std::vector<LidarPoint> points;
};

struct TimedScan {
  Stamp time;  // mapped sensor time
  Stamp host;  // receive time
  scip::Scan scan;
};

struct TimedGnss {
  Stamp time;
  Stamp host;
  nmea::Sentence sentence;  // GGA, RMC, VTG, HDT or THS; untimed types carry the time of their epoch's fix
};

struct TimedAttitude {
  Stamp time;
  Stamp host;
  xsens::MtData2 data;
};

struct SyncedFrame {
  std::uint64_t seq = 0;        // 0, 1, 2, ... in emission order, no gaps
  Stamp window_start;           // first firing of the first rotation
  Stamp window_end;             // last firing of the last rotation
  Stamp last_packet_host;       // receive time of the window's last 3D LiDAR packet: a decision's latency starts here
  std::uint32_t rotations = 0;  // whole rotations in the window (1 at 5 Hz spin, 2 at 10 Hz, ...)
  bool partial = false;         // a rotation was partial (stream start or end) or the window is short of a period
  std::vector<LidarPoint> points;   // time_s relative to window_start
  std::optional<TimedScan> scan2d;  // the scan nearest to the window's middle
  std::vector<TimedGnss> gnss;      // from the last epoch at or before window_start to the first at or after window_end
  std::vector<TimedAttitude> ahrs;  // likewise, every sample in between
  std::uint8_t missing = 0;         // bit(SensorKind) for each required sensor whose data is incomplete
  bool timed_out = false;           // emitted by the timeout, not because everything had arrived

  [[nodiscard]] bool is_missing(SensorKind k) const { return (missing & bit(k)) != 0; }
  [[nodiscard]] Stamp middle() const { return Stamp{window_start.ns + (window_end.ns - window_start.ns) / 2}; }
};

}  // namespace fieldguard::sync
