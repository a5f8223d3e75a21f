#include "fieldguard/engine/fusion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <variant>

#include "fieldguard/drivers/lidar3d_stream.hpp"
#include "fieldguard/drivers/nmea_stream.hpp"
#include "fieldguard/drivers/scip_session.hpp"
#include "fieldguard/drivers/xsens_stream.hpp"
#include "fieldguard/engine/samples.hpp"
#include "fieldguard/sync/synchronizer.hpp"

namespace fieldguard::app {

geo::CompensationParams compensation_params(const Config& cfg) {
  geo::CompensationParams p;
  p.projection = cfg.geo.projection;
  p.ahrs.frame = cfg.geo.ahrs_frame;
  p.ahrs.mounting = cfg.ahrs.mounting;
  p.ahrs.declination_deg = cfg.geo.declination_deg;
  p.antenna_m = {cfg.geo.antenna_m[0], cfg.geo.antenna_m[1], cfg.geo.antenna_m[2]};
  p.lidar = cfg.lidar.mounting;
  p.scanner = cfg.scan2d.mounting;
  p.min_gnss_quality = cfg.geo.min_gnss_quality;
  // Holding the end sample over a fraction of the gap that counts as a dropout, as the defaults do.
  p.track.max_attitude_gap_s = cfg.geo.max_attitude_gap_s;
  p.track.max_attitude_extrapolation_s = 0.4 * cfg.geo.max_attitude_gap_s;
  p.track.max_position_gap_s = cfg.geo.max_position_gap_s;
  p.track.max_position_extrapolation_s = 0.5 * cfg.geo.max_position_gap_s;
  return p;
}

namespace {

sync::SyncParams sync_params(const Config& cfg, const FusionInputs& in) {
  sync::SyncParams p;
  p.assembler.rate_hz = cfg.sync.rate_hz;
  p.assembler.timeout_s = cfg.sync.timeout_s;
  p.assembler.max_scan_offset_s = cfg.sync.max_scan_offset_s;
  p.assembler.max_pending = static_cast<std::size_t>(cfg.sync.max_pending);
  p.assembler.require_scan2d = in.scan2d;
  p.assembler.require_gnss = in.gnss;
  p.assembler.require_ahrs = in.ahrs;
  if (cfg.sync.extrapolate_pose) {
    // No further than the compensator's pose track extrapolates (compensation_params()).
    const geo::TrackParams track = compensation_params(cfg).track;
    p.assembler.gnss_lead_s = std::min(track.max_position_extrapolation_s, p.assembler.max_bracket_gap_s);
    p.assembler.ahrs_lead_s = std::min(track.max_attitude_extrapolation_s, p.assembler.max_bracket_gap_s);
  }
  return p;
}

}  // namespace

// ---- FrameDetector ------------------------------------------------------------------------------------

std::optional<perception::FramePose> detection_pose(const FusionInfo& f, const Mounting& lidar) {
  if (f.levelling != geo::Levelling::Full || !f.reference || !f.attitude) return std::nullopt;
  const double yaw = f.attitude->yaw_deg * (std::numbers::pi / 180.0);
  const double c = std::cos(yaw);
  const double s = std::sin(yaw);
  perception::FramePose p;
  p.x_m = f.reference->easting_m + c * lidar.x_m - s * lidar.y_m;
  p.y_m = f.reference->northing_m + s * lidar.x_m + c * lidar.y_m;
  p.z_m = f.reference->up_m + lidar.z_m;
  p.yaw_rad = yaw;
  p.plane = f.reference->zone;
  return p;
}

FrameDetector::FrameDetector(const Config& cfg) : pipeline_(cfg.perception), compensator_(compensation_params(cfg)) {}

DetectedFrame FrameDetector::process(FrameJob& job, bool detect) {
  DetectedFrame d;
  process(job, d, detect);
  return d;
}

void FrameDetector::process(FrameJob& job, DetectedFrame& d, bool detect, bool keep_labelled) {
  d.started = wall_clock_now();
  if (job.beams) (void)pipeline_.set_beams(*job.beams);  // the sensor's rings (a no-op once they are in force)
  const bool rotation = !job.synced;
  if (rotation) {
    // The rotation trades places with the earlier result's frame, whose buffer the job takes back to the producer.
    std::swap(d.frame, job.rotation);
    d.fusion.reset();
  } else {
    compensate(*job.synced, d);
  }
  d.compensated = wall_clock_now();
  if (!detect) {
    d.labelled.clear();
    d.result = perception::FrameResult{};
    d.finished = d.compensated;
    return;
  }
  try {
    pipeline_.process(d.frame.points, d.result);
  } catch (...) {
    if (rotation) std::swap(d.frame, job.rotation);  // the job is still the rotation that failed, for the report
    throw;
  }
  d.finished = wall_clock_now();
  d.labelled.clear();
  if (keep_labelled) {
    const auto points = pipeline_.last_points();
    d.labelled.assign(points.begin(), points.end());  // into the slot's earlier buffer: no allocation once warm
  }
}

void FrameDetector::compensate(const sync::SyncedFrame& sf, DetectedFrame& d) {
  compensator_.compensate(sf, scratch_);
  d.frame.index = sf.seq;
  d.frame.sensor_stamp = sf.window_start;
  d.frame.host_stamp = sf.window_start;
  d.frame.last_host_stamp = sf.last_packet_host;
  d.frame.partial = sf.partial;
  d.frame.packets = 0;
  // The compensated points to the result, and its earlier points' buffer to the compensator for the next frame.
  d.frame.points.swap(scratch_.points);
  d.fusion = FusionInfo{.levelling = scratch_.levelling,
                        .reference = scratch_.reference,
                        .attitude = scratch_.attitude,
                        .stats = scratch_.stats,
                        .missing = sf.missing,
                        .timed_out = sf.timed_out,
                        .rotations = sf.rotations,
                        .scan_points = static_cast<std::uint32_t>(scratch_.stats.scan.points_out)};
}

DetectorSet::DetectorSet(const Config& cfg, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) free_.push_back(std::make_unique<FrameDetector>(cfg));
}

