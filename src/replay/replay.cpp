// `fieldguard replay`: captured packets through the same decoders the daemon runs live.

#include "fieldguard/replay/replay.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "fieldguard/config/config.hpp"
#include "fieldguard/core/exit_code.hpp"
#include "fieldguard/drivers/lidar3d_stream.hpp"
#include "fieldguard/drivers/velodyne_position.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"
#include "fieldguard/engine/can_stage.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/engine/logging.hpp"
#include "fieldguard/engine/samples.hpp"
#include "fieldguard/engine/stage_times.hpp"
#include "fieldguard/io/byte_log.hpp"
#include "fieldguard/io/pcap_reader.hpp"
#include "fieldguard/output/can_sink.hpp"
#include "fieldguard/perception/obstacle_hold.hpp"
#include "fieldguard/perception/pipeline.hpp"
#include "fieldguard/sync/ordered_pool.hpp"
#include "fieldguard/sync/synchronizer.hpp"
#include "fieldguard/writers/bev.hpp"
#include "fieldguard/writers/geojson.hpp"
#include "fieldguard/writers/mcap_recorder.hpp"
#include "fieldguard/writers/obstacles_jsonl.hpp"
#include "fieldguard/writers/pcd_writer.hpp"
#include "replay/recording.hpp"

namespace fieldguard::app {
namespace {

namespace fs = std::filesystem;

struct PositionCounters {
  std::uint64_t packets = 0;
  std::uint64_t decoded = 0;
  std::uint64_t bad_length = 0;
  std::uint64_t rmc = 0;
  std::uint64_t nmea_rejected = 0;
  std::optional<velodyne::PositionPacket> last;
};

struct PortCounters {
  std::uint64_t other_port = 0;
};

std::string fmt_rmc(const nmea::Rmc& r) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s %04d-%02d-%02d lat %.6f lon %.6f", r.valid ? "valid" : "not valid",
                r.year.value_or(0), r.month.value_or(0), r.day.value_or(0), r.lat_deg.value_or(0.0),
                r.lon_deg.value_or(0.0));
  return buf;
}

// The median time of the pipeline a frame, and of each stage.
void print_stage_times(const std::vector<perception::StageTimes>& times) {
  if (times.empty()) return;
  std::printf("  pipeline time     %s\n", stage_times_line(times).c_str());
}

