#pragma once
// Sync as one object: decoded samples with their receive times in, SyncedFrames out. Maps each sensor's own
// time onto the host clock (one SensorClock per sensor), feeds the FrameAssembler and keeps the HealthMonitor.
//
// Thread contract: thread-compatible; meant to be driven by the one thread that decodes (the io thread live,
// the reader in replay). Pure: `now` is passed in.

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/drivers/nmea.hpp"
#include "fieldguard/drivers/scip_data.hpp"
#include "fieldguard/drivers/xsens_mtdata2.hpp"
#include "fieldguard/sync/clock_model.hpp"
#include "fieldguard/sync/frame_assembler.hpp"
#include "fieldguard/sync/health.hpp"

namespace fieldguard::sync {

struct SyncParams {
  AssemblerParams assembler;
  ClockParams lidar_clock;
  ClockParams scan_clock;
  ClockParams gnss_clock = [] {
    ClockParams p;
    p.jump_threshold_s = 0.3;  // NMEA output comes 20..200 ms after the epoch, by receiver and sentence
    return p;
  }();
  ClockParams ahrs_clock;
  // A 3D LiDAR PPS-synchronised to the GNSS receiver keeps UTC in its packets: GNSS epochs are then mapped
  // through the LiDAR's clock model, so a fix and a point of the same UTC instant get the same host time.
  // Used only while the two models agree within max_gnss_latency_s (a LiDAR without PPS counts from its
  // power-on and never agrees); otherwise, or false, each epoch is mapped by the GNSS's own model, and the
  // receiver's output latency then counts as transport delay.
  bool gnss_utc_via_lidar = true;
  double max_gnss_latency_s = 0.3;
  double rate_window_s = 2.0;
  double untimed_pairing_s = 0.5;  // VTG/HDT/THS take the time of a fix received at most this long before
  // A window waiting for a sensor is normal for a moment (the GNSS fix after the window comes up to a fix period
  // plus its latency later); the status names the sensor once the window has waited this long.
  double waiting_grace_s = 0.25;
};

class Synchronizer {
 public:
  explicit Synchronizer(const SyncParams& params = {});  // throws std::invalid_argument when invalid

  // A rotation from velodyne::Stream (sensor_stamp: UTC from the microseconds past the hour).
  void push_lidar(LidarFrame&& rotation);
  void push_scan(scip::Scan&& scan, Stamp host);
  void push_gnss(nmea::Sentence&& sentence, Stamp host);
  void push_ahrs(xsens::MtData2&& data, Stamp host);
  // Decoder rejections, for the health counters.
  void count_decode_errors(SensorKind k, std::uint64_t n) { health_.errors(k).decode += n; }

  void poll(Stamp now, std::vector<SyncedFrame>& out);
  void finish(std::vector<SyncedFrame>& out);
  // Buffer reuse (FrameAssembler::recycle(), take_spare_points()).
  void recycle(SyncedFrame&& frame) { assembler_.recycle(std::move(frame)); }
  bool take_spare_points(std::vector<LidarPoint>& out) { return assembler_.take_spare_points(out); }
  std::size_t trim_spares() { return assembler_.trim_spares(); }

  // The one-line status; names the sensor the oldest waiting window needs once it has waited waiting_grace_s,
  // or the 3D LiDAR when it has been silent for more than two frame periods.
  [[nodiscard]] std::string status(Stamp now) const;
  [[nodiscard]] std::optional<SensorKind> waiting_for(Stamp now) const;

  [[nodiscard]] const HealthMonitor& health() const { return health_; }
  [[nodiscard]] const FrameAssembler& assembler() const { return assembler_; }
  [[nodiscard]] const SensorClock& clock(SensorKind k) const;
  // GNSS epochs mapped through the LiDAR's clock (gnss_utc_via_lidar).
  [[nodiscard]] std::uint64_t gnss_via_lidar() const { return gnss_via_lidar_; }

 private:
  SensorClock& clock_of(SensorKind k);
  void note(SensorKind k, const Mapping& m, Stamp host);

  SyncParams params_;
  FrameAssembler assembler_;
  HealthMonitor health_;
  SensorClock lidar_clock_;
  SensorClock scan_clock_;
  SensorClock gnss_clock_;
  SensorClock ahrs_clock_;
  std::optional<Stamp> last_fix_time_;  // mapped time of the last timed NMEA sentence
  std::optional<Stamp> last_fix_host_;
  std::uint64_t gnss_via_lidar_ = 0;
};

}  // namespace fieldguard::sync
