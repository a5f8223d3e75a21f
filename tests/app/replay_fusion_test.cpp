// Issue 5's acceptance on a simulated session: the tractor drives across an uneven field (roll and pitch up to
// 8 degrees) past a fixed pole and stops 1 m short of a low box that only the 2D LiDAR sees. The recording
// (HDL-32E pcap, GNSS NMEA at 10 Hz, Xsens AHRS at 100 Hz, SCIP scans at 40 Hz) goes through the same path as
// `fieldguard replay`: RecordingReader -> SensorFusion (sync) -> FrameDetector (geo compensation, perception).
// Measured and printed: the height spread of the ground points with and without compensation, the pole's
// plane coordinates over 100 frames, and the box found from the 2D scan and not without it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"
#include "app/sim_can_support.hpp"
#include "fieldguard/config/config.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/geo/frame_compensator.hpp"
#include "fieldguard/geo/projection.hpp"
#include "fieldguard/io/byte_log.hpp"
#include "fieldguard/output/diagnostics.hpp"
#include "fieldguard/perception/obstacle_hold.hpp"
#include "fieldguard/perception/pipeline.hpp"
#include "fieldguard/writers/obstacles_jsonl.hpp"
#include "output/dbc_reader.hpp"
#include "replay/recording.hpp"
#include "support/shared_output.hpp"

namespace fieldguard::app {
namespace {

namespace fs = std::filesystem;
using testing::Json;

// 22 s at 10 Hz: 14.5 s driving at 1.5 m/s past the pole, 2 s braking, 5.5 s standing before the box; 110
// frames at 5 Hz.
constexpr int kRotations = 220;

// The uneven-drive scene's tractor: LiDAR on a mast 1.8 m up at the front, 2D LiDAR on the bumper 0.3 m up,
// GNSS antenna on the cab roof 2.8 m up (tools/sim/session.hpp, scenes_field.cpp).
// tests/data/fusion/uneven-drive.yaml: the uneven-drive scene's tractor.

struct Truth {
  double field_heading_deg = 0.0;
  double pole_lat = 0.0, pole_lon = 0.0, pole_h = 0.0;
  double box_lat = 0.0, box_lon = 0.0;
};

class ReplayFusion : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("fg_fusion_" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    fs::create_directories(*dir_);
    // One session per build, shared by this suite's test processes (making it takes 20 s under ASan).
    session_dir_ = new std::string(testing::shared_output(
        FIELDGUARD_TEST_WORK,
        "uneven-drive-" + std::to_string(kRotations) + "-seed1-" + testing::stamp_of(FIELDGUARD_SIM),
        [](const std::string& d) {
          const std::string cmd = std::string("'") + FIELDGUARD_SIM + "' --scene uneven-drive --session '" + d +
                                  "' --rotations " + std::to_string(kRotations) + " --seed 1 --quiet 2>&1";
          return std::system(cmd.c_str()) == 0;
        }));
    ASSERT_FALSE(session_dir_->empty()) << "fieldguard-sim could not write the session";
    const auto loaded = load_config_file(std::string(FIELDGUARD_TEST_DATA) + "/fusion/uneven-drive.yaml");
    ASSERT_TRUE(loaded.ok()) << loaded.issues.front().to_string();
    config_ = new Config(loaded.config);
    truth_ = new Truth;
    std::ifstream in(session("pose.truth.jsonl"));
    std::string header;
    std::getline(in, header);
    const Json parsed = Json::parse(header, nullptr, /*allow_exceptions=*/false);
    ASSERT_FALSE(parsed.is_discarded()) << header;
    const Json h = parsed.at("session");
    truth_->field_heading_deg = h.at("field_heading_deg").get<double>();
    for (const Json& o : h.at("objects")) {
      if (o.at("id").get<std::string>() == "pole-1") {
        truth_->pole_lat = o.at("base_lat_deg").get<double>();
        truth_->pole_lon = o.at("base_lon_deg").get<double>();
        truth_->pole_h = o.at("base_h_m").get<double>();
      } else if (o.at("id").get<std::string>() == "box-1") {
        truth_->box_lat = o.at("base_lat_deg").get<double>();
        truth_->box_lon = o.at("base_lon_deg").get<double>();
      }
    }
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
    delete session_dir_;
    delete config_;
    delete truth_;
  }
  static std::string session(const std::string& name) { return (fs::path(*session_dir_) / name).string(); }
  static std::vector<LogFile> all_logs() {
    return {{session("scan2d.log"), LogKind::Scan2d},
            {session("gnss.log"), LogKind::Gnss},
            {session("ahrs.log"), LogKind::Ahrs}};
  }
  // Every fused frame of the session, in order.
  static std::vector<FrameJob> fused_frames(const std::vector<LogFile>& logs) {
    auto rec = RecordingReader::open(session("lidar.pcap"), logs);
    EXPECT_TRUE(rec.has_value());
    std::vector<FrameJob> jobs;
    if (!rec) return jobs;
    SensorFusion fusion(*config_, {rec->has(LogKind::Scan2d), rec->has(LogKind::Gnss), rec->has(LogKind::Ahrs)});
    Stamp last;
    while (auto ev = rec->next()) {
      last = ev->time;
      if (ev->datagram != nullptr) {
        if (const auto channel = fusion.stream().channel_of(ev->datagram->dst_port)) {
          fusion.lidar(*channel, ev->datagram->payload, ev->time, jobs);
        }
      } else if (ev->kind == LogKind::Scan2d) {
        fusion.scan2d_bytes(ev->record->bytes, ev->record->direction == io::Direction::ToSensor, ev->time, jobs);
      } else if (ev->kind == LogKind::Gnss) {
        fusion.gnss(ev->record->bytes, ev->time, jobs);
      } else {
        fusion.ahrs(ev->record->bytes, ev->time, jobs);
      }
    }
    fusion.finish(last, jobs);
    return jobs;
  }