DetectorSet::Lease::Lease(DetectorSet& set) : set_(set) {
  const std::lock_guard lock(set_.mutex_);
  if (set_.free_.empty()) throw std::logic_error("more workers than detectors");
  d_ = std::move(set_.free_.back());
  set_.free_.pop_back();
}

DetectorSet::Lease::~Lease() {
  const std::lock_guard lock(set_.mutex_);
  set_.free_.push_back(std::move(d_));
}

// ---- SensorFusion -------------------------------------------------------------------------------------

struct SensorFusion::Decoders {
  explicit Decoders(const Config& cfg) : session(scip_client_config(cfg.scan2d)) {}
  scip::Session session;
  nmea::StreamParser nmea;
  xsens::StreamParser xsens;
  std::vector<nmea::Sentence> sentences;
  std::vector<xsens::StreamItem> items;
};

SensorFusion::SensorFusion(const Config& cfg, FusionInputs inputs)
    : inputs_(inputs),
      gnss_check_(cfg.safety.gnss),
      ahrs_check_(cfg.safety.ahrs),
      stream_(std::make_unique<lidar3d::Stream>(lidar3d_stream_options(cfg.lidar))),
      dec_(std::make_unique<Decoders>(cfg)) {
  if (inputs_.any()) sync_ = std::make_unique<sync::Synchronizer>(sync_params(cfg, inputs_));
}

SensorFusion::~SensorFusion() = default;

// The rings change only when the sensor is decided and when an RS-32's first DIFOP replaces its nominal table:
// looked at again only then (nothing allocated per rotation).
void SensorFusion::refresh_beams() {
  const auto model = stream_->model();
  const bool nominal = stream_->robosense().decoder().nominal();
  if (beams_ && model == beams_model_ && nominal == beams_nominal_) return;
  beams_model_ = model;
  beams_nominal_ = nominal;
  const std::vector<double> rings = stream_->ring_elevations_deg();
  if (rings.size() >= 2) beams_ = std::make_shared<const perception::BeamGeometry>(rings);
}

