// `fieldguard replay`: captured packets through the same decoders the daemon runs live.

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

#include "fieldguard/writers/bev.hpp"
#include "fieldguard/engine/can_stage.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/engine/logging.hpp"
#include "fieldguard/writers/obstacles_jsonl.hpp"
#include "fieldguard/writers/pcd_writer.hpp"
#include "fieldguard/writers/png_writer.hpp"
#include "replay/recording.hpp"
#include "fieldguard/engine/samples.hpp"
#include "fieldguard/engine/stage_times.hpp"
#include "fieldguard/io/byte_log.hpp"
#include "fieldguard/perception/pipeline.hpp"
#include "fieldguard/config/config.hpp"
#include "fieldguard/drivers/velodyne_position.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"
#include "fieldguard/io/pcap_reader.hpp"
#include "fieldguard/replay/replay.hpp"
#include "fieldguard/core/exit_code.hpp"
#include "fieldguard/output/can_sink.hpp"
#include "fieldguard/perception/obstacle_hold.hpp"
#include "fieldguard/sync/ordered_pool.hpp"
#include "fieldguard/sync/synchronizer.hpp"

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
  std::uint64_t data_bad_length = 0;
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

void print_summary(const std::string& pcap, const io::PcapStats& ps, const velodyne::Stream& stream,
                   const PositionCounters& pos, const PortCounters& ports, std::uint64_t written, double wall_s,
                   double span_s) {
  const auto& c = stream.counters();
  std::printf("replay summary: %s\n", pcap.c_str());
  std::printf("  records read      %llu\n", static_cast<unsigned long long>(ps.records));
  std::printf("  udp datagrams     %llu\n", static_cast<unsigned long long>(ps.datagrams));
  if (ps.ip_length_repaired != 0) {
    std::printf("  ip length repaired %llu (IP total length past the frame; UDP length used)\n",
                static_cast<unsigned long long>(ps.ip_length_repaired));
  }
  std::printf("  data packets      %llu read, %llu decoded\n", static_cast<unsigned long long>(c.packets),
              static_cast<unsigned long long>(c.decoded));
  std::printf("  position packets  %llu read, %llu decoded, %llu with RMC\n",
              static_cast<unsigned long long>(pos.packets), static_cast<unsigned long long>(pos.decoded),
              static_cast<unsigned long long>(pos.rmc));
  if (pos.last) {
    std::printf("  last position     pps %s", std::string(velodyne::to_string(pos.last->pps)).c_str());
    if (pos.last->rmc) std::printf(", RMC %s", fmt_rmc(*pos.last->rmc).c_str());
    std::printf("\n");
  }
  const auto m = stream.model();
  std::printf("  model             %s", m ? std::string(velodyne::to_string(*m)).c_str() : "undecided");
  if (!stream.detector().reason().empty()) std::printf(" (stream: %s)", stream.detector().reason().c_str());
  std::printf("\n");

  std::uint64_t dropped = 0;
  std::string reasons;
  auto add = [&](const std::string& name, std::uint64_t n) {
    if (n == 0) return;
    dropped += n;
    reasons += "    " + name + std::string(name.size() < 24 ? 24 - name.size() : 1, ' ') + std::to_string(n) + "\n";
  };
  for (std::size_t i = 0; i < io::kFrameDropCount; ++i) add(std::string(io::to_string(static_cast<io::FrameDrop>(i))), ps.drops[i]);
  add("other_port", ports.other_port);
  add("data_bad_length", ports.data_bad_length);
  add("position_bad_length", pos.bad_length);
  add("position_nmea_rejected", pos.nmea_rejected);
  for (std::size_t i = 0; i < velodyne::kDecodeErrorCount; ++i) {
    add("data_" + std::string(velodyne::to_string(static_cast<velodyne::DecodeError>(i))), c.errors[i]);
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
  std::optional<Image> bev;  // rendered by the worker: it needs that worker's Pipeline::last_points()
};

using Pool = sync::OrderedPool<FrameJob, Processed>;

}  // namespace