  static fs::path* dir_;  // this process's scratch
  static std::string* session_dir_;
  static Config* config_;
  static Truth* truth_;
};
fs::path* ReplayFusion::dir_ = nullptr;
std::string* ReplayFusion::session_dir_ = nullptr;
Config* ReplayFusion::config_ = nullptr;
Truth* ReplayFusion::truth_ = nullptr;

double sd(const std::vector<double>& v) {
  const double m = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  double q = 0.0;
  for (const double x : v) q += (x - m) * (x - m);
  return std::sqrt(q / static_cast<double>(v.size()));
}

TEST_F(ReplayFusion, EveryFrameIsCompleteAndLevelledFromItsOwnSamples) {
  const auto jobs = fused_frames(all_logs());
  ASSERT_GE(jobs.size(), 105U);
  FrameDetector detector(*config_);
  std::size_t full = 0;
  std::size_t timed_out = 0;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    FrameJob j = jobs[i];
    ASSERT_TRUE(j.synced.has_value());
    EXPECT_EQ(j.synced->seq, i);
    if (j.synced->timed_out) ++timed_out;
    const DetectedFrame d = detector.process(j);
    ASSERT_TRUE(d.fusion.has_value());
    if (d.fusion->levelling == geo::Levelling::Full) ++full;
  }
  std::printf("fused frames: %zu, %zu levelled with attitude and position, %zu timed out\n", jobs.size(), full,
              timed_out);
  // The first and the last windows may lack the GNSS fix after them; every other is whole.
  EXPECT_LE(timed_out, 2U);
  EXPECT_GE(full, jobs.size() - 2);
}

// Without compensation: the window's raw points put on the plane rigidly with the frame's reference pose
// (position and heading at the window's end), as a system without per-point attitude and deskew would.
Eigen::Vector3d uncompensated(const LidarPoint& p, const geo::CompensatedFrame& f, const Mounting& lidar) {
  const double yaw = f.attitude->yaw_deg * std::numbers::pi / 180.0;
  const double x = static_cast<double>(p.x) + lidar.x_m;
  const double y = static_cast<double>(p.y) + lidar.y_m;
  return f.reference->enu() + Eigen::Vector3d(std::cos(yaw) * x - std::sin(yaw) * y,
                                              std::sin(yaw) * x + std::cos(yaw) * y,
                                              static_cast<double>(p.z) + lidar.z_m);
}

// Spread of the ground's height at the same place of the field across frames: the ground points of the lower
// rings (0..11 of the HDL-32E point 16 to 31 degrees down: ground within 13 m whatever the pitch), on the plane,
// each 0.5 m cell's height per frame against its mean over the frames. The field's own swells and furrows are
// the same in every frame and drop out; what is left is how differently each frame puts the same ground.
struct CellSpread {
  std::map<std::pair<long, long>, std::map<std::uint64_t, std::pair<double, int>>> cells;  // cell -> frame -> (sum, n)
  void add(const Eigen::Vector3d& p, std::uint64_t frame) {
    auto& c = cells[{std::lround(std::floor(p.x() / 0.5)), std::lround(std::floor(p.y() / 0.5))}][frame];
    c.first += p.z();
    ++c.second;
  }
  [[nodiscard]] std::pair<double, std::size_t> sd() const {
    double q = 0.0;
    std::size_t n = 0;
    for (const auto& [key, frames] : cells) {
      if (frames.size() < 3) continue;
      double mean = 0.0;
      for (const auto& [f, sn] : frames) mean += sn.first / sn.second;
      mean /= static_cast<double>(frames.size());
      for (const auto& [f, sn] : frames) {
        q += (sn.first / sn.second - mean) * (sn.first / sn.second - mean);
        ++n;
      }
    }
    return {n == 0 ? 0.0 : std::sqrt(q / static_cast<double>(n)), n};
  }
};