void SensorFusion::rotations_to(Stamp host, std::vector<FrameJob>& out) {
  refresh_beams();
  for (LidarFrame& f : rotations_) {
    if (sync_) {
      sync_->push_lidar(std::move(f));
    } else {
      FrameJob& j = out.emplace_back();
      j.rotation = std::move(f);
      j.beams = beams_;
      j.complete = host;
      j.last_packet = j.rotation.last_host_stamp;
      ++counts_.frames;
    }
  }
  rotations_.clear();
  if (sync_) frames_to(host, out);
}

void SensorFusion::frames_to(Stamp host, std::vector<FrameJob>& out) {
  sync_->poll(host, frames_);
  jobs_from_frames(host, out);
  // The buffers of rotations copied into a frame, back to the stream for later rotations.
  std::vector<LidarPoint> points;
  while (sync_->take_spare_points(points)) {
    LidarFrame spare;
    spare.points.swap(points);
    stream_->recycle(std::move(spare));
  }
}

std::size_t SensorFusion::trim_spares() { return stream_->trim_spares() + (sync_ ? sync_->trim_spares() : 0); }

void SensorFusion::recycle(FrameJob& job) {
  if (job.rotation.points.capacity() > 0) stream_->recycle(std::move(job.rotation));
  if (job.synced && sync_) {
    sync_->recycle(std::move(*job.synced));
    job.synced.reset();
  }
}

void SensorFusion::jobs_from_frames(Stamp host, std::vector<FrameJob>& out) {
  for (sync::SyncedFrame& f : frames_) {
    FrameJob& j = out.emplace_back();
    j.synced = std::move(f);
    j.beams = beams_;
    j.complete = host;
    j.last_packet = j.synced->last_packet_host;
    ++counts_.frames;
  }
  frames_.clear();
}

lidar3d::Outcome SensorFusion::lidar(lidar3d::Channel channel, ByteSpan payload, Stamp host,
                                     std::vector<FrameJob>& out) {
  const lidar3d::Outcome o = stream_->push(channel, payload, host, rotations_);
  if (!rotations_.empty()) rotations_to(host, out);
  return o;
}

void SensorFusion::scan2d_bytes(ByteSpan bytes, bool to_sensor, Stamp host, std::vector<FrameJob>& out) {
  if (to_sensor) {
    // The client opens every connection with SCIP2.0: that is where the live session was reset.
    static constexpr char kFirst[] = "SCIP2.0";
    if (bytes.size() >= 7 && std::equal(bytes.begin(), bytes.begin() + 7, kFirst)) (void)dec_->session.connect();
    return;
  }
  scip::SessionEvents ev = dec_->session.on_bytes(bytes);
  counts_.scan_errors += ev.decode_errors + ev.parser_errors;
  if (sync_) sync_->count_decode_errors(sync::SensorKind::Scan2d, ev.decode_errors + ev.parser_errors);
  for (scip::Scan& s : ev.scans) {
    ++counts_.scans;
    if (sync_ && inputs_.scan2d) sync_->push_scan(std::move(s), host);
  }
  if (sync_) frames_to(host, out);
}

void SensorFusion::scan(const scip::Scan& s, Stamp host, std::vector<FrameJob>& out) {
  ++counts_.scans;
  if (!sync_ || !inputs_.scan2d) return;
  scip::Scan copy = s;
  sync_->push_scan(std::move(copy), host);
  frames_to(host, out);
}

void SensorFusion::gnss(ByteSpan bytes, Stamp host, std::vector<FrameJob>& out) {
  const std::uint64_t rejected = dec_->nmea.counters().rejected() - dec_->nmea.counters().unsupported;
  dec_->nmea.push(bytes, dec_->sentences);
  const std::uint64_t now_rejected = dec_->nmea.counters().rejected() - dec_->nmea.counters().unsupported;
  counts_.gnss_errors += now_rejected - rejected;
  if (sync_) sync_->count_decode_errors(sync::SensorKind::Gnss, now_rejected - rejected);
  pass_sentences(host);
  if (sync_) frames_to(host, out);
}