void print_summary(const std::string& pcap, const io::PcapStats& ps, const lidar3d::Stream& stream,
                   const PositionCounters& pos, const PortCounters& ports, std::uint64_t written, double wall_s,
                   double span_s) {
  const lidar3d::Counters c = stream.counters();
  std::printf("replay summary: %s\n", pcap.c_str());
  std::printf("  records read      %llu\n", static_cast<unsigned long long>(ps.records));
  std::printf("  udp datagrams     %llu\n", static_cast<unsigned long long>(ps.datagrams));
  if (ps.ip_length_repaired != 0) {
    std::printf("  ip length repaired %llu (IP total length past the frame; UDP length used)\n",
                static_cast<unsigned long long>(ps.ip_length_repaired));
  }
  std::printf("  data packets      %llu read, %llu decoded\n", static_cast<unsigned long long>(c.data_packets),
              static_cast<unsigned long long>(c.decoded));
  if (stream.family() == lidar3d::Family::RoboSense || c.info_packets != 0) {
    const robosense::StreamCounters& rc = stream.robosense().counters();
    std::printf("  difop packets     %llu read, %llu decoded; angles from %s\n",
                static_cast<unsigned long long>(rc.difop_packets), static_cast<unsigned long long>(rc.difop_accepted),
                stream.robosense().decoder().nominal() ? "the nominal table (no DIFOP had them)"
                : rc.difop_accepted != 0               ? "DIFOP"
                                                       : "the configured table");
  }
  std::printf("  position packets  %llu read, %llu decoded, %llu with RMC\n",
              static_cast<unsigned long long>(pos.packets), static_cast<unsigned long long>(pos.decoded),
              static_cast<unsigned long long>(pos.rmc));
  if (pos.last) {
    std::printf("  last position     pps %s", std::string(velodyne::to_string(pos.last->pps)).c_str());
    if (pos.last->rmc) std::printf(", RMC %s", fmt_rmc(*pos.last->rmc).c_str());
    std::printf("\n");
  }
  const auto m = stream.model();
  std::printf("  model             %s", m ? std::string(lidar3d::to_string(*m)).c_str() : "undecided");
  if (!stream.reason().empty()) std::printf(" (stream: %s)", stream.reason().c_str());
  std::printf("\n");
  if (const auto& id = stream.refused_as()) {
    std::printf("  refused           %llu MSOP packets of %s (%s): only the RS-LiDAR-32 is supported\n",
                static_cast<unsigned long long>(c.refused), id->name.empty() ? "an unknown sensor" : id->name.c_str(),
                id->detail.c_str());
  }

  std::uint64_t dropped = 0;
  std::string reasons;
  auto add = [&](const std::string& name, std::uint64_t n) {
    if (n == 0) return;
    dropped += n;
    reasons += "    " + name + std::string(name.size() < 24 ? 24 - name.size() : 1, ' ') + std::to_string(n) + "\n";
  };
  for (std::size_t i = 0; i < io::kFrameDropCount; ++i)
    add(std::string(io::to_string(static_cast<io::FrameDrop>(i))), ps.drops[i]);
  add("other_port", ports.other_port);
  add("data_bad_length", c.bad_length);
  add("other_lidar_family", c.other_family);
  add("msop_refused", c.refused);
  add("position_bad_length", pos.bad_length);
  add("position_nmea_rejected", pos.nmea_rejected);
  const velodyne::StreamCounters& vc = stream.velodyne().counters();
  for (std::size_t i = 0; i < velodyne::kDecodeErrorCount; ++i) {
    add("data_" + std::string(velodyne::to_string(static_cast<velodyne::DecodeError>(i))), vc.errors[i]);
  }
  const robosense::StreamCounters& rc = stream.robosense().counters();
  for (std::size_t i = 0; i < robosense::kDecodeErrorCount; ++i) {
    const std::string name(robosense::to_string(static_cast<robosense::DecodeError>(i)));
    add("msop_" + name, rc.msop_errors[i]);
    add("difop_" + name, rc.difop_errors[i]);
  }
  std::printf("  dropped           %llu\n%s", static_cast<unsigned long long>(dropped), reasons.c_str());
  if (ps.truncated) std::printf("  file truncated    yes: the capture ends inside a record\n");
  if (!ps.read_error.empty()) std::printf("  read error        %s\n", ps.read_error.c_str());
  std::printf("  rotations         %llu full, %llu partial\n", static_cast<unsigned long long>(c.full_rotations),
              static_cast<unsigned long long>(c.partial_rotations));
  std::printf("  points            %llu\n", static_cast<unsigned long long>(c.points));
  if (written > 0) std::printf("  pcd files         %llu\n", static_cast<unsigned long long>(written));
  std::printf("  capture span      %.3f s\n", span_s);
  std::printf("  wall time         %.3f s\n", wall_s);
}

// Receive times of one sensor's data, for the safety monitor of `--can-log`: a frame decided at capture time t
// must see the sensor as it was at t, not as far as the reader has got, or the output would depend on how far
// the workers lag behind the reader.
class HeardTimes {
 public:
  void add(Stamp t) { times_.push_back(t); }
  // The newest time at or before `t` (0 when none); forgets what no later question can need.
  Stamp at(Stamp t) {
    while (times_.size() > 1 && times_[1].ns <= t.ns) times_.pop_front();
    return !times_.empty() && times_.front().ns <= t.ns ? times_.front() : Stamp{};
  }

 private:
  std::deque<Stamp> times_;
};

// A frame on its way through the worker pool: see fusion.hpp.
struct Processed {
  DetectedFrame det;
};

using Pool = sync::OrderedPool<FrameJob, Processed>;

// Implausible GNSS / AHRS samples, by receive time: each goes to the first decision at or after it.
struct TimedProblem {
  Stamp at;
  output::safety::Sensor sensor;
  output::safety::Problem problem;
};

// One replay, in three steps: open() the inputs and outputs, read() every record through the frame path (frames
// are processed by the pool's workers and delivered here in frame order, where everything is written), then
// finish(): the summary and the exit code. Thread-compatible; its pool's workers call process() only.
class Replay {
 public:
  Replay(const ReplayOptions& opt, const Config& cfg, std::size_t workers)
      : opt_(opt), cfg_(cfg), workers_(workers), hold_(cfg.perception.hold) {}

