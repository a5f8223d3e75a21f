#pragma once
// A 3D LiDAR point and a frame of them (one rotation).

#include <cstdint>
#include <vector>

#include "fieldguard/core/time.hpp"

namespace fieldguard {

// Which sensor measured a point of a merged frame (geo/frame_compensator.hpp lifts the 2D LiDAR's scan into
// the 3D LiDAR's frame, each point marked).
enum class PointSource : std::uint8_t { Lidar3d = 0, Lidar2d = 1 };

enum class ReturnType : std::uint8_t { Strongest = 1, Last = 2, StrongestAndLast = 3, SecondStrongest = 4 };

// Sensor frame of REP-103: x forward (azimuth 0), y left, z up, metres.
struct LidarPoint {
  float x = 0.F;
  float y = 0.F;
  float z = 0.F;
  float intensity = 0.F;           // raw reflectivity, 0..255
  float time_s = 0.F;              // seconds after the frame's sensor stamp (packet-relative in a decoder)
  float range_m = 0.F;             // distance from the sensor origin after calibration
  std::uint16_t azimuth_cdeg = 0;  // azimuth of the firing, 0.01 degree, clockwise from x
  std::uint16_t ring = 0;          // laser ring, 0 = lowest beam
  ReturnType return_type = ReturnType::Strongest;
  std::uint8_t source = 0;  // PointSource: which sensor measured it (a decoder writes 3D LiDAR)
  std::uint16_t reserved1 = 0;
};
static_assert(sizeof(LidarPoint) == 32, "LidarPoint is a plain 32-byte record");

struct LidarFrame {
  std::uint64_t index = 0;    // 0-based rotation index in the stream
  Stamp sensor_stamp;         // sensor time of the first firing in the frame
  Stamp host_stamp;           // host / pcap time of the frame's first packet
  Stamp last_host_stamp;      // host / pcap time of the packet carrying its last point (kernel receive time live)
  bool partial = false;       // the first or last rotation of a stream, not a full 360 degrees
  std::uint32_t packets = 0;  // data packets that contributed
  std::vector<LidarPoint> points;
};

}  // namespace fieldguard