TEST_F(ReplayFusion, GroundHeightSpreadIsAtLeastThreeTimesSmallerCompensated) {
  const auto jobs = fused_frames(all_logs());
  ASSERT_GE(jobs.size(), 100U);
  geo::CompensationParams cp = compensation_params(*config_);
  cp.plane_points = true;
  const geo::FrameCompensator comp(cp);
  const geo::GaussKrueger gk(cp.projection);
  const auto pole = gk.forward({truth_->pole_lat, truth_->pole_lon, truth_->pole_h});
  const auto box = gk.forward({truth_->box_lat, truth_->box_lon, 0.0});
  ASSERT_TRUE(pole.has_value() && box.has_value());
  auto near_object = [&](const Eigen::Vector3d& p) {
    return std::hypot(p.x() - pole->easting_m, p.y() - pole->northing_m) < 1.0 ||
           std::hypot(p.x() - box->easting_m, p.y() - box->northing_m) < 1.5;
  };
  CellSpread raw;
  CellSpread fixed;
  std::vector<double> raw_z;
  std::vector<double> comp_z;
  geo::CompensatedFrame out;
  for (const FrameJob& job : jobs) {
    comp.compensate(*job.synced, out);
    if (out.levelling != geo::Levelling::Full) continue;
    // Ahead of the LiDAR only: behind and below it the low rings hit the tractor's own hood.
    for (const LidarPoint& p : job.synced->points) {
      if (p.ring > 11 || p.x < 1.0F) continue;
      const Eigen::Vector3d u = uncompensated(p, out, config_->lidar.mounting);
      if (near_object(u)) continue;
      raw.add(u, job.synced->seq);
      raw_z.push_back(static_cast<double>(p.z));
    }
    const double yaw = out.attitude->yaw_deg * std::numbers::pi / 180.0;
    for (const auto& p : out.plane) {
      if (p.source != PointSource::Lidar3d || p.channel > 11 || near_object(p.enu)) continue;
      const Eigen::Vector3d d = p.enu - out.reference->enu();
      if (std::cos(yaw) * d.x() + std::sin(yaw) * d.y() - config_->lidar.mounting.x_m < 1.0) continue;
      fixed.add(p.enu, job.synced->seq);
    }
    for (const LidarPoint& p : out.points) {
      if (p.source == static_cast<std::uint8_t>(PointSource::Lidar3d) && p.ring <= 11 && p.x >= 1.0F) {
        comp_z.push_back(static_cast<double>(p.z));
      }
    }
  }
  const auto [raw_sd, raw_n] = raw.sd();
  const auto [fixed_sd, fixed_n] = fixed.sd();
  ASSERT_GT(raw_n, 5000U);
  ASSERT_GT(fixed_n, 5000U);
  std::printf(
      "ground height at the same place across %zu frames (0.5 m cells, rings 0-11): uncompensated %.3f m "
      "(%zu cell-frames), compensated %.3f m (%zu): %.1fx smaller\n",
      jobs.size(), raw_sd, raw_n, fixed_sd, fixed_n, raw_sd / fixed_sd);
  std::printf(
      "(all those ground points' heights pooled, the field's own swells included: sensor frame %.3f m, "
      "detection frame %.3f m)\n",
      sd(raw_z), sd(comp_z));
  EXPECT_GE(raw_sd / fixed_sd, 3.0);
  // The compensated spread is what the range noise (1.5 cm), the AHRS noise and the GNSS noise leave.
  EXPECT_LT(fixed_sd, 0.05);
}

// Distance of a point on the plane from the surface of the pole, a vertical 0.1 m square prism whose sides
// run along the field's axes (the simulator's world x is the field heading, grid yaw `axis_yaw`).
double off_pole(const Eigen::Vector3d& p, const geo::PlaneCoord& c, double axis_yaw) {
  const double dx = p.x() - c.easting_m;
  const double dy = p.y() - c.northing_m;
  const double lx = std::abs(std::cos(axis_yaw) * dx + std::sin(axis_yaw) * dy);
  const double ly = std::abs(-std::sin(axis_yaw) * dx + std::cos(axis_yaw) * dy);
  if (lx > 0.05 || ly > 0.05) return std::hypot(std::max(lx - 0.05, 0.0), std::max(ly - 0.05, 0.0));
  return std::min(0.05 - lx, 0.05 - ly);
}