void SensorFusion::ahrs(ByteSpan bytes, Stamp host, std::vector<FrameJob>& out) {
  const std::uint64_t rejected = dec_->xsens.counters().rejected();
  dec_->xsens.push(bytes, dec_->items);
  const std::uint64_t now_rejected = dec_->xsens.counters().rejected();
  counts_.ahrs_errors += now_rejected - rejected;
  if (sync_) sync_->count_decode_errors(sync::SensorKind::Ahrs, now_rejected - rejected);
  pass_items(host);
  if (sync_) frames_to(host, out);
}

void SensorFusion::pass_sentences(Stamp host) {
  for (nmea::Sentence& s : dec_->sentences) {
    ++counts_.gnss;
    check(s, host);
    if (sync_ && inputs_.gnss) sync_->push_gnss(std::move(s), host);
  }
  dec_->sentences.clear();
}

void SensorFusion::pass_items(Stamp host) {
  for (xsens::StreamItem& it : dec_->items) {
    auto* m = std::get_if<xsens::MtData2>(&it);
    if (m == nullptr) continue;
    ++counts_.ahrs;
    check(*m, host);
    if (sync_ && inputs_.ahrs) sync_->push_ahrs(std::move(*m), host);
  }
  dec_->items.clear();
}

void SensorFusion::poll(Stamp now, std::vector<FrameJob>& out) {
  if (sync_) frames_to(now, out);
}

void SensorFusion::finish(Stamp now, std::vector<FrameJob>& out) {
  stream_->finish(rotations_);
  rotations_to(now, out);
  if (!sync_) return;
  dec_->nmea.finish(dec_->sentences);
  pass_sentences(now);
  dec_->xsens.finish(dec_->items);
  pass_items(now);
  sync_->finish(frames_);
  jobs_from_frames(now, out);
}

void SensorFusion::check(const nmea::Sentence& s, Stamp host) {
  const auto* g = std::get_if<nmea::Gga>(&s);
  if (g == nullptr) return;
  output::safety::GnssFix f;
  // The receive time: a serial line keeps the order, so only the jump check uses it, as the interval.
  f.sensor = host;
  f.quality = g->quality;
  f.satellites = g->satellites;
  f.hdop = g->hdop;
  f.lat_deg = g->lat_deg.value_or(std::numeric_limits<double>::quiet_NaN());
  f.lon_deg = g->lon_deg.value_or(std::numeric_limits<double>::quiet_NaN());
  if (!g->quality || *g->quality == 0) {
    // No fix: empty position fields are normal then; the fix check speaks, not the NaN check.
    if (std::isnan(f.lat_deg)) f.lat_deg = 0.0;
    if (std::isnan(f.lon_deg)) f.lon_deg = 0.0;
  }
  const auto p = gnss_check_.check(f);
  if (p != output::safety::Problem::None && problems_.gnss == output::safety::Problem::None) {
    problems_.gnss = p;
    problems_.gnss_at = host;
  }
}

void SensorFusion::check(const xsens::MtData2& m, Stamp host) {
  if (!m.euler_deg) return;
  output::safety::Attitude a;
  // SampleTimeFine counts 10 kHz; 0 (absent) skips the rate check.
  a.sensor = m.sample_time_fine ? Stamp{static_cast<std::int64_t>(*m.sample_time_fine) * 100'000} : Stamp{};
  a.roll_deg = m.euler_deg->x;
  a.pitch_deg = m.euler_deg->y;
  a.yaw_deg = m.euler_deg->z;
  const auto p = ahrs_check_.check(a);
  if (p != output::safety::Problem::None && problems_.ahrs == output::safety::Problem::None) {
    problems_.ahrs = p;
    problems_.ahrs_at = host;
  }
}

SensorFusion::Problems SensorFusion::take_problems() { return std::exchange(problems_, Problems{}); }

std::string SensorFusion::status(Stamp now) const { return sync_ ? sync_->status(now) : std::string(); }

}  // namespace fieldguard::app