  // The session, the capture, the byte logs and every output the options ask for. False (with the message
  // printed) when one cannot be opened.
  bool open();
  // Every record of the capture and the logs, merged by receive time, then the last frames and the pool drained.
  void read();
  // The summary on stdout and warnings on the log; the process exit code.
  int finish();

 private:
  bool open_outputs();
  void process(FrameJob& job, Processed& out);  // over the slot's earlier result (OrderedPool::ProcessInto)
  void deliver(const Pool::Result& r);
  void write_frame(const Pool::Result& r);
  void decide(const Pool::Result& r, const LidarFrame& f, perception::FrameResult& result);
  void submit_jobs();
  void on_datagram(const io::UdpDatagram& dg);
  void on_record(LogKind kind, const io::ByteLogRecord& rec);
  void progress_line();
  void print_fusion_summary() const;
  std::string can_log_error() const {
    return "cannot write " + *opt_.can_log + ": " + std::strerror(can_log_->stats().last_errno);
  }

  const ReplayOptions& opt_;
  const Config& cfg_;
  const std::size_t workers_;
  const std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
  std::shared_ptr<spdlog::logger> log_ = logger("replay");

  // Inputs.
  std::string pcap_path_;
  std::vector<LogFile> logs_;
  std::optional<RecordingReader> recording_;
  std::optional<SensorFusion> fusion_;
  // Outputs.
  std::ofstream samples_file_;
  std::optional<SampleDecoder> samples_;
  std::string pcd_dir_;
  std::string bev_dir_;
  std::ofstream obstacles_out_;
  std::optional<output::CandumpLogSink> can_log_;
  std::optional<McapRecorder> mcap_;
  std::optional<GeoJsonWriter> geojson_;
  // Without --can-log the obstacles JSONL still carries each frame's decision: the stage decides into a sink that
  // sends nowhere, from a configuration without the J1939 address claim (nothing is on a bus to contest it).
  output::NullSink no_bus_;
  std::optional<Config> decide_cfg_;
  std::optional<CanStage> can_;
  bool detect_ = false;  // the detection pipeline runs (an output needs its result)
  // The frame path.
  std::optional<DetectorSet> detectors_;
  std::optional<Pool> pool_;
  std::vector<FrameJob> jobs_;
  perception::ObstacleHold hold_;    // frame to frame, so here in frame order and not in the workers
  std::array<HeardTimes, 3> heard_;  // scan2d, gnss, ahrs: LogKind order
  std::deque<TimedProblem> problems_;
  // Counts for the summary.
  PositionCounters pos_;
  PortCounters ports_;
  std::uint64_t obstacles_total_ = 0;
  std::uint64_t held_total_ = 0;
  std::vector<perception::StageTimes> times_;  // each frame's
  std::uint64_t written_ = 0;
  std::uint64_t lost_ = 0;
  std::string write_error_;
  Stamp first_time_;
  Stamp last_time_;
  bool progress_ = false;
  std::chrono::steady_clock::time_point last_progress_ = started_;
};