int replay(const ReplayOptions& opt) {
  const auto log = logger("replay");
  const auto started = std::chrono::steady_clock::now();

  const auto loaded = load_config_file(opt.config);
  if (!loaded.ok()) {
    for (const auto& issue : loaded.issues) std::fprintf(stderr, "%s\n", issue.to_string().c_str());
    std::fprintf(stderr, "fieldguard replay: invalid configuration %s\n", opt.config.c_str());
    return kExitBadInput;
  }
  const Config& cfg = loaded.config;
  const std::size_t workers = opt.workers.value_or(static_cast<std::size_t>(cfg.pipeline.workers));

  const std::string session_dir = opt.session.value_or("");
  if (!session_dir.empty() && !fs::is_directory(session_dir)) {
    std::fprintf(stderr, "fieldguard replay: %s is not a directory written by `fieldguard record`\n", session_dir.c_str());
    return kExitBadInput;
  }
  const std::string pcap_path = session_dir.empty() ? *opt.pcap : (fs::path(session_dir) / "lidar.pcap").string();
  std::ofstream samples_file;
  if (const auto& s = opt.samples_out) {
    samples_file.open(*s, std::ios::trunc);
    if (!samples_file) {
      std::fprintf(stderr, "fieldguard replay: cannot write %s\n", s->c_str());
      return kExitBadInput;
    }
  }
  std::vector<LogFile> logs;
  const std::tuple<const char*, LogKind, const std::optional<std::string>&> kLogNames[] = {
      {"scan2d", LogKind::Scan2d, opt.scan2d_log}, {"gnss", LogKind::Gnss, opt.gnss_log},
      {"ahrs", LogKind::Ahrs, opt.ahrs_log}};
  for (const auto& [name, kind, given] : kLogNames) {
    if (given) {
      logs.push_back({*given, kind});
    } else if (!session_dir.empty() && fs::exists(fs::path(session_dir) / (std::string(name) + ".log"))) {
      logs.push_back({(fs::path(session_dir) / (std::string(name) + ".log")).string(), kind});
    }
  }
  std::optional<SampleDecoder> samples;
  if (samples_file.is_open()) samples.emplace(cfg, &samples_file);
  auto recording = RecordingReader::open(pcap_path, logs);
  if (!recording) {
    std::fprintf(stderr, "fieldguard replay: %s\n", recording.error().c_str());
    return kExitBadInput;
  }
  const FusionInputs inputs{recording->has(LogKind::Scan2d), recording->has(LogKind::Gnss), recording->has(LogKind::Ahrs)};

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
  const std::string pcd_dir = opt.pcd_dir.value_or("");
  const std::string bev_dir = opt.bev_dir.value_or("");
  if (!pcd_dir.empty() && !make_dir("PCD", pcd_dir)) return kExitBadInput;
  if (!bev_dir.empty() && !make_dir("bird's-eye", bev_dir)) return kExitBadInput;
  std::ofstream obstacles_out;
  if (const auto& o = opt.obstacles_out) {
    obstacles_out.open(*o, std::ios::binary | std::ios::trunc);
    if (!obstacles_out) {
      std::fprintf(stderr, "fieldguard replay: cannot write %s\n", o->c_str());
      return kExitBadInput;
    }
  }
  std::optional<output::CandumpLogSink> can_log;
  std::optional<CanStage> can;
  if (const auto& c = opt.can_log) {
    try {
      can_log.emplace(*c, cfg.can.interface);
      can.emplace(cfg, *can_log);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "fieldguard replay: --can-log: %s\n", e.what());
      return kExitBadInput;
    }
  }
  auto can_log_error = [&] {
    return "cannot write " + *opt.can_log + ": " + std::strerror(can_log->stats().last_errno);
  };
  SensorFusion fusion(cfg, inputs);
  const bool detect = obstacles_out.is_open() || !bev_dir.empty() || can.has_value();
  // A fused frame needs the compensation even when only its points are written.
  std::optional<DetectorSet> detectors;
  if (detect || fusion.fused()) detectors.emplace(cfg, workers);
  std::uint64_t obstacles_total = 0;
  std::vector<perception::StageTimes> times;  // each frame's, for the summary
  std::array<HeardTimes, 3> heard;  // scan2d, gnss, ahrs: LogKind order
  // Implausible GNSS / AHRS samples, by receive time: each goes to the first decision at or after it.
  struct TimedProblem {
    Stamp at;
    output::safety::Sensor sensor;
    output::safety::Problem problem;
  };
  std::deque<TimedProblem> problems;
  const output::safety::Sensor kHeardSensor[] = {output::safety::Sensor::Scan2d, output::safety::Sensor::Gnss,
                                                 output::safety::Sensor::Ahrs};

  PositionCounters pos;
  PortCounters ports;
  std::vector<FrameJob> jobs;
  std::uint64_t written = 0;
  std::uint64_t lost = 0;
  std::string write_error;
  Stamp first_time;
  Stamp last_time;
  const bool progress = !opt.quiet && isatty(STDERR_FILENO) != 0;
  auto last_progress = started;

  // Workers: compensation, perception (and the bird's-eye picture, which needs the worker's pipeline). Everything
  // that is written happens in deliver(), on this thread, in frame order: the output does not depend on the count.
  auto process = [&](FrameJob& job) {
    Processed out;
    if (!detectors) {
      out.det.frame = std::move(job.rotation);
      return out;
    }
    const DetectorSet::Lease detector(*detectors);
    out.det = detector->process(job, detect);
    if (!bev_dir.empty()) out.bev = render_bev(detector->pipeline().last_points(), out.det.result, cfg.perception, std::nullopt);
    return out;
  };
  // Frame to frame, so here in frame order and not in the workers (obstacle_hold.hpp).
  perception::ObstacleHold hold(cfg.perception.hold);
  std::uint64_t held_total = 0;
  std::vector<perception::Obstacle> held;  // one frame's held obstacles, for its picture
  auto deliver = [&](const Pool::Result& r) {
    if (r.outcome != sync::Outcome::Processed || r.output == nullptr) {
      // Replay uses the non-dropping submit, so this is a failed pipeline run; it is reported, never skipped.
      ++lost;
      if (write_error.empty()) {
        const FrameJob& j = *r.input;
        write_error = "frame " + std::to_string(j.synced ? j.synced->seq : j.rotation.index) + " was not processed (" +
                      sync::to_string(r.outcome) + (r.error != nullptr ? ": " + *r.error : std::string()) + ")";
      }
      return;
    }
    if (!write_error.empty()) return;
    const LidarFrame& f = r.output->det.frame;
    const FusionInfo* fused = r.output->det.fusion ? &*r.output->det.fusion : nullptr;
    char stem[64];
    std::snprintf(stem, sizeof stem, "frame_%06llu%s", static_cast<unsigned long long>(f.index),
                  f.partial ? "_partial" : "");
    if (!pcd_dir.empty()) {
      write_error = write_pcd((fs::path(pcd_dir) / (std::string(stem) + ".pcd")).string(), f);
      if (write_error.empty()) ++written;
    }
    if (!detect) return;
    perception::FrameResult& result = r.output->det.result;
    // A fused frame levelled in full gives its pose: the hold moves what it remembers by the travel and turning.
    const std::optional<perception::FramePose> pose =
        fused != nullptr ? detection_pose(*fused, cfg.lidar.mounting) : std::nullopt;
    hold.apply(f.host_stamp.ns, result, std::nullopt, pose);
    held_total += result.counts.held;
    if (result.counts.held > 0 && r.output->bev) {
      held.clear();
      for (const auto& o : result.obstacles) {
        if (o.held) held.push_back(o);
      }
      draw_obstacles(*r.output->bev, held);
    }
    obstacles_total += result.obstacles.size();
    times.push_back(result.times);
    if (obstacles_out.is_open() && write_error.empty()) {
      obstacles_out << obstacles_json_line(f, result, fused, &cfg.lidar.mounting) << '\n';
      if (!obstacles_out) write_error = "cannot write " + *opt.obstacles_out;
    }
    if (r.output->bev && write_error.empty()) {
      write_error = write_png((fs::path(bev_dir) / (std::string(stem) + ".png")).string(), *r.output->bev);
    }
    if (can) {
      for (std::size_t i = 0; i < heard.size(); ++i) {
        const Stamp t = heard[i].at(r.input->complete);
        if (t.ns != 0) can->sensor_data(kHeardSensor[i], t);
      }
      while (!problems.empty() && problems.front().at.ns <= r.input->complete.ns) {
        can->sensor_problem(problems.front().sensor, problems.front().problem);
        problems.pop_front();
      }
      can->frame(f, result, r.input->complete, lost);
      if (can_log->stats().write_errors != 0 && write_error.empty()) write_error = can_log_error();
    }
  };
  sync::PoolParams pool_params;
  pool_params.workers = workers;
  pool_params.queue_capacity = static_cast<std::size_t>(cfg.pipeline.queue_capacity);
  Pool pool(pool_params, process);
  auto handle_jobs = [&] {
    for (auto& j : jobs) {
      // Back-pressure instead of a drop: replay must lose no frame, so a full queue waits for results.
      while (!pool.try_submit(j)) pool.poll_wait(deliver);
      pool.poll(deliver);
    }
    jobs.clear();
  };

  auto on_datagram = [&](const io::UdpDatagram& dg) {
    if (samples) samples->lidar(dg);
    if (dg.dst_port == cfg.lidar.data_port) {
      if (dg.payload.size() != velodyne::kDataPacketSize) {
        ++ports.data_bad_length;
        return;
      }
      fusion.lidar(dg.payload, dg.host_time, jobs);
      handle_jobs();
    } else if (dg.dst_port == cfg.lidar.position_port) {
      ++pos.packets;
      auto p = velodyne::decode_position_packet(dg.payload);
      if (!p) {
        ++pos.bad_length;
        return;
      }
      ++pos.decoded;
      if (p->rmc) ++pos.rmc;
      if (p->nmea_error) ++pos.nmea_rejected;
      pos.last = std::move(p).value();
    } else {
      ++ports.other_port;
    }
  };
  auto on_record = [&](LogKind kind, const io::ByteLogRecord& rec) {
    const bool to_sensor = rec.direction == io::Direction::ToSensor;
    switch (kind) {
      case LogKind::Scan2d:
        if (samples) samples->scan2d(rec.bytes, to_sensor);
        fusion.scan2d_bytes(rec.bytes, to_sensor, rec.host_time, jobs);
        break;
      case LogKind::Gnss:
        if (samples) samples->gnss(rec.bytes);
        fusion.gnss(rec.bytes, rec.host_time, jobs);
        break;
      case LogKind::Ahrs:
        if (samples) samples->ahrs(rec.bytes);
        fusion.ahrs(rec.bytes, rec.host_time, jobs);
        break;
    }
    if (!to_sensor) heard[static_cast<std::size_t>(kind)].add(rec.host_time);
    if (can) {
      const auto p = fusion.take_problems();
      if (p.gnss != output::safety::Problem::None) problems.push_back({p.gnss_at, output::safety::Sensor::Gnss, p.gnss});
      if (p.ahrs != output::safety::Problem::None) problems.push_back({p.ahrs_at, output::safety::Sensor::Ahrs, p.ahrs});
    }
    handle_jobs();
  };

  // The capture and the byte logs, merged by receive time.
  while (auto ev = recording->next()) {
    if (first_time.ns == 0) {
      first_time = ev->time;
      if (can) can->start(first_time);
    }
    last_time = Stamp{std::max(last_time.ns, ev->time.ns)};
    if (ev->datagram != nullptr) {
      on_datagram(*ev->datagram);
    } else {
      on_record(ev->kind, *ev->record);
    }
    if (progress) {
      const auto now = std::chrono::steady_clock::now();
      if (now - last_progress > std::chrono::seconds(1)) {
        last_progress = now;
        std::fprintf(stderr, "\r  %llu records, %llu frames ...",
                     static_cast<unsigned long long>(recording->capture().stats().records),
                     static_cast<unsigned long long>(fusion.counts().frames));
      }
    }
  }
  fusion.finish(last_time, jobs);
  handle_jobs();
  pool.stop(sync::Drain::Yes);
  while (pool.outstanding() > 0 && pool.poll(deliver) > 0) {
  }
  if (can) {
    can->tick(last_time, lost);
    if (can_log->stats().write_errors != 0 && write_error.empty()) write_error = can_log_error();
  }
  if (progress) std::fprintf(stderr, "\r%60s\r", "");

  const velodyne::Stream& stream = fusion.stream();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const io::PcapStats& pcap_stats = recording->capture().stats();
  print_summary(pcap_path, pcap_stats, stream, pos, ports, written, wall_s,
                static_cast<double>(last_time.ns - first_time.ns) * 1e-9);
  if (detect) {
    std::printf("  obstacles         %llu", static_cast<unsigned long long>(obstacles_total));
    if (cfg.perception.hold.enabled) {
      std::printf(" (%llu of them held from fragments)", static_cast<unsigned long long>(held_total));
    }
    std::printf("\n");
    print_stage_times(times);
  }
  std::printf("  workers           %zu, %llu frames lost\n", workers, static_cast<unsigned long long>(lost));
  if (can) {
    const auto& cc = can->counts();
    std::printf("  stop decisions    %llu stop, %llu go, %llu changes\n", static_cast<unsigned long long>(cc.stop_frames),
                static_cast<unsigned long long>(cc.go_frames), static_cast<unsigned long long>(cc.changes));
    std::printf("  can frames        %llu\n", static_cast<unsigned long long>(can_log->stats().sent));
  }
  for (const auto& l : recording->logs()) {
    std::printf("  %-17s %llu records (%s)%s%s\n", fs::path(l.file.path).filename().c_str(),
                static_cast<unsigned long long>(l.records), l.source.c_str(), l.truncated ? ", cut short at the end" : "",
                l.error.empty() ? "" : (", " + l.error).c_str());
  }
  if (!logs.empty()) {
    const auto& fc = fusion.counts();
    std::printf("  samples           %llu scans, %llu gnss sentences, %llu ahrs messages\n",
                static_cast<unsigned long long>(fc.scans), static_cast<unsigned long long>(fc.gnss),
                static_cast<unsigned long long>(fc.ahrs));
    if (fc.scan_errors + fc.gnss_errors + fc.ahrs_errors != 0) {
      std::printf("  sample errors     %llu scan2d, %llu gnss, %llu ahrs\n", static_cast<unsigned long long>(fc.scan_errors),
                  static_cast<unsigned long long>(fc.gnss_errors), static_cast<unsigned long long>(fc.ahrs_errors));
    }
  }
  if (const sync::Synchronizer* sy = fusion.synchronizer()) {
    const auto& ac = sy->assembler().counters();
    std::printf("  fused frames      %llu at %.3g Hz: %llu complete, %llu timed out (", static_cast<unsigned long long>(ac.frames),
                cfg.sync.rate_hz, static_cast<unsigned long long>(ac.complete), static_cast<unsigned long long>(ac.timed_out));
    bool first = true;
    for (const sync::SensorKind k : sync::kAllSensors) {
      const auto n = ac.missing[static_cast<std::size_t>(k)];
      if (n == 0) continue;
      std::printf("%s%llu lacking %s", first ? "" : ", ", static_cast<unsigned long long>(n), std::string(sync::to_string(k)).c_str());
      first = false;
    }
    std::printf("%s), %llu late rotations dropped\n", first ? "none lacking a sensor" : "",
                static_cast<unsigned long long>(ac.late_rotations));
  }
  if (samples) samples->finish();

  if (pcap_stats.truncated) log->warn("{} is truncated: it ends inside a record; everything before was used", pcap_path);
  if (!pcap_stats.read_error.empty()) log->warn("{}: reading stopped early: {}", pcap_path, pcap_stats.read_error);
  if (cfg.lidar.model != velodyne::Model::Unknown && stream.detector().decided() &&
      *stream.detector().decided() != cfg.lidar.model) {
    log->warn("lidar.model is {} but the packets look like a {} ({}); check the configuration",
              velodyne::to_string(cfg.lidar.model), velodyne::to_string(*stream.detector().decided()),
              stream.detector().reason());
  }
  if (!write_error.empty()) {
    std::fprintf(stderr, "fieldguard replay: %s\n", write_error.c_str());
    return kExitFailure;
  }
  if (!logs.empty() && stream.counters().packets == 0) return kExitOk;  // a recording without 3D LiDAR data
  if (stream.counters().packets == 0) {
    std::fprintf(stderr, "fieldguard replay: %s holds no UDP datagram to the data port %u: not a Velodyne capture, or "
                 "lidar.data_port is wrong\n", pcap_path.c_str(), cfg.lidar.data_port);
    return kExitBadInput;
  }
  if (stream.counters().decoded == 0) {
    std::fprintf(stderr, "fieldguard replay: none of the %llu datagrams to port %u in %s is a Velodyne data packet\n",
                 static_cast<unsigned long long>(stream.counters().packets), cfg.lidar.data_port, pcap_path.c_str());
    return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace fieldguard::app
