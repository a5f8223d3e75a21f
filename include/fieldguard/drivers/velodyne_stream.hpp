#pragma once
// A Velodyne data stream: packets in, rotations out. Joins model detection, decoding and rotation assembly
// and counts every packet by outcome. Pure and push-style (no I/O); one producer: not thread-safe.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/drivers/rotation_assembler.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"

namespace fieldguard::velodyne {

struct StreamOptions {
  Model model = Model::Unknown;            // Unknown = detect from the stream
  std::optional<Calibration> calibration;  // none = the built-in table of the model
  TimestampReference timestamp_reference = TimestampReference::LastFiring;
  double min_range_m = 0.5;
  double max_range_m = 130.0;
  double rotation_cut_deg = 0.0;
  std::size_t max_undecided_packets = 16;  // packets held while the model is being detected
};

struct StreamCounters {
  std::uint64_t packets = 0;                              // data packets pushed
  std::uint64_t decoded = 0;                              // packets that yielded points (or a valid empty packet)
  std::array<std::uint64_t, kDecodeErrorCount> errors{};  // by DecodeError
  std::uint64_t points = 0;
  std::uint64_t full_rotations = 0;
  std::uint64_t partial_rotations = 0;
  [[nodiscard]] std::uint64_t rejected() const;
};

class Stream {
 public:
  // Throws std::invalid_argument when the calibration does not fit a configured model.
  explicit Stream(StreamOptions options);

  // Packets are decoded straight into the frame under construction (RotationAssembler::append_room()).
  void push(ByteSpan payload, Stamp host_time, std::vector<LidarFrame>& done);
  void finish(std::vector<LidarFrame>& done);
  // Optional: hands back a frame the consumer is done with, so that its point buffer is reused for a later
  // rotation instead of being freed and allocated again (RotationAssembler::recycle()).
  void recycle(LidarFrame&& frame) { assembler_.recycle(std::move(frame)); }
  std::size_t trim_spares() { return assembler_.trim_spares(); }  // RotationAssembler::trim_spares()

  [[nodiscard]] const StreamCounters& counters() const { return counters_; }
  // The model packets are decoded as (configured, taken from the calibration, or detected).
  [[nodiscard]] std::optional<Model> model() const;
  // What the stream itself says (detector verdict and reason), also when the model was configured.
  [[nodiscard]] const ModelDetector& detector() const { return detector_; }

 private:
  struct Held {
    std::vector<std::uint8_t> bytes;
    Stamp host;
  };
  void start_decoder(Model m);
  // A packet read_packet_header() accepted (`header`), once the decoder exists.
  void decode_one(ByteSpan payload, const PacketHeader& header, Stamp host_time, std::vector<LidarFrame>& done);
  void decode_held(const Held& held, std::vector<LidarFrame>& done);
  void count_frames(const std::vector<LidarFrame>& done, std::size_t from);

  StreamOptions options_;
  ModelDetector detector_;
  std::optional<Decoder> decoder_;
  RotationAssembler assembler_;
  std::vector<Held> held_;
  StreamCounters counters_;
};

}  // namespace fieldguard::velodyne