bool Replay::open() {
  const std::string session_dir = opt_.session.value_or("");
  if (!session_dir.empty() && !fs::is_directory(session_dir)) {
    std::fprintf(stderr, "fieldguard replay: %s is not a directory written by `fieldguard record`\n",
                 session_dir.c_str());
    return false;
  }
  pcap_path_ = session_dir.empty() ? *opt_.pcap : (fs::path(session_dir) / "lidar.pcap").string();
  if (const auto& s = opt_.samples_out) {
    samples_file_.open(*s, std::ios::trunc);
    if (!samples_file_) {
      std::fprintf(stderr, "fieldguard replay: cannot write %s\n", s->c_str());
      return false;
    }
  }
  const std::tuple<const char*, LogKind, const std::optional<std::string>&> kLogNames[] = {
      {"scan2d", LogKind::Scan2d, opt_.scan2d_log},
      {"gnss", LogKind::Gnss, opt_.gnss_log},
      {"ahrs", LogKind::Ahrs, opt_.ahrs_log}};
  for (const auto& [name, kind, given] : kLogNames) {
    if (given) {
      logs_.push_back({*given, kind});
    } else if (!session_dir.empty() && fs::exists(fs::path(session_dir) / (std::string(name) + ".log"))) {
      logs_.push_back({(fs::path(session_dir) / (std::string(name) + ".log")).string(), kind});
    }
  }
  if (samples_file_.is_open()) samples_.emplace(cfg_, &samples_file_);
  auto recording = RecordingReader::open(pcap_path_, logs_);
  if (!recording) {
    std::fprintf(stderr, "fieldguard replay: %s\n", recording.error().c_str());
    return false;
  }
  recording_.emplace(std::move(recording).value());
  if (!open_outputs()) return false;
  fusion_.emplace(cfg_, FusionInputs{recording_->has(LogKind::Scan2d), recording_->has(LogKind::Gnss),
                                     recording_->has(LogKind::Ahrs)});
  detect_ =
      obstacles_out_.is_open() || !bev_dir_.empty() || can_.has_value() || mcap_.has_value() || geojson_.has_value();
  // A fused frame needs the compensation even when only its points are written.
  if (detect_ || fusion_->fused()) detectors_.emplace(cfg_, workers_);
  sync::PoolParams pool_params;
  pool_params.workers = workers_;
  pool_params.queue_capacity = static_cast<std::size_t>(cfg_.pipeline.queue_capacity);
  pool_.emplace(pool_params, [this](FrameJob& job, Processed& out) { process(job, out); });
  progress_ = !opt_.quiet && isatty(STDERR_FILENO) != 0;
  return true;
}

bool Replay::open_outputs() {
  auto make_dir = [](const std::string& option, const std::string& dir) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) {
      std::fprintf(stderr, "fieldguard replay: cannot create the %s directory %s: %s\n", option.c_str(), dir.c_str(),
                   ec ? ec.message().c_str() : "a file of that name exists");
      return false;
    }
    return true;
  };
  pcd_dir_ = opt_.pcd_dir.value_or("");
  bev_dir_ = opt_.bev_dir.value_or("");
  if (!pcd_dir_.empty() && !make_dir("PCD", pcd_dir_)) return false;
  if (!bev_dir_.empty() && !make_dir("bird's-eye", bev_dir_)) return false;
  if (const auto& o = opt_.obstacles_out) {
    obstacles_out_.open(*o, std::ios::binary | std::ios::trunc);
    if (!obstacles_out_) {
      std::fprintf(stderr, "fieldguard replay: cannot write %s\n", o->c_str());
      return false;
    }
  }
  if (const auto& m = opt_.mcap_out) {
    McapRecording rec;
    rec.path = *m;
    rec.options.compression = mcap_compression(opt_.mcap_compression).value_or(McapCompression::Zstd);
    mcap_.emplace(cfg_);
    if (!mcap_->open(rec)) {
      std::fprintf(stderr, "fieldguard replay: %s\n", mcap_->error().c_str());
      return false;
    }
  }
  if (const auto& g = opt_.geojson_out) {
    geojson_.emplace(cfg_.geo.projection, cfg_.lidar.mounting);
    if (!geojson_->open(*g)) {
      std::fprintf(stderr, "fieldguard replay: %s\n", geojson_->error().c_str());
      return false;
    }
  }
  if (const auto& c = opt_.can_log) {
    try {
      can_log_.emplace(*c, cfg_.can.interface);
      can_.emplace(cfg_, *can_log_);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "fieldguard replay: --can-log: %s\n", e.what());
      return false;
    }
  } else if (obstacles_out_.is_open() || mcap_ || !bev_dir_.empty()) {
    decide_cfg_ = cfg_;
    decide_cfg_->can.j1939.address_claim = false;
    can_.emplace(*decide_cfg_, no_bus_);
  }
  return true;
}

// On a worker: compensation and perception, the labelled points kept with the frame when an output draws them.
// Everything that is written happens in deliver(), on the reading thread, in frame order: the output does not
// depend on the number of workers.
void Replay::process(FrameJob& job, Processed& out) {
  if (!detectors_) {
    std::swap(out.det.frame, job.rotation);
    out.det.result = perception::FrameResult{};
    out.det.fusion.reset();
    return;
  }
  const DetectorSet::Lease detector(*detectors_);
  // The labelled points stay with the frame for the outputs drawn after its decision (MCAP, the picture).
  detector->process(job, out.det, detect_, mcap_.has_value() || !bev_dir_.empty());
}

