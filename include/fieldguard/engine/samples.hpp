#pragma once
// Decoded samples of every sensor as JSON lines, one decoder for both ends of a recording: `record` feeds it
// the live bytes as they arrive, `replay --session` feeds it the recorded files. The same bytes in, the
// same lines out, so a recording can be proved faithful by comparing the two (per sensor: lines of one
// sensor keep their order; sensors interleave differently live and in replay).

#include <cstdint>
#include <memory>
#include <ostream>

#include "fieldguard/config/config.hpp"
#include "fieldguard/core/bytes.hpp"
#include "fieldguard/drivers/lidar3d_stream.hpp"
#include "fieldguard/drivers/scip_client.hpp"
#include "fieldguard/io/udp_frame.hpp"

namespace fieldguard::app {

// The 3D LiDAR's stream as the configuration describes it (replay, the daemon and the sample decoder build the
// same one). An RS-32 decodes with nominal angles until its first DIFOP.
[[nodiscard]] lidar3d::StreamOptions lidar3d_stream_options(const LidarConfig& lidar);
// The SCIP client a recording's conversation was held with (replay re-plays it into a scip::Session).
[[nodiscard]] scip::ClientConfig scip_client_config(const Scan2dConfig& c);

struct SampleCounts {
  std::uint64_t lidar_frames = 0;
  std::uint64_t lidar_positions = 0;
  std::uint64_t scans = 0;
  std::uint64_t gnss = 0;
  std::uint64_t ahrs = 0;
};

class SampleDecoder {
 public:
  // `out` may be null: decode and count only.
  SampleDecoder(const Config& config, std::ostream* out);
  ~SampleDecoder();
  SampleDecoder(const SampleDecoder&) = delete;
  SampleDecoder& operator=(const SampleDecoder&) = delete;

  void lidar(const io::UdpDatagram& d);
  // to_sensor: bytes the client sent (a new connection starts with SCIP2.0); false: bytes from the sensor.
  void scan2d(ByteSpan bytes, bool to_sensor);
  void gnss(ByteSpan bytes);
  void ahrs(ByteSpan bytes);
  void finish();  // flushes what the stream decoders still hold

  [[nodiscard]] const SampleCounts& counts() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldguard::app