// Each frame's pole points on the plane against the pole's true surface (Gauss-Krueger, WGS84, 3-degree zone):
// the points are where the pole really is, frame after frame, while the tractor drives past it, rocking.
TEST_F(ReplayFusion, FixedPoleStaysWithin5cmOnThePlaneOver100Frames) {
  const auto jobs = fused_frames(all_logs());
  geo::CompensationParams cp = compensation_params(*config_);
  cp.plane_points = true;
  const geo::FrameCompensator comp(cp);
  const geo::GaussKrueger gk(cp.projection);
  const auto truth = gk.forward({truth_->pole_lat, truth_->pole_lon, truth_->pole_h});
  ASSERT_TRUE(truth.has_value());
  // World x: compass heading 60 deg true = ENU yaw 30 deg from true east; on the grid, plus the convergence.
  const double axis_yaw = (90.0 - truth_->field_heading_deg + truth->convergence_deg) * std::numbers::pi / 180.0;
  std::vector<double> rms_fixed;
  std::vector<double> rms_raw;
  std::vector<double> east;
  std::vector<double> north;
  geo::CompensatedFrame out;
  for (const FrameJob& job : jobs) {
    comp.compensate(*job.synced, out);
    if (out.levelling != geo::Levelling::Full) continue;
    auto on_pole = [&](const Eigen::Vector3d& p) {
      const double dz = p.z() - truth->up_m;
      return std::hypot(p.x() - truth->easting_m, p.y() - truth->northing_m) < 0.5 && dz > 0.3 && dz < 1.9;
    };
    double q = 0.0;
    double se = 0.0;
    double sn = 0.0;
    int n = 0;
    for (const auto& p : out.plane) {
      if (p.source != PointSource::Lidar3d || !on_pole(p.enu)) continue;
      q += off_pole(p.enu, *truth, axis_yaw) * off_pole(p.enu, *truth, axis_yaw);
      se += p.enu.x();
      sn += p.enu.y();
      ++n;
    }
    if (n < 3) continue;
    rms_fixed.push_back(std::sqrt(q / n));
    east.push_back(se / n);
    north.push_back(sn / n);
    // The same rotation uncompensated: the points near the pole's place, however far off it they land.
    double qr = 0.0;
    int nr = 0;
    for (const LidarPoint& p : job.synced->points) {
      const Eigen::Vector3d u = uncompensated(p, out, config_->lidar.mounting);
      if (std::hypot(u.x() - truth->easting_m, u.y() - truth->northing_m) > 1.0 || u.z() - truth->up_m < 0.3 ||
          u.z() - truth->up_m > 1.9) {
        continue;
      }
      qr += off_pole(u, *truth, axis_yaw) * off_pole(u, *truth, axis_yaw);
      ++nr;
    }
    if (nr > 0) rms_raw.push_back(std::sqrt(qr / nr));
  }
  ASSERT_GE(rms_fixed.size(), 100U) << "frames that see the pole";
  const double worst = *std::max_element(rms_fixed.begin(), rms_fixed.end());
  const double mean_rms =
      std::accumulate(rms_fixed.begin(), rms_fixed.end(), 0.0) / static_cast<double>(rms_fixed.size());
  const double worst_raw = rms_raw.empty() ? 0.0 : *std::max_element(rms_raw.begin(), rms_raw.end());
  const double me = std::accumulate(east.begin(), east.end(), 0.0) / static_cast<double>(east.size());
  const double mn = std::accumulate(north.begin(), north.end(), 0.0) / static_cast<double>(north.size());
  double spread = 0.0;
  for (std::size_t i = 0; i < east.size(); ++i) spread = std::max(spread, std::hypot(east[i] - me, north[i] - mn));
  std::printf(
      "pole over %zu frames: its points' RMS distance from the true pole surface %.3f m on average, %.3f m in "
      "the worst frame (uncompensated: worst %.3f m); the visible faces' centroid stays within %.3f m of its "
      "mean (the faces seen change as the tractor passes: up to 0.1 m)\n",
      rms_fixed.size(), mean_rms, worst, worst_raw, spread);
  EXPECT_LE(worst, 0.05);
  EXPECT_GT(worst_raw, 3.0 * worst);
}
// The stop requests of a `replay --session DIR --can-log` run: (stamp us, sensor fault reason) of each STOP.
struct Dm1 {
  long long us = 0;  // the stamp of its frame (one frame) or of its last packet (BAM)
  std::vector<output::j1939::Dtc> dtcs;
  output::j1939::Lamps lamps;
};
struct StopLog {
  std::vector<long long> sensor_fault_us;  // stamps of stop requests giving a sensor fault
  std::size_t stops = 0;
  std::size_t frames = 0;
  std::uint32_t first_id = 0;  // of the log's first frame
  std::vector<Dm1> dm1;        // every DM1 in the log, as sent
};
StopLog replay_stops(const std::string& session_dir, const std::string& work) {
  const std::string config = std::string(FIELDGUARD_TEST_DATA) + "/fusion/uneven-drive.yaml";
  const std::string log = work + "/can.log";
  const auto r = testing::run_fieldguard("replay --quiet --config '" + config + "' --session '" + session_dir +
                                         "' --can-log '" + log + "'");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const auto db = test::dbc::parse_file(std::string(FIELDGUARD_SOURCE_DIR) + "/config/fieldguard.dbc");
  const auto& stop = db.by_name("FG_STOP_REQUEST");
  const auto& summary = db.by_name("FG_OBSTACLE_SUMMARY");
  StopLog out;
  output::j1939::BamReceiver bam;
  for (const auto& f : testing::read_candump(testing::slurp(log))) {
    if (out.first_id == 0) out.first_id = f.id;
    if (testing::is_node_frame(f.id)) {
      output::CanFrame frame{f.id, static_cast<std::uint8_t>(f.data.size()), {}};
      std::copy(f.data.begin(), f.data.end(), frame.data.begin());
      std::optional<std::vector<std::uint8_t>> dm1;
      if (output::j1939_fields(f.id).pgn == output::j1939::kPgnDm1) dm1 = f.data;
      if (auto m = bam.feed(frame, static_cast<double>(f.us) * 1e-6); m && m->pgn == output::j1939::kPgnDm1) {
        dm1 = m->data;
      }
      if (dm1) {
        auto d = output::j1939::decode_diagnostic(*dm1);
        EXPECT_TRUE(d.has_value()) << "a DM1 that does not decode at " << f.us;
        if (d) out.dm1.push_back({f.us, d->dtcs, d->lamps});
      }
      continue;
    }
    const auto* m = db.by_can_id(f.id);
    if (m == &summary) ++out.frames;
    if (m != &stop) continue;
    const auto v = test::dbc::decode(*m, f.data);
    if (v.at("Command") != 1.0) continue;
    ++out.stops;
    if (v.at("ReasonSensorFault") == 1.0) out.sensor_fault_us.push_back(f.us);
  }
  return out;
}