void Replay::deliver(const Pool::Result& r) {
  if (r.outcome != sync::Outcome::Processed || r.output == nullptr) {
    // Replay uses the non-dropping submit, so this is a failed pipeline run; it is reported, never skipped.
    ++lost_;
    if (write_error_.empty()) {
      const FrameJob& j = *r.input;
      write_error_ = "frame " + std::to_string(j.synced ? j.synced->seq : j.rotation.index) + " was not processed (" +
                     sync::to_string(r.outcome) + (r.error != nullptr ? ": " + *r.error : std::string()) + ")";
    }
    return;
  }
  if (!write_error_.empty()) return;
  write_frame(r);
}

// One processed frame's outputs, in frame order: its PCD, then (when detecting) the hold, the CAN stage's
// decision, the obstacles line, GeoJSON, MCAP and the picture (with the decision and its stop zone).
void Replay::write_frame(const Pool::Result& r) {
  const LidarFrame& f = r.output->det.frame;
  const FusionInfo* fused = r.output->det.fusion ? &*r.output->det.fusion : nullptr;
  char stem[64];
  std::snprintf(stem, sizeof stem, "frame_%06llu%s", static_cast<unsigned long long>(f.index),
                f.partial ? "_partial" : "");
  if (!pcd_dir_.empty()) {
    write_error_ = write_pcd((fs::path(pcd_dir_) / (std::string(stem) + ".pcd")).string(), f);
    if (write_error_.empty()) ++written_;
  }
  if (!detect_) return;
  perception::FrameResult& result = r.output->det.result;
  // A fused frame levelled in full gives its pose: the hold moves what it remembers by the travel and turning.
  const std::optional<perception::FramePose> pose =
      fused != nullptr ? detection_pose(*fused, cfg_.lidar.mounting) : std::nullopt;
  hold_.apply(f.host_stamp.ns, result, std::nullopt, pose);
  held_total_ += result.counts.held;
  obstacles_total_ += result.obstacles.size();
  times_.push_back(result.times);
  // Decided before the obstacles line is written: the line carries the decision.
  if (can_) decide(r, f, result);
  const output::safety::Decision* decision = can_ && can_->last_decision() ? &*can_->last_decision() : nullptr;
  if (obstacles_out_.is_open() && write_error_.empty()) {
    obstacles_out_ << obstacles_json_line(f, result, fused, &cfg_.lidar.mounting, decision, cfg_.safety.clear_frames)
                   << '\n';
    if (!obstacles_out_) write_error_ = "cannot write " + *opt_.obstacles_out;
  }
  if (geojson_ && write_error_.empty() && !geojson_->frame(f, result, fused)) write_error_ = geojson_->error();
  if (mcap_ && write_error_.empty()) {
    if (!mcap_->frame(f, result, r.output->det.labelled, fused, decision)) write_error_ = mcap_->error();
  }
  if (!bev_dir_.empty() && write_error_.empty()) {
    const std::optional<perception::Box3> zone =
        decision != nullptr ? std::optional(stop_zone_box(decision->zone)) : std::nullopt;
    const BevCaption caption{f.index, f.host_stamp, f.partial, decision, cfg_.safety.clear_frames};
    write_error_ = render_bev(r.output->det.labelled, result.obstacles, cfg_.perception, zone, caption)
                       .write_png((fs::path(bev_dir_) / (std::string(stem) + ".png")).string());
  }
}

// The safety monitor on one frame, with every sensor as it was heard at the frame's decision time.
void Replay::decide(const Pool::Result& r, const LidarFrame& f, perception::FrameResult& result) {
  static constexpr output::safety::Sensor kHeardSensor[] = {output::safety::Sensor::Scan2d,
                                                            output::safety::Sensor::Gnss, output::safety::Sensor::Ahrs};
  for (std::size_t i = 0; i < heard_.size(); ++i) {
    const Stamp t = heard_[i].at(r.input->complete);
    if (t.ns != 0) can_->sensor_data(kHeardSensor[i], t);  // NOLINT(clang-analyzer-core.CallAndMessage): i < 3
  }
  while (!problems_.empty() && problems_.front().at.ns <= r.input->complete.ns) {
    can_->sensor_problem(problems_.front().sensor, problems_.front().problem);
    problems_.pop_front();
  }
  can_->frame(f, result, r.input->complete, lost_);
  if (can_log_ && can_log_->stats().write_errors != 0 && write_error_.empty()) write_error_ = can_log_error();
}

