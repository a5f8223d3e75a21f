#pragma once
// Velodyne HDL-32E / VLP-16 data packet decoder: bytes in, points out. Pure: no I/O, no threads, no logging.
// Thread-compatible: a const decoder may be used from several threads.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/expected.hpp"
#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/drivers/velodyne_calibration.hpp"
#include "fieldguard/drivers/velodyne_types.hpp"

namespace fieldguard::velodyne {

// What the packet says about itself, readable without a calibration.
struct PacketHeader {
  std::uint32_t timestamp_us = 0;  // microseconds past the top of the hour (bytes 1200..1203)
  std::uint8_t return_byte = 0;    // byte 1204
  std::uint8_t product_byte = 0;   // byte 1205
  ReturnMode return_mode = ReturnMode::Strongest;  // from byte 1204, or from the layout if it is unset
  bool dual_layout = false;        // blocks 0 and 1 carry the same azimuth
  std::uint16_t first_azimuth_cdeg = 0;
  std::uint16_t last_azimuth_cdeg = 0;
};

// Validates length, block flags and azimuths, and reads the header fields.
[[nodiscard]] Expected<PacketHeader, DecodeError> read_packet_header(ByteSpan payload);

struct DecoderOptions {
  Model model = Model::HDL32E;  // must be known here; see ModelDetector for "auto"
  TimestampReference timestamp_reference = TimestampReference::LastFiring;
  double min_range_m = 0.5;     // returns nearer than this are dropped (0 = "no return" is always dropped)
  double max_range_m = 130.0;
};

class Decoder {
 public:
  // Throws std::invalid_argument if the calibration does not fit the model (laser count).
  Decoder(const Calibration& calibration, const DecoderOptions& options);

  // Appends the packet's points to `out`. time_s of each point is seconds relative to the packet's
  // timestamp (the firing it marks), so a LastFiring reference gives negative offsets.
  // Dual-return packets yield both returns; a return identical in both blocks is emitted once as
  // StrongestAndLast.
  Expected<PacketHeader, DecodeError> decode(ByteSpan payload, std::vector<LidarPoint>& out) const;

  [[nodiscard]] Model model() const { return options_.model; }

 private:
  DecoderOptions options_;
  Calibration calibration_;
  // Precomputed per laser: cos/sin of the vertical angle, azimuth correction in 0.01 degree, offsets.
  struct LaserTable {
    float cos_vert;
    float sin_vert;
    float rot_cdeg;
    float dist_m;
    float vert_offset_m;
    float horiz_offset_m;
    std::uint16_t ring;
  };
  std::vector<LaserTable> table_;
};

// Decides HDL-32E vs VLP-16 from the stream: the factory byte AND the packet spacing / firing layout,
// since early VLP-16 firmware reports the HDL-32E's product byte 0x21. Feed packet headers in order.
class ModelDetector {
 public:
  void observe(const PacketHeader& header);
  [[nodiscard]] std::optional<Model> decided() const { return decided_; }
  // Why it decided what it did, for the log ("spacing 1327 us (VLP-16), product byte 0x21 (HDL-32E)").
  [[nodiscard]] const std::string& reason() const { return reason_; }

 private:
  std::optional<PacketHeader> last_;
  std::vector<std::uint32_t> spacings_us_;
  std::optional<Model> decided_;
  std::string reason_;
};

// Sensor time of a packet: microseconds past the hour combined with a host time near it, taking the hour
// from the host time and moving by one hour where the two differ by more than 30 minutes.
[[nodiscard]] Stamp sensor_time_from_hour_offset(std::uint32_t us_past_hour, Stamp host);

}  // namespace fieldguard::velodyne