// One GGA 8 s into the session moved by one minute of latitude (1.85 km): the GNSS is implausible (a position
// jump), and the safety monitor, fed by replay as the daemon would feed it, says STOP, sensor fault.
TEST_F(ReplayFusion, AGnssPositionJumpStopsTheTractorAsASensorFault) {
  const fs::path bad = *dir_ / "jump";
  fs::create_directories(bad);
  for (const char* f : {"lidar.pcap", "scan2d.log", "ahrs.log"})
    fs::copy_file(session(f), bad / f, fs::copy_options::overwrite_existing);
  auto in = io::ByteLogReader::open(session("gnss.log"));
  ASSERT_TRUE(in.has_value());
  auto out = io::ByteLogWriter::create((bad / "gnss.log").string(), in->source());
  ASSERT_TRUE(out.has_value());
  int gga = 0;
  long long jump_us = 0;
  while (auto rec = in->next()) {
    std::string text(rec->bytes.begin(), rec->bytes.end());
    const std::size_t at = text.find("GGA,");
    if (at != std::string::npos && ++gga == 80) {
      // $GNGGA,hhmmss.ss,DDMM.MMMMM,N,... : one more minute of latitude, and the checksum after it.
      const std::size_t lat = text.find(',', text.find(',', at) + 1) + 1;
      ASSERT_TRUE(std::isdigit(static_cast<unsigned char>(text[lat + 3])));
      text[lat + 3] = static_cast<char>(text[lat + 3] == '9' ? '0' : text[lat + 3] + 1);
      const std::size_t dollar = text.rfind('$', at);
      const std::size_t star = text.find('*', at);
      unsigned sum = 0;
      for (std::size_t i = dollar + 1; i < star; ++i) sum ^= static_cast<unsigned char>(text[i]);
      char hex[3];
      std::snprintf(hex, sizeof hex, "%02X", sum);
      text[star + 1] = hex[0];
      text[star + 2] = hex[1];
      jump_us = rec->host_time.ns / 1000;
    }
    const std::vector<std::uint8_t> bytes(text.begin(), text.end());
    ASSERT_TRUE(out->write(rec->host_time, rec->direction, bytes));
  }
  ASSERT_TRUE(out->flush());
  ASSERT_NE(jump_us, 0) << "the session has fewer than 80 GGA sentences";

  const StopLog clean = replay_stops(*session_dir_, (*dir_).string());
  const StopLog jumped = replay_stops(bad.string(), bad.string());
  ASSERT_GT(clean.frames, 100U);
  EXPECT_EQ(jumped.frames, clean.frames);
  // Clean: no sensor fault after start-up (a STOP for the box ahead at the end is an obstacle, not a fault).
  std::size_t clean_after = 0;
  for (const long long us : clean.sensor_fault_us) clean_after += us > jump_us - 5'000'000 ? 1U : 0U;
  EXPECT_EQ(clean_after, 0U);
  // Jumped: a sensor-fault STOP no later than the first frame decided after the jump (at 5 Hz, 0.2 s plus the
  // window's wait for the GNSS fix after it: within 0.6 s).
  const auto first = std::find_if(jumped.sensor_fault_us.begin(), jumped.sensor_fault_us.end(),
                                  [&](long long us) { return us >= jump_us; });
  ASSERT_NE(first, jumped.sensor_fault_us.end()) << "no sensor-fault stop after the jump";
  std::printf("GNSS position jump (GGA %d): STOP, sensor fault, decided %.3f s after it arrived\n",
              gga >= 80 ? 80 : gga, static_cast<double>(*first - jump_us) * 1e-6);
  EXPECT_LE(*first - jump_us, 600'000);

  // On the bus as a J1939 node (issue 27): the log begins with our Address Claimed; the jump is DM1's DTC
  // SPN 520194 (GNSS) FMI 2 (erratic) within a second, and a DM1 without it (lamps off) once it has passed.
  EXPECT_EQ(jumped.first_id, 0x18EEFF80U) << std::hex << jumped.first_id;
  EXPECT_EQ(clean.first_id, 0x18EEFF80U) << std::hex << clean.first_id;
  ASSERT_GT(clean.dm1.size(), 10U) << "DM1 once a second";
  const auto gnss_erratic = [](const Dm1& d) {
    return std::any_of(d.dtcs.begin(), d.dtcs.end(), [](const output::j1939::Dtc& c) {
      return c.spn == output::j1939::sensor_spn(output::safety::Sensor::Gnss) && c.fmi == 2;
    });
  };
  EXPECT_TRUE(std::none_of(clean.dm1.begin(), clean.dm1.end(), gnss_erratic)) << "a DTC in the clean session";
  const auto raised = std::find_if(jumped.dm1.begin(), jumped.dm1.end(),
                                   [&](const Dm1& d) { return d.us >= jump_us && gnss_erratic(d); });
  ASSERT_NE(raised, jumped.dm1.end()) << "no DM1 with the GNSS's DTC after the jump";
  EXPECT_LE(raised->us - jump_us, 1'000'000);
  EXPECT_EQ(raised->lamps.amber_warning, output::j1939::Lamp::On);
  EXPECT_EQ(raised->dtcs.front().occurrences, 1);
  const auto cleared = std::find_if(raised, jumped.dm1.end(), [](const Dm1& d) { return d.dtcs.empty(); });
  ASSERT_NE(cleared, jumped.dm1.end()) << "the DTC never cleared";
  EXPECT_EQ(cleared->lamps.amber_warning, output::j1939::Lamp::Off);
  std::printf("DM1: GNSS erratic (520194/2) %.3f s after the jump, cleared %.3f s after that\n",
              static_cast<double>(raised->us - jump_us) * 1e-6, static_cast<double>(cleared->us - raised->us) * 1e-6);

  // The same log through python-can (Debian's python3-can) and a decoder written from the standards' layouts
  // (tests/interop/j1939_read.py): our claim with its NAME, and every DM1, one-frame or BAM, the same.
  const auto py = testing::run_shell("/usr/bin/python3 '" + std::string(FIELDGUARD_SOURCE_DIR) +
                                     "/tests/interop/j1939_read.py' '" + (bad / "can.log").string() + "'");
  ASSERT_EQ(py.exit_code, 0) << "python-can (tools/install-deps installs python3-can): " << py.output;
  EXPECT_EQ(py.output.rfind("first 18EEFF80 extended\nclaim 80 name=", 0), 0U) << py.output;
  EXPECT_NE(py.output.find("function=255 industry_group=2 arbitrary=1\n"), std::string::npos) << py.output;
  std::string ours;
  for (const auto& d : jumped.dm1) {
    char lamps[3];
    std::snprintf(lamps, sizeof lamps, "%02X", encode_diagnostic(output::j1939::DiagnosticMessage{d.lamps, {}})[0]);
    std::string codes;
    for (const auto& c : d.dtcs) {
      codes += (codes.empty() ? "" : ",") + std::to_string(c.spn) + "/" + std::to_string(c.fmi) + "/" +
               std::to_string(c.occurrences);
    }
    ours += "dm1 " + std::to_string(d.us) + " lamps=" + lamps + " dtcs=" + (codes.empty() ? "-" : codes) + "\n";
  }
  std::string theirs;
  std::istringstream lines(py.output);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("dm1 ", 0) == 0) theirs += line + "\n";
  }
  EXPECT_EQ(theirs, ours);
  EXPECT_NE(theirs.find(" dtcs=520194/2/1\n"), std::string::npos) << theirs;
}