void Replay::submit_jobs() {
  const auto deliver = [this](const Pool::Result& r) { this->deliver(r); };
  for (auto& j : jobs_) {
    // Back-pressure instead of a drop: replay must lose no frame, so a full queue waits for results.
    while (!pool_->try_submit(j)) pool_->poll_wait(deliver);
    fusion_->recycle(j);  // the slot's earlier job, handed back
    pool_->poll(deliver);
  }
  jobs_.clear();
}

void Replay::on_datagram(const io::UdpDatagram& dg) {
  if (samples_) samples_->lidar(dg);
  if (const auto channel = fusion_->stream().channel_of(dg.dst_port)) {
    fusion_->lidar(*channel, dg.payload, dg.host_time, jobs_);
    submit_jobs();
  } else if (dg.dst_port == cfg_.lidar.position_port) {
    ++pos_.packets;
    auto p = velodyne::decode_position_packet(dg.payload);
    if (!p) {
      ++pos_.bad_length;
      return;
    }
    ++pos_.decoded;
    if (p->rmc) ++pos_.rmc;
    if (p->nmea_error) ++pos_.nmea_rejected;
    pos_.last = std::move(p).value();
  } else {
    ++ports_.other_port;
  }
}

void Replay::on_record(LogKind kind, const io::ByteLogRecord& rec) {
  const bool to_sensor = rec.direction == io::Direction::ToSensor;
  switch (kind) {
    case LogKind::Scan2d:
      if (samples_) samples_->scan2d(rec.bytes, to_sensor);
      fusion_->scan2d_bytes(rec.bytes, to_sensor, rec.host_time, jobs_);
      break;
    case LogKind::Gnss:
      if (samples_) samples_->gnss(rec.bytes);
      fusion_->gnss(rec.bytes, rec.host_time, jobs_);
      break;
    case LogKind::Ahrs:
      if (samples_) samples_->ahrs(rec.bytes);
      fusion_->ahrs(rec.bytes, rec.host_time, jobs_);
      break;
  }
  if (!to_sensor) heard_[static_cast<std::size_t>(kind)].add(rec.host_time);
  if (can_) {
    const auto p = fusion_->take_problems();
    if (p.gnss != output::safety::Problem::None) problems_.push_back({p.gnss_at, output::safety::Sensor::Gnss, p.gnss});
    if (p.ahrs != output::safety::Problem::None) problems_.push_back({p.ahrs_at, output::safety::Sensor::Ahrs, p.ahrs});
  }
  submit_jobs();
}

void Replay::progress_line() {
  const auto now = std::chrono::steady_clock::now();
  if (now - last_progress_ <= std::chrono::seconds(1)) return;
  last_progress_ = now;
  std::fprintf(stderr, "\r  %llu records, %llu frames ...",
               static_cast<unsigned long long>(recording_->capture().stats().records),
               static_cast<unsigned long long>(fusion_->counts().frames));
}

void Replay::read() {
  while (auto ev = recording_->next()) {
    if (first_time_.ns == 0) {
      first_time_ = ev->time;
      if (can_) can_->start(first_time_);
    }
    last_time_ = Stamp{std::max(last_time_.ns, ev->time.ns)};
    if (ev->datagram != nullptr) {
      on_datagram(*ev->datagram);
    } else {
      on_record(ev->kind, *ev->record);
    }
    if (progress_) progress_line();
  }
  fusion_->finish(last_time_, jobs_);
  submit_jobs();
  pool_->stop(sync::Drain::Yes);
  const auto deliver = [this](const Pool::Result& r) { this->deliver(r); };
  while (pool_->outstanding() > 0 && pool_->poll(deliver) > 0) {
  }
  if (can_) {
    can_->tick(last_time_, lost_);
    if (can_log_ && can_log_->stats().write_errors != 0 && write_error_.empty()) write_error_ = can_log_error();
  }
  if (progress_) std::fprintf(stderr, "\r%60s\r", "");
}

