#pragma once
// The one path from sensor data to detected frames that replay and the daemon share.
//
// SensorFusion (the io side, one thread): the sensors' bytes and packets in, with their receive times,
// FrameJobs out. Two modes, chosen once from which sensors feed it:
//   rotations  the 3D LiDAR alone: every rotation is a frame, its points in the LiDAR's own frame;
//   fused      a 2D LiDAR, GNSS or AHRS as well: sync::Synchronizer maps every sensor's clock onto the host
//              clock and cuts frames of whole rotations at sync.rate_hz with the 2D scan nearest in time and
//              the GNSS and AHRS samples around the window.
// FrameDetector (a worker's): a FrameJob in, a DetectedFrame out. A fused frame is first made into the levelled
// detection frame by geo::FrameCompensator (its own GNSS/AHRS samples only, so the result does not depend on
// which worker runs it or when), then perception runs on it.

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/config/config.hpp"
#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/core/time.hpp"
#include "fieldguard/drivers/nmea.hpp"
#include "fieldguard/drivers/scip_data.hpp"
#include "fieldguard/drivers/xsens_mtdata2.hpp"
#include "fieldguard/geo/frame_compensator.hpp"
#include "fieldguard/output/plausibility.hpp"
#include "fieldguard/perception/beam_geometry.hpp"
#include "fieldguard/perception/obstacle.hpp"
#include "fieldguard/perception/obstacle_hold.hpp"
#include "fieldguard/perception/pipeline.hpp"
#include "fieldguard/sync/synced_frame.hpp"

namespace fieldguard::lidar3d {
class Stream;
enum class Outcome : std::uint8_t;
enum class Channel : std::uint8_t;
enum class Model : std::uint8_t;
}  // namespace fieldguard::lidar3d
namespace fieldguard::sync {
class Synchronizer;
}

namespace fieldguard::app {

// The sensors that feed frames besides the 3D LiDAR.
struct FusionInputs {
  bool scan2d = false;
  bool gnss = false;
  bool ahrs = false;
  [[nodiscard]] bool any() const { return scan2d || gnss || ahrs; }
  // Live: the sensors the configuration enables.
  [[nodiscard]] static FusionInputs enabled_in(const Config& cfg) {
    return {cfg.scan2d.enabled, cfg.gnss.serial.enabled, cfg.ahrs.serial.enabled};
  }
};

// sync::SyncParams and geo::CompensationParams as the configuration gives them.
[[nodiscard]] geo::CompensationParams compensation_params(const Config& cfg);

// A frame on its way to a worker.
struct FrameJob {
  LidarFrame rotation;                      // rotations mode
  std::optional<sync::SyncedFrame> synced;  // fused mode
  // The 3D LiDAR's rings when the job was made (its decoder's table: built-in, calibration file or DIFOP), for
  // the rules scaled by their spacing (perception::Pipeline::set_beams()); shared by every job until it changes.
  std::shared_ptr<const perception::BeamGeometry> beams;
  Stamp complete;     // host time at which the frame was whole: its last data in hand (or its timeout)
  Stamp last_packet;  // receive time of its last 3D LiDAR packet (the kernel's, live): where its latency starts
};

// What the outputs need of the compensation.
struct FusionInfo {
  geo::Levelling levelling = geo::Levelling::None;
  std::optional<geo::PlaneCoord> reference;  // vehicle reference point at the frame's reference instant
  std::optional<geo::EulerDeg> attitude;
  geo::CompensationStats stats;
  std::uint8_t missing = 0;  // sync::bit() of the sensors the frame lacks
  bool timed_out = false;
  std::uint32_t rotations = 0;
  std::uint32_t scan_points = 0;  // lifted 2D points in the frame
};

// Where a fused frame's boxes stand, for the hold (perception::FramePose): the detection frame's origin in the
// plane and its heading, p_plane = reference + Rz(yaw) (p_detect + the LiDAR's mounting position), in the
// reference's zone. Only for a frame levelled in full (position and attitude: the frame's z is vertical and
// its place known); nothing otherwise.
[[nodiscard]] std::optional<perception::FramePose> detection_pose(const FusionInfo& f, const Mounting& lidar);

struct DetectedFrame {
  // The points detection ran on: the rotation, or the compensated fused frame (index: the frame's sequence
  // number, host_stamp: its window's start, partial: a partial window or a frame that lacks a sensor).
  LidarFrame frame;
  perception::FrameResult result;
  std::optional<FusionInfo> fusion;  // fused mode
  // The points detection worked on, labelled (Pipeline::last_points()), when the caller asked for them: a view
  // of the frame needs them after the worker's pipeline has moved on.
  std::vector<perception::LabeledPoint> labelled;
  // Wall-clock times on the worker, the worker's share of the frame's latency: taken up, compensated (= started
  // for a rotation), detected.
  Stamp started;
  Stamp compensated;
  Stamp finished;
};

class FrameDetector {
 public:
  explicit FrameDetector(const Config& cfg);
  // detect = false: compensation only (points to write). keep_labelled: d.labelled gets the labelled points.
  [[nodiscard]] DetectedFrame process(FrameJob& job, bool detect = true);
  // The same into `d`, an earlier frame's result whose buffers are reused: once warm, nothing is allocated. The
  // job keeps its own points (a fused frame's raw points; a rotation's trade places with d's earlier points), for
  // the producer to recycle (SensorFusion::recycle()).
  void process(FrameJob& job, DetectedFrame& d, bool detect = true, bool keep_labelled = false);
  [[nodiscard]] const perception::Pipeline& pipeline() const { return pipeline_; }