// The last 20 frames (4 s; the tractor has stopped 1 m short of the box) of a replay's obstacles.
std::vector<Json> last_frames(const std::string& args, std::size_t n) {
  const auto r = testing::run_fieldguard("replay --quiet --config '" + std::string(FIELDGUARD_TEST_DATA) +
                                         "/fusion/uneven-drive.yaml' " + args);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::vector<Json> frames;
  for (auto& j : testing::json_lines(r.output)) frames.push_back(std::move(j));
  if (frames.size() > n) frames.erase(frames.begin(), frames.end() - static_cast<std::ptrdiff_t>(n));
  return frames;
}

// The 0.4 m box 1 m in front of the bumper (the bumper is 0.3 m ahead of the 3D LiDAR; the box's near face
// then 1.3 m ahead of it), below the 3D LiDAR's lowest beam from 1.8 m up: found in the standing frames from
// the 2D scan, and not without it.
TEST_F(ReplayFusion, LowBoxInFrontOfTheBumperIsFoundFromThe2dScanOnly) {
  const geo::GaussKrueger gk(compensation_params(*config_).projection);
  const auto box = gk.forward({truth_->box_lat, truth_->box_lon, 0.0});
  ASSERT_TRUE(box.has_value());
  auto in_front = [](const Json& o) {
    const auto mn = o.at("min").get<std::vector<double>>();
    const auto mx = o.at("max").get<std::vector<double>>();
    return mn.size() == 3 && mx.size() == 3 && mn[0] < 2.5 && mx[0] > 0.3 && mn[1] < 1.0 && mx[1] > -1.0;
  };
  const auto with_scan = last_frames("--session '" + *session_dir_ + "' --obstacles-out /dev/stdout", 20);
  ASSERT_EQ(with_scan.size(), 20U);
  std::size_t found = 0;
  double worst_plane = 0.0;
  for (const Json& f : with_scan) {
    EXPECT_EQ(f.at("fusion").at("levelling").get<std::string>(), "full");
    for (const Json& o : f.at("obstacles")) {
      if (!in_front(o)) continue;
      EXPECT_EQ(o.at("seen_by").get<std::string>(), "2d") << "the 3D LiDAR cannot see it from 1.8 m up";
      ++found;
      const auto p = o.at("plane").get<std::vector<double>>();
      ASSERT_EQ(p.size(), 3U);
      worst_plane = std::max(worst_plane, std::hypot(p[0] - box->easting_m, p[1] - box->northing_m));
      break;
    }
  }
  const auto without = last_frames("--pcap '" + session("lidar.pcap") + "' --gnss-log '" + session("gnss.log") +
                                       "' --ahrs-log '" + session("ahrs.log") + "' --obstacles-out /dev/stdout",
                                   20);
  ASSERT_EQ(without.size(), 20U);
  std::size_t found_without = 0;
  for (const Json& f : without) {
    for (const Json& o : f.at("obstacles")) found_without += in_front(o) ? 1U : 0U;
  }
  std::printf(
      "low box 1 m in front of the bumper: found in %zu of the last 20 frames with the 2D scan (its footprint "
      "within %.2f m of the truth's centre on the plane), %zu without it\n",
      found, worst_plane, found_without);
  EXPECT_EQ(found, 20U);
  EXPECT_EQ(found_without, 0U);
  // The scan sees the box's near face: its footprint's centre lies within half the box's 0.4 m depth and the
  // face's noise of the true centre.
  EXPECT_LE(worst_plane, 0.35);
}

