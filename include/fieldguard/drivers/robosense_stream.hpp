#pragma once
// A RoboSense RS-32 stream: MSOP and DIFOP packets in, rotations out. Joins the decoder (which waits for a
// DIFOP's angle table, as rs_driver's wait_for_difop does) with rotation assembly, and counts every packet by
// outcome. Pure and push-style (no I/O); one producer: not thread-safe.

#include <array>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/drivers/robosense.hpp"
#include "fieldguard/drivers/rotation_assembler.hpp"

namespace fieldguard::robosense {

struct StreamOptions {
  DecoderOptions decoder;
  double rotation_cut_deg = 0.0;
};

struct StreamCounters {
  std::uint64_t msop_packets = 0;                              // MSOP packets pushed
  std::uint64_t msop_decoded = 0;                              // MSOP packets that yielded points (or none in range)
  std::array<std::uint64_t, kDecodeErrorCount> msop_errors{};  // by DecodeError (NoCalibration: before DIFOP)
  std::uint64_t difop_packets = 0;                             // DIFOP packets pushed
  std::uint64_t difop_accepted = 0;                            // DIFOP packets parsed and applied
  std::array<std::uint64_t, kDecodeErrorCount> difop_errors{};
  std::uint64_t difop_without_angles = 0;  // DIFOP whose angle table is not written
  std::uint64_t difop_angle_changes = 0;   // DIFOP whose table differs from the one in use (kept: the first)
  std::uint64_t points = 0;
  std::uint64_t full_rotations = 0;
  std::uint64_t partial_rotations = 0;
  [[nodiscard]] std::uint64_t msop_rejected() const;
  [[nodiscard]] std::uint64_t difop_rejected() const;
};

class Stream {
 public:
  // Throws std::invalid_argument for an impossible configuration (see Decoder).
  explicit Stream(StreamOptions options = {});

  void push_msop(ByteSpan payload, Stamp host_time, std::vector<LidarFrame>& frames);
  void push_difop(ByteSpan payload);
  void finish(std::vector<LidarFrame>& frames);
  // Optional: hands back a frame the consumer is done with, so that its point buffer is reused for a later
  // rotation (RotationAssembler::recycle()).
  void recycle(LidarFrame&& frame) { assembler_.recycle(std::move(frame)); }
  std::size_t trim_spares() { return assembler_.trim_spares(); }  // RotationAssembler::trim_spares()

  [[nodiscard]] const StreamCounters& counters() const { return counters_; }
  [[nodiscard]] const Decoder& decoder() const { return decoder_; }
  [[nodiscard]] const std::optional<DifopInfo>& last_difop() const { return last_difop_; }

 private:
  void count_frames(const std::vector<LidarFrame>& frames, std::size_t from);

  Decoder decoder_;
  RotationAssembler assembler_;
  std::optional<DifopInfo> last_difop_;
  StreamCounters counters_;
};

}  // namespace fieldguard::robosense
