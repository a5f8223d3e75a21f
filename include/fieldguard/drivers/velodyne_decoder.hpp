#pragma once
// Velodyne HDL-32E / VLP-16 data packet decoder: bytes in, points out. Pure: no I/O, no threads, no logging.
// Thread-compatible: a const decoder may be used from several threads.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/expected.hpp"
#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/drivers/rotation_assembler.hpp"
#include "fieldguard/drivers/velodyne_calibration.hpp"
#include "fieldguard/drivers/velodyne_types.hpp"

namespace fieldguard::velodyne {

// What the packet says about itself, readable without a calibration.
struct PacketHeader {
  std::uint32_t timestamp_us = 0;                  // microseconds past the top of the hour (bytes 1200..1203)
  std::uint8_t return_byte = 0;                    // byte 1204
  std::uint8_t product_byte = 0;                   // byte 1205
  ReturnMode return_mode = ReturnMode::Strongest;  // from byte 1204, or from the layout if it is unset
  bool dual_layout = false;                        // blocks 0 and 1 carry the same azimuth
  std::uint16_t first_azimuth_cdeg = 0;
  std::uint16_t last_azimuth_cdeg = 0;
};

// Validates length, block flags and azimuths, and reads the header fields.
[[nodiscard]] Expected<PacketHeader, DecodeError> read_packet_header(ByteSpan payload);

struct DecoderOptions {
  Model model = Model::HDL32E;  // must be known here; see ModelDetector for "auto"
  TimestampReference timestamp_reference = TimestampReference::LastFiring;
  double min_range_m = 0.5;  // returns nearer than this are dropped (0 = "no return" is always dropped)
  double max_range_m = 130.0;
};

class Decoder {
 public:
  // Throws std::invalid_argument if the calibration does not fit the model (laser count).
  Decoder(const Calibration& calibration, const DecoderOptions& options);

  // Appends the packet's points to `out`. time_s of each point is seconds relative to the packet's
  // timestamp (the firing it marks), so a LastFiring reference gives negative offsets.
  // Dual-return packets yield both returns; a return identical in both blocks is emitted once as
  // StrongestAndLast. On an error nothing is appended.
  // Azimuth cos/sin come from a 0.01-degree table with linear interpolation (within 7e-8 of the exact values):
  // x and y lie within 0.02 mm of the exact geometry at 130 m (0.08 mm with the libm cos/sin of a float angle
  // used before). See src/drivers/velodyne_decoder_kernels.hpp.
  Expected<PacketHeader, DecodeError> decode(ByteSpan payload, std::vector<LidarPoint>& out) const;

  // Most points one data packet yields: one per slot (a dual-return pair of blocks yields two per slot of the pair).
  static constexpr std::size_t kMaxPointsPerPacket = kBlocksPerPacket * kSlotsPerBlock;

  // The same points as decode(payload, out), written to the front of `room` (whatever it held is overwritten,
  // up to all of it); `count` is set to the number of points (0 on an error). For writing straight into a frame:
  // RotationAssembler::append_room() / commit().
  Expected<PacketHeader, DecodeError> decode(ByteSpan payload, std::span<LidarPoint, kMaxPointsPerPacket> room,
                                             std::size_t& count) const;
  // The same, and `azimuths` set to bounds on the azimuth_cdeg of every point written (for
  // RotationAssembler::commit()); on an error, or where the firings' azimuths wrap past 0 inside the packet, the
  // bounds are AzimuthRange{} (every azimuth).
  Expected<PacketHeader, DecodeError> decode(ByteSpan payload, std::span<LidarPoint, kMaxPointsPerPacket> room,
                                             std::size_t& count, AzimuthRange& azimuths) const;

  // A packet's firing-group azimuths, read once from its block azimuths for both of velodyne::Stream's steps: their
  // bounds decide whether the packet lies inside the frame under way (RotationAssembler::in_frame_offset_s()), and
  // decode_accepted() decodes with them instead of reading them again. Made only by azimuths().
  class PacketAzimuths {
   public:
    // The bounds decode() gives with the points: AzimuthRange{} (every azimuth) where the firings' azimuths may
    // wrap past 0 inside the packet, or for a payload read_packet_header() would refuse.
    [[nodiscard]] AzimuthRange bounds() const { return bounds_; }

   private:
    friend class Decoder;
    std::array<float, kBlocksPerPacket> az_{};     // azimuth of each firing group (single return: 12, dual: 6)
    std::array<float, kBlocksPerPacket> delta_{};  // its step to the next group
    AzimuthRange bounds_;
    // The azimuth corrections the bounds were worked out with: decode_accepted() trusts them only where they are
    // its own (bit for bit), so that no PacketAzimuths can make it skip a wrap it needs.
    std::uint32_t min_rot_bits_ = 0;
    std::uint32_t max_rot_bits_ = 0;
    bool dual_ = false;
    bool valid_ = false;  // a 1206-byte payload whose block azimuths are all below 36000
  };