// The hold's view of a fused frame (detection_pose): where the detection frame's origin, the LiDAR's mounting
// position, stands on the plane, and the heading; only for a frame levelled in full.
TEST(DetectionPose, IsTheLidarsPlaceAndHeadingForAFrameLevelledInFull) {
  FusionInfo f;
  f.levelling = geo::Levelling::Full;
  geo::PlaneCoord ref;
  ref.easting_m = 3'512'000.0;
  ref.northing_m = 5'401'000.0;
  ref.up_m = 300.0;
  ref.zone = 3;
  f.reference = ref;
  f.attitude = geo::EulerDeg{2.0, -1.0, 90.0};
  const Mounting lidar{2.0, 0.5, 1.8, 0.0, 0.0, 0.0};
  const auto p = detection_pose(f, lidar);
  ASSERT_TRUE(p.has_value());
  // Heading north (90 degrees from east): 2 m ahead is 2 m north, 0.5 m left is 0.5 m west.
  EXPECT_NEAR(p->x_m, 3'512'000.0 - 0.5, 1e-6);
  EXPECT_NEAR(p->y_m, 5'401'000.0 + 2.0, 1e-6);
  EXPECT_NEAR(p->z_m, 301.8, 1e-9);
  EXPECT_NEAR(p->yaw_rad, std::numbers::pi / 2, 1e-12);
  EXPECT_EQ(p->plane, 3);

  // The obstacles JSON's "plane" key puts a box's footprint centre on the plane the same way.
  f.attitude = geo::EulerDeg{0.0, 0.0, 37.0};
  const auto q = detection_pose(f, lidar);
  ASSERT_TRUE(q.has_value());
  perception::FrameResult r;
  perception::Obstacle o;
  o.min = {11.F, -3.F, -1.5F};
  o.max = {12.F, -2.F, 0.2F};
  r.obstacles.push_back(o);
  LidarFrame frame;
  const std::string line = obstacles_json_line(frame, r, &f, &lidar);
  const Json j = Json::parse(line, nullptr, /*allow_exceptions=*/false);
  ASSERT_TRUE(j.is_object() && j.at("obstacles").size() == 1 && j.at("obstacles").at(0).contains("plane")) << line;
  const auto plane = j.at("obstacles").at(0).at("plane").get<std::vector<double>>();
  ASSERT_EQ(plane.size(), 3U) << line;
  const double e = plane[0], n = plane[1], u = plane[2];
  const double c = std::cos(q->yaw_rad), s = std::sin(q->yaw_rad);
  EXPECT_NEAR(e, q->x_m + c * 11.5 - s * -2.5, 1e-3);
  EXPECT_NEAR(n, q->y_m + s * 11.5 + c * -2.5, 1e-3);
  EXPECT_NEAR(u, q->z_m - 1.5, 1e-3);

  // Levelled by attitude only (no place), or lacking either: no pose.
  FusionInfo g = f;
  g.levelling = geo::Levelling::AttitudeOnly;
  EXPECT_FALSE(detection_pose(g, lidar).has_value());
  g = f;
  g.reference.reset();
  EXPECT_FALSE(detection_pose(g, lidar).has_value());
  g = f;
  g.attitude.reset();
  EXPECT_FALSE(detection_pose(g, lidar).has_value());
}