void Replay::print_fusion_summary() const {
  for (const auto& l : recording_->logs()) {
    std::printf("  %-17s %llu records (%s)%s%s\n", fs::path(l.file.path).filename().c_str(),
                static_cast<unsigned long long>(l.records), l.source.c_str(),
                l.truncated ? ", cut short at the end" : "", l.error.empty() ? "" : (", " + l.error).c_str());
  }
  if (!logs_.empty()) {
    const auto& fc = fusion_->counts();
    std::printf("  samples           %llu scans, %llu gnss sentences, %llu ahrs messages\n",
                static_cast<unsigned long long>(fc.scans), static_cast<unsigned long long>(fc.gnss),
                static_cast<unsigned long long>(fc.ahrs));
    if (fc.scan_errors + fc.gnss_errors + fc.ahrs_errors != 0) {
      std::printf("  sample errors     %llu scan2d, %llu gnss, %llu ahrs\n",
                  static_cast<unsigned long long>(fc.scan_errors), static_cast<unsigned long long>(fc.gnss_errors),
                  static_cast<unsigned long long>(fc.ahrs_errors));
    }
  }
  if (const sync::Synchronizer* sy = fusion_->synchronizer()) {
    const auto& ac = sy->assembler().counters();
    std::printf("  fused frames      %llu at %.3g Hz: %llu complete, %llu timed out (",
                static_cast<unsigned long long>(ac.frames), cfg_.sync.rate_hz,
                static_cast<unsigned long long>(ac.complete), static_cast<unsigned long long>(ac.timed_out));
    bool first = true;
    for (const sync::SensorKind k : sync::kAllSensors) {
      const auto n = ac.missing[static_cast<std::size_t>(k)];
      if (n == 0) continue;
      std::printf("%s%llu lacking %s", first ? "" : ", ", static_cast<unsigned long long>(n),
                  std::string(sync::to_string(k)).c_str());
      first = false;
    }
    std::printf("%s), %llu late rotations dropped\n", first ? "none lacking a sensor" : "",
                static_cast<unsigned long long>(ac.late_rotations));
  }
}