 private:
  void compensate(const sync::SyncedFrame& sf, DetectedFrame& d);  // into d.frame and d.fusion
  perception::Pipeline pipeline_;
  geo::FrameCompensator compensator_;
  geo::CompensatedFrame scratch_;
};

// A FrameDetector keeps scratch buffers between frames and is not thread-safe: each worker borrows one for the
// length of a frame. There are as many as workers, so a worker never finds the set empty.
class DetectorSet {
 public:
  DetectorSet(const Config& cfg, std::size_t n);
  class Lease {
   public:
    explicit Lease(DetectorSet& set);
    ~Lease();
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    Lease(Lease&&) = delete;
    Lease& operator=(Lease&&) = delete;
    FrameDetector& operator*() const { return *d_; }
    FrameDetector* operator->() const { return d_.get(); }

   private:
    DetectorSet& set_;
    std::unique_ptr<FrameDetector> d_;
  };

 private:
  std::mutex mutex_;
  std::vector<std::unique_ptr<FrameDetector>> free_;
};

struct FusionCounts {
  std::uint64_t frames = 0;       // jobs handed out
  std::uint64_t scans = 0;        // 2D scans decoded
  std::uint64_t gnss = 0;         // NMEA sentences decoded
  std::uint64_t ahrs = 0;         // MTData2 messages decoded
  std::uint64_t scan_errors = 0;  // SCIP framing or decoding errors
  std::uint64_t gnss_errors = 0;  // NMEA sentences rejected
  std::uint64_t ahrs_errors = 0;  // Xsens messages rejected
};

class SensorFusion {
 public:
  SensorFusion(const Config& cfg, FusionInputs inputs);
  ~SensorFusion();
  SensorFusion(const SensorFusion&) = delete;
  SensorFusion& operator=(const SensorFusion&) = delete;

  [[nodiscard]] bool fused() const { return inputs_.any(); }

  // A datagram of one of the 3D LiDAR's channels (lidar3d::Stream::push()) received at `host`.
  lidar3d::Outcome lidar(lidar3d::Channel channel, ByteSpan payload, Stamp host, std::vector<FrameJob>& out);
  // The 2D LiDAR's conversation as a byte log holds it (to_sensor: what the client sent; a new connection
  // starts with SCIP2.0) ...
  void scan2d_bytes(ByteSpan bytes, bool to_sensor, Stamp host, std::vector<FrameJob>& out);
  // ... or a scan a live scip source has already decoded.
  void scan(const scip::Scan& s, Stamp host, std::vector<FrameJob>& out);
  void gnss(ByteSpan bytes, Stamp host, std::vector<FrameJob>& out);
  void ahrs(ByteSpan bytes, Stamp host, std::vector<FrameJob>& out);
  // Frames whose timeout has passed at host time `now` (fused mode; nothing in rotations mode).
  void poll(Stamp now, std::vector<FrameJob>& out);
  // End of input: the rotation still open and every waiting window go out.
  void finish(Stamp now, std::vector<FrameJob>& out);
  // A job the pool handed back (OrderedPool::submit() swaps in the slot's earlier input): its buffers go back to
  // the 3D LiDAR's stream and the synchronizer, so that a steady stream allocates nothing once warm.
  void recycle(FrameJob& job);
  // Frees the spare buffers (rotations, frames) that sat unused since the last call, as after a burst; call it
  // now and then (the daemon: every second). Returns how many.
  std::size_t trim_spares();

  [[nodiscard]] const lidar3d::Stream& stream() const { return *stream_; }
  [[nodiscard]] const sync::Synchronizer* synchronizer() const { return sync_.get(); }
  [[nodiscard]] const FusionCounts& counts() const { return counts_; }

  // Plausibility of the GNSS fixes (GGA) and AHRS attitudes (MTData2 Euler angles) decoded so far, for the
  // safety monitor (`safety.gnss`, `safety.ahrs` limits), checked in every mode.
  struct Problems {
    output::safety::Problem gnss = output::safety::Problem::None;  // first since the previous take
    output::safety::Problem ahrs = output::safety::Problem::None;
    Stamp gnss_at;  // receive time of the sample that showed it
    Stamp ahrs_at;
  };
  [[nodiscard]] Problems take_problems();
  [[nodiscard]] std::string status(Stamp now) const;

 private:
  struct Decoders;
  void rotations_to(Stamp host, std::vector<FrameJob>& out);
  void frames_to(Stamp host, std::vector<FrameJob>& out);         // poll sync, then jobs_from_frames
  void jobs_from_frames(Stamp host, std::vector<FrameJob>& out);  // frames_ out as jobs complete at `host`
  void pass_sentences(Stamp host);                                // decoded NMEA: counted, checked, to sync
  void pass_items(Stamp host);                                    // decoded MTData2: likewise

  void check(const nmea::Sentence& s, Stamp host);
  void check(const xsens::MtData2& m, Stamp host);

  FusionInputs inputs_;
  output::safety::GnssCheck gnss_check_;
  output::safety::AhrsCheck ahrs_check_;
  Problems problems_;
  std::unique_ptr<lidar3d::Stream> stream_;
  // The stream's rings as a geometry, made again when they change (the sensor decided, a DIFOP's table).
  std::shared_ptr<const perception::BeamGeometry> beams_;
  std::optional<lidar3d::Model> beams_model_;
  bool beams_nominal_ = false;
  void refresh_beams();
  std::unique_ptr<sync::Synchronizer> sync_;
  std::unique_ptr<Decoders> dec_;
  std::vector<LidarFrame> rotations_;
  std::vector<sync::SyncedFrame> frames_;
  FusionCounts counts_;
};

}  // namespace fieldguard::app