std::array<double, 2> footprint_centre(const std::array<float, 3>& min, const std::array<float, 3>& max) {
  return {0.5 * (static_cast<double>(min[0]) + static_cast<double>(max[0])),
          0.5 * (static_cast<double>(min[1]) + static_cast<double>(max[1]))};
}

// What the hold remembers, moved frame to frame by the frames' poses: the pole's box of one fully levelled
// frame, moved by its pose and the next frame's, lands where the next frame reports the pole; left where it
// was, it is off by the travel (1.5 m/s, 0.3 m a frame at 5 Hz).
TEST_F(ReplayFusion, APoleMovedByTheFramePosesLandsOnItsNextReport) {
  auto jobs = fused_frames(all_logs());
  const geo::GaussKrueger gk(compensation_params(*config_).projection);
  const auto truth = gk.forward({truth_->pole_lat, truth_->pole_lon, truth_->pole_h});
  ASSERT_TRUE(truth.has_value());
  FrameDetector detector(*config_);
  struct Report {
    std::array<float, 3> min, max;
    perception::FramePose pose;
  };
  std::optional<Report> last;
  std::vector<double> moved, still;
  for (FrameJob& job : jobs) {
    const DetectedFrame d = detector.process(job);
    const auto pose = d.fusion ? detection_pose(*d.fusion, config_->lidar.mounting) : std::nullopt;
    const perception::Obstacle* pole = nullptr;
    if (pose) {
      // The pole: the obstacle whose footprint centre the pose puts within 1 m of the pole's true place.
      const double c = std::cos(pose->yaw_rad), s = std::sin(pose->yaw_rad);
      for (const auto& o : d.result.obstacles) {
        const auto m = footprint_centre(o.min, o.max);
        const double e = pose->x_m + c * m[0] - s * m[1], n = pose->y_m + s * m[0] + c * m[1];
        if (std::hypot(e - truth->easting_m, n - truth->northing_m) < 1.0) pole = &o;
      }
    }
    if (pole == nullptr) {
      last.reset();
      continue;
    }
    const auto now = footprint_centre(pole->min, pole->max);
    if (last) {
      std::array<float, 3> mn{}, mx{};
      perception::move_box(last->min, last->max, last->pose, *pose, mn, mx);
      const auto m = footprint_centre(mn, mx);
      const auto t = footprint_centre(last->min, last->max);
      moved.push_back(std::hypot(m[0] - now[0], m[1] - now[1]));
      still.push_back(std::hypot(t[0] - now[0], t[1] - now[1]));
    }
    last = Report{pole->min, pole->max, *pose};
  }
  ASSERT_GE(moved.size(), 30U) << "pairs of consecutive frames that report the pole";
  std::vector<double> sm = moved, ss = still;
  std::sort(sm.begin(), sm.end());
  std::sort(ss.begin(), ss.end());
  std::printf(
      "pole reported in %zu pairs of consecutive frames: its last box moved by the two poses lands %.3f m "
      "from the next report (median; worst %.3f m), left where it was %.3f m (median; worst %.3f m)\n",
      moved.size(), sm[sm.size() / 2], sm.back(), ss[ss.size() / 2], ss.back());
  EXPECT_LE(sm.back(), 0.15) << "within half the hold's 0.3 m gate";
  EXPECT_GT(ss[ss.size() / 2], 0.2) << "the travel between two frames";
}

}  // namespace
}  // namespace fieldguard::app