int Replay::finish() {
  const lidar3d::Stream& stream = fusion_->stream();
  const lidar3d::Counters counts = stream.counters();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  const io::PcapStats& pcap_stats = recording_->capture().stats();
  print_summary(pcap_path_, pcap_stats, stream, pos_, ports_, written_, wall_s,
                static_cast<double>(last_time_.ns - first_time_.ns) * 1e-9);
  if (detect_) {
    std::printf("  obstacles         %llu", static_cast<unsigned long long>(obstacles_total_));
    if (cfg_.perception.hold.enabled) {
      std::printf(" (%llu of them held from fragments)", static_cast<unsigned long long>(held_total_));
    }
    std::printf("\n");
    print_stage_times(times_);
  }
  std::printf("  workers           %zu, %llu frames lost\n", workers_, static_cast<unsigned long long>(lost_));
  if (can_) {
    const auto& cc = can_->counts();
    std::printf("  stop decisions    %llu stop, %llu go, %llu changes\n",
                static_cast<unsigned long long>(cc.stop_frames), static_cast<unsigned long long>(cc.go_frames),
                static_cast<unsigned long long>(cc.changes));
    if (can_log_) {
      std::printf("  can frames        %llu\n", static_cast<unsigned long long>(can_log_->stats().sent));
      std::printf("  j1939             %s\n", j1939_summary(can_->link()).c_str());
    }
  }
  print_fusion_summary();
  if (samples_) samples_->finish();
  if (geojson_) {
    if (!geojson_->close() && write_error_.empty()) write_error_ = geojson_->error();
    const GeoJsonCounts& g = geojson_->counts();
    std::printf("  geojson           %llu footprints from %llu frames with a pose; %llu frames without one\n",
                static_cast<unsigned long long>(g.features), static_cast<unsigned long long>(g.frames_placed),
                static_cast<unsigned long long>(g.frames_unplaced));
    if (g.frames_placed == 0) {
      log_->warn("--geojson-out: no frame had a full pose (a session with GNSS and AHRS is needed): no footprints");
    }
  }
  if (mcap_) {
    if (!mcap_->close() && write_error_.empty()) write_error_ = mcap_->error();
    const McapRecorderStats m = mcap_->stats();
    std::printf("  mcap              %llu frames, %llu messages, %.1f MB\n", static_cast<unsigned long long>(m.frames),
                static_cast<unsigned long long>(m.messages), static_cast<double>(m.bytes) * 1e-6);
  }

  if (pcap_stats.truncated)
    log_->warn("{} is truncated: it ends inside a record; everything before was used", pcap_path_);
  if (!pcap_stats.read_error.empty()) log_->warn("{}: reading stopped early: {}", pcap_path_, pcap_stats.read_error);
  const auto& detected = stream.velodyne().detector().decided();
  if (cfg_.lidar.model != lidar3d::Model::Auto && stream.family() == lidar3d::Family::Velodyne && detected &&
      std::string_view(velodyne::to_string(*detected)) != lidar3d::to_string(cfg_.lidar.model)) {
    log_->warn("lidar.model is {} but the packets look like a {} ({}); check the configuration",
               lidar3d::to_string(cfg_.lidar.model), velodyne::to_string(*detected),
               stream.velodyne().detector().reason());
  }
  if (counts.other_family != 0) {
    log_->warn(
        "{} packets of another 3D LiDAR family than the {} in use were dropped; check lidar.model and the "
        "ports",
        counts.other_family, stream.model() ? lidar3d::to_string(*stream.model()) : "one");
  }
  if (!write_error_.empty()) {
    std::fprintf(stderr, "fieldguard replay: %s\n", write_error_.c_str());
    return kExitFailure;
  }
  if (!logs_.empty() && counts.data_packets == 0 && counts.refused == 0) return kExitOk;  // no 3D LiDAR data
  if (counts.data_packets == 0 && counts.refused != 0) {
    const lidar3d::MsopIdentity& id = *stream.refused_as();
    std::fprintf(stderr,
                 "fieldguard replay: %s holds MSOP packets of %s (%s), not of an RS-LiDAR-32: fieldguard decodes the "
                 "HDL-32E, VLP-16 and RS-32 only\n",
                 pcap_path_.c_str(), id.name.empty() ? "an unknown sensor" : id.name.c_str(), id.detail.c_str());
    return kExitBadInput;
  }
  if (counts.data_packets == 0 && counts.other_family != 0) {
    std::fprintf(stderr,
                 "fieldguard replay: %s holds only packets of another 3D LiDAR than lidar.model %s (%llu dropped): "
                 "set lidar.model to auto or to the sensor's model\n",
                 pcap_path_.c_str(), std::string(lidar3d::to_string(cfg_.lidar.model)).c_str(),
                 static_cast<unsigned long long>(counts.other_family));
    return kExitBadInput;
  }
  if (counts.data_packets == 0) {
    std::fprintf(stderr,
                 "fieldguard replay: %s holds no UDP datagram to the data port %u (Velodyne) or the MSOP port %u "
                 "(RS-32): not a 3D LiDAR capture, or lidar.data_port / lidar.msop_port is wrong\n",
                 pcap_path_.c_str(), cfg_.lidar.data_port, cfg_.lidar.msop_port);
    return kExitBadInput;
  }
  if (counts.decoded == 0) {
    const bool rs32 = stream.family() == lidar3d::Family::RoboSense;
    std::fprintf(stderr, "fieldguard replay: none of the %llu datagrams to port %u in %s is a%s\n",
                 static_cast<unsigned long long>(counts.data_packets),
                 rs32 ? cfg_.lidar.msop_port : cfg_.lidar.data_port, pcap_path_.c_str(),
                 rs32 ? "n RS-32 MSOP packet" : " Velodyne data packet");
    return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace

int replay(const ReplayOptions& opt) {
  const auto loaded = load_config_file(opt.config);
  if (!loaded.ok()) {
    for (const auto& issue : loaded.issues) std::fprintf(stderr, "%s\n", issue.to_string().c_str());
    std::fprintf(stderr, "fieldguard replay: invalid configuration %s\n", opt.config.c_str());
    return kExitBadInput;
  }
  const Config& cfg = loaded.config;
  Replay replay(opt, cfg, opt.workers.value_or(static_cast<std::size_t>(cfg.pipeline.workers)));
  if (!replay.open()) return kExitBadInput;
  replay.read();
  return replay.finish();
}

}  // namespace fieldguard::app