  // The steps of decode(), for velodyne::Stream, which has read the header (read_packet_header()) already and wants
  // the point times frame-relative straight from the decoder (RotationAssembler::in_frame_offset_s()):
  //  - accept(): the model checks decode() makes on top of read_packet_header() (NoModel, ModelMismatch);
  //  - azimuths(): the packet's group azimuths and the bounds decode() gives (before decoding the points);
  //  - decode_accepted(): the points of a packet accept() accepted, as decode() writes them, except that with a
  //    time_offset_s every time_s is float(time_offset_s + double(the packet-relative time)): exactly what
  //    RotationAssembler::commit() makes of it. `azimuths` must be azimuths() of the same payload and header;
  //    anything else (a payload of another length, another return layout, bad azimuths) decodes to nothing.
  [[nodiscard]] std::optional<DecodeError> accept(const PacketHeader& header) const;
  [[nodiscard]] PacketAzimuths azimuths(ByteSpan payload, const PacketHeader& header) const;
  [[nodiscard]] std::size_t decode_accepted(ByteSpan payload, const PacketHeader& header,
                                            const PacketAzimuths& azimuths,
                                            std::span<LidarPoint, kMaxPointsPerPacket> room,
                                            std::optional<double> time_offset_s) const;

  [[nodiscard]] Model model() const { return options_.model; }

 private:
  [[nodiscard]] Expected<PacketHeader, DecodeError> check(ByteSpan payload) const;
  // azimuths() of a payload read_packet_header() accepted with `dual` (its layout), length already checked.
  template <bool kDual>
  [[nodiscard]] PacketAzimuths read_azimuths(const std::uint8_t* bytes) const;
  [[nodiscard]] std::size_t decode_checked(const std::uint8_t* bytes, const PacketHeader& header,
                                           const PacketAzimuths& azimuths, LidarPoint* room,
                                           std::optional<double> time_offset_s) const;
  // How a firing's azimuth is brought into [0, 36000): not at all (the packet's azimuth bounds lie inside the turn),
  // by one add or subtract of a turn (fast_wrap_), or by fmod and libm cos/sin (corrections beyond 350 degrees).
  enum class Wrap : std::uint8_t { None, Fast, General };
  template <bool kDual, Wrap kWrap, bool kFrameTimes>
  [[nodiscard]] std::size_t decode_points(const std::uint8_t* bytes, const PacketHeader& header,
                                          const PacketAzimuths& groups, const float* times, double time_offset_s,
                                          LidarPoint* dst) const;

  DecoderOptions options_;
  Calibration calibration_;
  // Everything about each of the 32 slots of a block that does not depend on the packet, precomputed at
  // construction (protocols.md §1.7, §1.10): the laser's corrections and the slot's firing time in the block.
  // Structure of arrays, so that the per-slot loops vectorise.
  struct SlotTables {
    std::array<float, kSlotsPerBlock> cos_vert;
    std::array<float, kSlotsPerBlock> sin_vert;
    std::array<float, kSlotsPerBlock> rot_cdeg;  // azimuth correction, 0.01 degree, subtracted
    std::array<float, kSlotsPerBlock> dist_m;
    std::array<float, kSlotsPerBlock> vert_offset_m;
    std::array<float, kSlotsPerBlock> horiz_offset_m;
    std::array<float, kSlotsPerBlock> in_block_us;     // firing time after the block's first firing
    std::array<float, kSlotsPerBlock> block_fraction;  // in_block_us / block duration: share of the azimuth step
    std::array<std::uint16_t, kSlotsPerBlock> ring;
    std::array<std::uint32_t, kSlotsPerBlock> ring_word;  // the ring's half of a point's (azimuth, ring) word
    // vert_offset_m * sin_vert and vert_offset_m * cos_vert: products the per-point formulas take, rounded to float
    // here exactly as they would be there (one float multiply), so that a point costs two multiplies fewer.
    std::array<float, kSlotsPerBlock> vert_offset_sin;
    std::array<float, kSlotsPerBlock> vert_offset_cos;
    // The raw distances (units of the resolution) whose return is kept: raw_above < raw < raw_below. The range test
    // in integers, worked out at construction from the float test it replaces (min_range_m <= range <= max_range_m
    // and raw != 0; range = float(raw) * resolution + dist_m rises with raw), so that it keeps the same returns.
    std::array<std::int32_t, kSlotsPerBlock> raw_above;
    std::array<std::int32_t, kSlotsPerBlock> raw_below;
  };
  SlotTables slots_{};
  // Time of each firing of a packet (s), relative to the firing the packet timestamp marks: [0] single return
  // (12 firing groups), [1] dual (6); row g of 32 slots per group. Precomputed: the same floats for every packet.
  std::array<std::array<float, kBlocksPerPacket * kSlotsPerBlock>, 2> group_time_s_{};
  float block_us_ = 0.F;
  float last_firing_single_us_ = 0.F;  // the last firing of a packet after its first, single / dual return
  float last_firing_dual_us_ = 0.F;
  float resolution_m_ = 0.F;
  // Every |rot_cdeg| < 35000: an azimuth + step - correction stays inside (-36000, 72000), where one add or
  // subtract of a turn wraps it exactly as fmod does.
  bool fast_wrap_ = true;
  // Smallest and largest azimuth correction of the slots (0.01 degree): with the block azimuths they bound the
  // azimuth of every firing of a packet (AzimuthRange).
  float min_rot_cdeg_ = 0.F;
  float max_rot_cdeg_ = 0.F;
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
