// `fieldguard run` end to end: the real daemon receives a simulated HDL-32E capture played over loopback UDP
// by fieldguard-udp-player at the capture's pace, and writes its CAN frames to a candump log that the test
// decodes with the DBC (tests/output/dbc_reader). Deadlines are checked on the log's own stamps (the host
// clock at each decision), never on the test's wall clock, so a loaded machine slows the test, not the
// verdict; only SIGTERM's "within a second" is wall time, as it is in the issue.
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/ptrace.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app/child_process.hpp"
#include "app/json_reader.hpp"
#include "app/sim_can_support.hpp"
#include "fieldguard/config/config.hpp"
#include "fieldguard/output/safety_params.hpp"
#include "io/pcap_builder.hpp"
#include "output/dbc_reader.hpp"

namespace fieldguard {
namespace {

using testing::count_lines;
using testing::free_udp_port;
using testing::is_node_frame;
using testing::LogFrame;
using testing::Process;
using testing::read_candump;
using testing::replaced;
using testing::slurp;

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using WallClock = std::chrono::steady_clock;

const std::string kSource = FIELDGUARD_SOURCE_DIR;
constexpr int kRotations = 120;  // 20 per crossing band: the pedestrian walks 0.8 m a rotation
constexpr double kPeriod = 0.1;  // the simulator's 10 Hz (181 packets: 100.09 ms)

struct Stop {
  long long us = 0;
  int command = -1;
  bool obstacle = false;
  bool sensor_fault = false;
  bool pipeline_late = false;
  bool starting_up = false;
  bool shutting_down = false;
};

// The log, decoded: each rotation's decision (the stop request at its summary's stamp) and every stop request.
struct Decoded {
  std::map<long long, Stop> by_frame;
  std::vector<Stop> stops;
  std::vector<long long> heartbeats;
  std::vector<int> lidar_health;  // FG_HEARTBEAT Lidar3d, per heartbeat
};

Decoded decode_log(const std::string& text) {
  const auto db = test::dbc::parse_file(kSource + "/config/fieldguard.dbc");
  const auto& summary = db.by_name("FG_OBSTACLE_SUMMARY");
  const auto& stop = db.by_name("FG_STOP_REQUEST");
  const auto& heartbeat = db.by_name("FG_HEARTBEAT");
  Decoded d;
  long long frame_at = -1;
  long long frame_counter = -1;
  long long last_us = 0;
  for (const auto& f : read_candump(text)) {
    EXPECT_GE(f.us, last_us) << "the log goes back in time";
    last_us = f.us;
    if (is_node_frame(f.id)) continue;
    const auto* m = db.by_can_id(f.id);
    EXPECT_NE(m, nullptr) << std::hex << f.id;
    if (m == nullptr) continue;
    const auto v = test::dbc::decode(*m, f.data);
    if (m == &summary) {
      frame_at = f.us;
      frame_counter = static_cast<long long>(v.at("FrameCounter"));
    } else if (m == &heartbeat) {
      d.heartbeats.push_back(f.us);
      d.lidar_health.push_back(static_cast<int>(v.at("Lidar3d")));
    } else if (m == &stop) {
      Stop s{f.us,
             static_cast<int>(v.at("Command")),
             v.at("ReasonObstacle") == 1.0,
             v.at("ReasonSensorFault") == 1.0,
             v.at("ReasonPipelineLate") == 1.0,
             v.at("ReasonStartingUp") == 1.0,
             v.at("ReasonShuttingDown") == 1.0};
      d.stops.push_back(s);
      if (frame_at == f.us) {
        EXPECT_EQ(d.by_frame.count(frame_counter), 0U) << "two decisions for rotation " << frame_counter;
        d.by_frame[frame_counter] = s;
        frame_at = -1;
      }
    }
  }
  return d;
}

// The simulator's pedestrian capture, shared (writing it takes a few seconds).
class RunE2e : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    capture_ = std::make_unique<testing::PedestrianCapture>(kRotations);
    ASSERT_TRUE(capture_->ok) << capture_->command;
    pcap_ = capture_->pcap;
    truth_ = capture_->truth;
  }
  static void TearDownTestSuite() {
    capture_.reset();
    rs32_.reset();
  }

  // The shipped configuration with the LiDAR on `port`, a candump log, a zone 0.6 m wide (each crossing
  // walks into it and out again), and two workers.
  std::string config_text(std::uint16_t port, const fs::path& log) const {
    std::string text = slurp(kSource + "/config/fieldguard.yaml");
    auto replace = [&](const std::string& from, const std::string& to) {
      const auto at = text.find(from);
      EXPECT_NE(at, std::string::npos) << from;
      if (at != std::string::npos) text.replace(at, from.size(), to);
    };
    replace("data_port: 2368 ", "data_port: " + std::to_string(port) + " ");
    // model auto listens on the RS-32's ports too: free ones, for tests running side by side.
    replace("msop_port: 6699 ", "msop_port: " + std::to_string(free_udp_port()) + " ");
    replace("difop_port: 7788 ", "difop_port: " + std::to_string(free_udp_port()) + " ");
    replace("\n  sink: socketcan ", "\n  sink: candump ");
    replace("\n  log_path: \"\" ", "\n  log_path: '" + log.string() + "' ");
    replace("\n    half_width_m: 2.0 ", "\n    half_width_m: 0.3 ");
    replace("\n  workers: 1 ", "\n  workers: 2 ");
    return text;
  }
  fs::path write_config(std::uint16_t port, const fs::path& log) const {
    const auto p = dir.path() / "run.yaml";
    std::ofstream(p) << config_text(port, log);
    return p;
  }
  // The same with every sensor live and required: the 2D LiDAR (the SCIP emulator on `scip_port`, its wall
  // 8 m ahead outside the near-field zone), GNSS and AHRS (the navigation emulator's pseudo-terminals), and
  // frames fused at 10 Hz: one frame per rotation of the 10 Hz capture, frame counter = rotation index.
  fs::path write_fused_config(std::uint16_t port, std::uint16_t scip_port, const fs::path& log) const {
    std::string text = config_text(port, log);
    text = replaced(text,
                    "\nscan2d:                          # Hokuyo UTM-30LX-EW 2D LiDAR, SCIP 2.0 over TCP: the near "
                    "blind zone in front\n  enabled: false ",
                    "\nscan2d:\n  enabled: true ");
    text = replaced(text, "\n  host: 192.168.0.10 ", "\n  host: 127.0.0.1 ");
    text = replaced(text, "\n  port: 10940 ", "\n  port: " + std::to_string(scip_port) + " ");
    text = replaced(text, "\n  enabled: false\n  device: /dev/ttyUSB0 ",
                    "\n  enabled: true\n  device: " + (dir.path() / "gnss").string() + " ");
    text = replaced(text, "\n  enabled: false\n  device: /dev/ttyUSB1\n",
                    "\n  enabled: true\n  device: " + (dir.path() / "ahrs").string() + "\n");
    text = replaced(text, "\n  rate_hz: 5.0 ", "\n  rate_hz: 10.0 ");
    text = replaced(text, "\n      max: [12.0, 4.0, 1.0]", "\n      max: [6.0, 4.0, 1.0]");
    // The tractor's speed from a bus this machine does not have (no SocketCAN): the daemon runs on with the
    // zone at its full-speed length and says so.
    text = replaced(text, "\n  speed: none ", "\n  speed: ccvs1 ");
    for (const char* s : {"scan2d", "gnss", "ahrs"}) {
      const std::string from = std::string("\n    ") + s + ":";
      const auto at = text.find(from, text.find("\n  sensors:"));
      EXPECT_NE(at, std::string::npos) << s;
      const auto req = text.find("required: false", at);
      if (at != std::string::npos && req != std::string::npos) text.replace(req, 15, "required: true ");
    }
    const auto p = dir.path() / "run.yaml";
    std::ofstream(p) << text;
    return p;
  }
  static std::vector<std::string> daemon_argv(const fs::path& config) {
    return {FIELDGUARD_BINARY, "run", "--config", config.string()};
  }
  static std::vector<std::string> player_argv(std::uint16_t port, bool live_time = false) {
    std::vector<std::string> a{FIELDGUARD_UDP_PLAYER, "--pcap", pcap_, "--map", "2368:" + std::to_string(port)};
    if (live_time) a.emplace_back("--live-time");  // a PPS-synchronised LiDAR's clock: UTC, as the GNSS's
    return a;
  }
  // fused: every sensor live (HDL-32E); rs32: the RS-LiDAR-32's capture instead, model auto, MSOP and DIFOP each
  // on its own port.
  void pedestrian_stops_clear_goes_silence_stops(bool fused, bool rs32 = false);

  testing::TempDir dir;
  static std::unique_ptr<testing::PedestrianCapture> capture_;
  static std::unique_ptr<testing::PedestrianCapture> rs32_;  // made by the RS-32 test when it runs
  static std::string pcap_;
  static std::string truth_;
};
std::unique_ptr<testing::PedestrianCapture> RunE2e::capture_;
std::unique_ptr<testing::PedestrianCapture> RunE2e::rs32_;
std::string RunE2e::pcap_;
std::string RunE2e::truth_;

TEST_F(RunE2e, PedestrianStopsClearGoesSilenceStopsAndSigtermEndsWithAStop) {
  pedestrian_stops_clear_goes_silence_stops(false);
}

// The same with every sensor emulated live: the 2D LiDAR over loopback TCP, GNSS and AHRS on pseudo-terminals,
// frames fused by sync and compensated by geo before detection.
TEST_F(RunE2e, FusedFromEveryLiveSensorPedestrianStopsClearGoesSilenceStops) {
  pedestrian_stops_clear_goes_silence_stops(true);
}

// The same with an RS-LiDAR-32 (the sensor of the published work): its MSOP and DIFOP on loopback, the shipped
// configuration unchanged but for the ports (model auto tells the sensor from its packets).
TEST_F(RunE2e, Rs32PedestrianStopsClearGoesSilenceStops) {
  rs32_ = std::make_unique<testing::PedestrianCapture>(kRotations, "rs32");
  ASSERT_TRUE(rs32_->ok) << rs32_->command;
  pedestrian_stops_clear_goes_silence_stops(false, true);
}

void RunE2e::pedestrian_stops_clear_goes_silence_stops(bool fused, bool rs32) {
  const std::uint16_t port = free_udp_port();
  const auto log = dir.path() / "can.log";
  std::uint16_t msop_port = 0;
  std::uint16_t difop_port = 0;
  std::optional<Process> scip;
  std::optional<Process> nav;
  fs::path config;
  if (fused) {
    scip.emplace(std::vector<std::string>{FIELDGUARD_SCIP_EMULATOR, "--scene", "wall"}, dir.path() / "scip.out");
    ASSERT_TRUE(scip->wait_for("\n", 10s)) << scip->output();  // it prints the port it listens on
    const auto scip_port = static_cast<std::uint16_t>(std::stoi(scip->output()));
    nav.emplace(std::vector<std::string>{FIELDGUARD_NAV_EMULATOR, "--gnss-link", (dir.path() / "gnss").string(),
                                         "--ahrs-link", (dir.path() / "ahrs").string()},
                dir.path() / "nav.out");
    for (int i = 0; i < 200 && !(fs::exists(dir.path() / "gnss") && fs::exists(dir.path() / "ahrs")); ++i) {
      std::this_thread::sleep_for(10ms);
    }
    config = write_fused_config(port, scip_port, log);
  } else if (rs32) {
    config = write_config(port, log);
    const auto loaded = app::load_config_file(config.string());
    ASSERT_TRUE(loaded.ok());
    msop_port = loaded.config.lidar.msop_port;
    difop_port = loaded.config.lidar.difop_port;
  } else {
    config = write_config(port, log);
  }
  // Its stderr as systemd's journal stream: JOURNAL_STREAM names the file (device and inode; Process truncates
  // it, the inode stays), so each line starts with its syslog priority, as journald reads them.
  const fs::path daemon_out = dir.path() / "daemon.out";
  std::ofstream(daemon_out).close();
  struct stat st {};
  ASSERT_EQ(::stat(daemon_out.c_str(), &st), 0);
  Process daemon(daemon_argv(config), daemon_out,
                 {{"JOURNAL_STREAM", std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino)}});
  ASSERT_TRUE(daemon.wait_for("listening for the 3D LiDAR on udp port " + std::to_string(port), 60s))
      << daemon.output();
  // The J1939 address is ours 250 ms after the claim: from then on every decision reaches the bus.
  ASSERT_TRUE(daemon.wait_for(" claimed (NAME 0x", 5s)) << daemon.output();
  if (fused) {
    // Every required sensor heard before the capture starts: the first rotations are decided, not waited for.
    ASSERT_TRUE(daemon.wait_for("frames fused from every enabled sensor", 5s)) << daemon.output();
    EXPECT_TRUE(daemon.wait_for("the stop zone keeps its full-speed length", 5s)) << daemon.output();
    std::this_thread::sleep_for(1500ms);
  }
  if (rs32) {
    ASSERT_TRUE(daemon.wait_for(std::to_string(msop_port) + " (RS-32 MSOP)", 1s)) << daemon.output();
    Process player({FIELDGUARD_UDP_PLAYER, "--pcap", rs32_->pcap, "--map", "6699:" + std::to_string(msop_port), "--map",
                    "7788:" + std::to_string(difop_port)},
                   dir.path() / "player.out");
    ASSERT_EQ(player.exited(120s), 0) << slurp(dir.path() / "player.out");
  } else {
    Process player(player_argv(port, fused), dir.path() / "player.out");
    ASSERT_EQ(player.exited(120s), 0) << slurp(dir.path() / "player.out");
  }
  // The LiDAR fell silent when the player sent its last packet, which its summary stamps on the system clock
  // (the CAN log's stamps are this clock's). Seeing the player exit comes later, by as much as a loaded
  // machine delays a process's teardown and this test's polling.
  const std::string player_out = slurp(dir.path() / "player.out");
  const auto last_at = player_out.find(", the last at ");
  ASSERT_NE(last_at, std::string::npos) << player_out;
  const long long silent_us = std::stoll(player_out.substr(last_at + std::strlen(", the last at ")));
  ASSERT_GT(silent_us, 0) << player_out;
  // The LiDAR is silent now: the daemon must say so (timeout 0.3 s) while it keeps running.
  ASSERT_TRUE(daemon.wait_for("lidar silent", 30s)) << daemon.output();
  if (rs32) {
    EXPECT_NE(daemon.output().find("3D LiDAR: RS-32 (RS-32 MSOP packets on port"), std::string::npos)
        << daemon.output();
  }
  // Priorities as journald reads them: the silent sensor a warning (`journalctl -p warning` shows it), the
  // obstacle stop and the go information; every line carries one.
  EXPECT_NE(daemon.output().find("<4>[safety] warning: "), std::string::npos) << daemon.output();
  EXPECT_NE(daemon.output().find("<6>[safety] info: "), std::string::npos) << daemon.output();
  std::istringstream lines(daemon.output());
  for (std::string line; std::getline(lines, line);) {
    if (line.find("[safety]") == std::string::npos) continue;
    const bool degraded = line.find(": stop: sensor fault") != std::string::npos ||
                          line.find(": stop: implausible data") != std::string::npos ||
                          line.find(": stop: pipeline late") != std::string::npos;
    EXPECT_EQ(line.rfind(degraded ? "<4>[safety] warning: " : "<6>[safety] info: ", 0), 0U) << line;
  }
  std::this_thread::sleep_for(300ms);
  ASSERT_EQ(::kill(daemon.pid(), SIGTERM), 0);
  const auto t_term = WallClock::now();
  const auto status = daemon.exited(10s);
  const double exit_s = std::chrono::duration<double>(WallClock::now() - t_term).count();
  ASSERT_TRUE(status.has_value()) << daemon.output();
  EXPECT_EQ(*status, 0) << daemon.output();
  // (d) within a second of SIGTERM (wall time: the issue's own words).
  EXPECT_LT(exit_s, 1.0);
  std::printf("[ measured ] SIGTERM to exit %.3f s\n", exit_s);
  {
    // The exit summary's detection times: a median above zero, each stage's after it, and the run's worst.
    const std::string out = daemon.output();
    const std::string timed = "  pipeline time     median ";
    const auto at = out.find(timed);
    ASSERT_NE(at, std::string::npos) << out;
    EXPECT_GT(std::stod(out.substr(at + timed.size())), 0.0) << out;
    const auto line_end = out.find('\n', at);
    const std::string line = out.substr(at, line_end - at);
    EXPECT_NE(line.find(", voxel "), std::string::npos) << line;
    const auto worst = line.find("; worst ");
    ASSERT_NE(worst, std::string::npos) << line;
    EXPECT_GT(std::stod(line.substr(worst + 8)), 0.0) << line;
    std::printf("[ measured ] %s\n", line.substr(2).c_str());
    // The binary counts its frame path's heap allocations once warm (core/alloc_count.hpp) and says how many.
    const std::string allocs = "  allocations       frame path ";
    const auto al = out.find(allocs);
    ASSERT_NE(al, std::string::npos) << out;
    const std::string alloc_line = out.substr(al + 2, out.find('\n', al) - al - 2);
    EXPECT_NE(alloc_line.find("sensor samples "), std::string::npos) << alloc_line;
    std::printf("[ measured ] %s\n", alloc_line.c_str());
    // The latency in its parts, each named, detection's above zero.
    const std::string parts = "  latency parts     ";
    const auto lp = out.find(parts);
    ASSERT_NE(lp, std::string::npos) << out;
    const std::string parts_line = out.substr(lp + 2, out.find('\n', lp) - lp - 2);
    for (const char* name :
         {"waiting for sensors ", "io thread ", "to a worker ", "compensation ", "detection ", "decision "}) {
      EXPECT_NE(parts_line.find(name), std::string::npos) << parts_line;
    }
    const auto det = parts_line.find("detection ");
    ASSERT_NE(det, std::string::npos) << parts_line;
    EXPECT_GT(std::stod(parts_line.substr(det + 10)), 0.0) << parts_line;
    std::printf("[ measured ] %s\n", parts_line.c_str());
    // The hold is on in fieldguard.yaml: the daemon runs it, in frame order, and counts what it held.
    const std::string held = "  held obstacles    ";
    const auto h = out.find(held);
    ASSERT_NE(h, std::string::npos) << out;
    EXPECT_GE(std::stoll(out.substr(h + held.size())), 0) << out;
  }

  const auto loaded = app::load_config_file(config.string());
  ASSERT_TRUE(loaded.ok());
  const auto& safety = loaded.config.safety;
  const int clear = safety.clear_frames;
  ASSERT_GE(clear, 2);
  const double zx0 = safety.zone.rear_x_m;
  const double zx1 = safety.zone.front_x_m + output::safety::zone_length_m(safety.zone, std::nullopt);
  const double zy = safety.zone.half_width_m;

  const Decoded d = decode_log(slurp(log));
  ASSERT_FALSE(d.stops.empty());
  // (d) the last word is STOP, shutting down.
  EXPECT_EQ(d.stops.back().command, 1);
  EXPECT_TRUE(d.stops.back().shutting_down);
  // Every full rotation but the last (which no packet closes) is decided: nothing was lost on the way.
  for (int k = 1; k < kRotations - 1; ++k) EXPECT_EQ(d.by_frame.count(k), 1U) << "rotation " << k << " was not decided";

  // Truth: where the pedestrian is per rotation (rotation k of the capture = frame counter k).
  const auto truth = testing::json_lines(slurp(rs32 ? rs32_->truth : truth_));
  ASSERT_EQ(truth.size(), static_cast<std::size_t>(kRotations));
  enum class Where { Inside, Far, Between };
  std::vector<Where> where;
  for (const auto& t : truth) {
    Where w = Where::Far;
    for (const auto& o : t.at("objects")) {
      if (o.at("id").get<std::string>() != "pedestrian") continue;
      const auto lo = o.at("min").get<std::vector<double>>();
      const auto hi = o.at("max").get<std::vector<double>>();
      const double m = 0.1;  // in by 10 cm, and seen
      const bool inside =
          lo[0] < zx1 - m && hi[0] > zx0 + m && lo[1] < zy - m && hi[1] > -zy + m && o.at("hits").get<double>() >= 5;
      const double f = 0.05;
      const bool far = lo[0] > zx1 + f || hi[0] < zx0 - f || lo[1] > zy + f || hi[1] < -zy - f;
      w = inside ? Where::Inside : (far ? Where::Far : Where::Between);
    }
    where.push_back(w);
  }
  auto at = [&](int k) { return where[static_cast<std::size_t>(k)]; };
  // (a) the first rotation in which it is in the zone, or the next one, says STOP, obstacle in zone.
  int entries = 0;
  for (int k = 1; k + 1 < kRotations - 1; ++k) {
    if (at(k) != Where::Inside || at(k - 1) == Where::Inside) continue;
    ++entries;
    const Stop& now = d.by_frame.at(k);
    const Stop& next = d.by_frame.at(k + 1);
    EXPECT_TRUE((now.command == 1 && now.obstacle) || (next.command == 1 && next.obstacle))
        << "the pedestrian is in the zone at rotation " << k << " but rotations " << k << " and " << k + 1 << " say "
        << now.command << " and " << next.command;
  }
  EXPECT_GE(entries, 3);
  // (c) after it leaves: STOP held for clear - 1 more rotations, GO once `clear` rotations were clear.
  int gos = 0;
  int late_or_fault_frames = 0;
  for (int k = 0; k < kRotations - 1; ++k) {
    if (at(k) == Where::Inside && d.by_frame.count(k) != 0) {
      EXPECT_EQ(d.by_frame.at(k).command, 1) << "rotation " << k;
      for (int j = k + 1; j < std::min(k + clear, kRotations - 1); ++j) {
        EXPECT_EQ(d.by_frame.at(j).command, 1) << "rotation " << j << " follows an obstacle in the zone at " << k;
      }
    }
    bool far_long_enough = k >= clear;
    for (int j = k - clear + 1; far_long_enough && j <= k; ++j) far_long_enough = at(j) == Where::Far;
    if (far_long_enough && d.by_frame.count(k) != 0) {
      const Stop& s = d.by_frame.at(k);
      // Fused, a serial sensor the daemon did not hear for longer than its timeout (the AHRS's is 0.1 s) is a
      // STOP of its own, right whatever the zone says: on this loaded 2-core machine the pseudo-terminals are
      // sometimes not read for that long (README, Measurements). So is a frame decided more than the deadline
      // (0.3 s) after its last data: fused, a frame waits for a GNSS fix when the newest is too old to extrapolate
      // from, which happens when the pseudo-terminals are read late (seen once in CI: rotations 63-64 pipeline late,
      // beside 14 sensor-fault frames). Such frames are counted, not held to GO; a daemon late on every frame still
      // fails the count of GOs below.
      if (fused && s.command == 1 && (s.sensor_fault || s.pipeline_late) && !s.obstacle) {
        ++late_or_fault_frames;
        continue;
      }
      ++gos;
      EXPECT_EQ(s.command, 0) << "rotation " << k << ": clear for " << clear << " rotations; reasons: obstacle "
                              << s.obstacle << ", sensor fault " << s.sensor_fault << ", pipeline late "
                              << s.pipeline_late << ", starting up " << s.starting_up;
    }
  }
  EXPECT_GE(gos, 20);
  if (fused) {
    std::printf("[ measured ] %d clear frames stopped for a silent serial sensor or a late frame instead\n",
                late_or_fault_frames);
  }

  // (b) silence: the last packet came at most one rotation after the last decided rotation's stamp (its
  // closing packet is older than its decision); STOP, sensor fault must follow within timeout + one frame.
  const long long last_frame_us = d.by_frame.rbegin()->second.us;
  const auto fault = std::find_if(d.stops.begin(), d.stops.end(),
                                  [&](const Stop& s) { return s.us > last_frame_us && s.sensor_fault; });
  ASSERT_NE(fault, d.stops.end());
  EXPECT_EQ(fault->command, 1);
  const double timeout = safety.sensor(output::safety::Sensor::Lidar).timeout_s;
  const double after_s = static_cast<double>(fault->us - last_frame_us) * 1e-6;
  EXPECT_LE(after_s, kPeriod + timeout + kPeriod * 1.01) << "STOP came " << after_s << " s after the last rotation";
  // The capture ends on a whole turn: its last rotation is whole with its last packet and decided then, not when a
  // next rotation begins (none does), so the last decision follows the last packet by the decision's latency.
  if (!fused) {
    const double decided_after_s = static_cast<double>(last_frame_us - silent_us) * 1e-6;
    EXPECT_GE(decided_after_s, -0.001) << "the last rotation decided before its last packet was sent";
    EXPECT_LE(decided_after_s, 0.05) << "the last rotation waited for a next one";
  }
  const double from_silence = static_cast<double>(fault->us - silent_us) * 1e-6;
  EXPECT_LE(from_silence, timeout + kPeriod) << "STOP came " << from_silence << " s after the last packet";
  EXPECT_GE(from_silence, timeout - 0.05) << "STOP for silence before the timeout";
  std::printf(
      "[ measured ] silence STOP %.3f s after the last decided rotation (bound %.3f s), %.3f s after the "
      "last packet (bound: timeout + one frame, %.3f s)\n",
      after_s, 2 * kPeriod + timeout, from_silence, timeout + kPeriod);
  // Every stop request after it says STOP, and the heartbeats report the LiDAR at fault (1).
  for (auto it = fault; it != d.stops.end(); ++it) EXPECT_EQ(it->command, 1);
  for (std::size_t i = 0; i < d.heartbeats.size(); ++i) {
    if (d.heartbeats[i] > fault->us) {
      EXPECT_EQ(d.lidar_health[i], 1) << "heartbeat at " << d.heartbeats[i];
    }
  }
  // Heartbeats at the fixed rate all along, also while nothing came.
  ASSERT_GT(d.heartbeats.size(), static_cast<std::size_t>(kRotations));
  for (std::size_t i = 1; i < d.heartbeats.size(); ++i) {
    EXPECT_EQ(d.heartbeats[i] - d.heartbeats[i - 1], 100000) << "heartbeat " << i;
  }
}

TEST_F(RunE2e, SighupWithABrokenConfigKeepsTheRunningOneAndLogsTheErrors) {
  const std::uint16_t port = free_udp_port();
  const auto log = dir.path() / "can.log";
  const auto config = write_config(port, log);
  Process daemon(daemon_argv(config), dir.path() / "daemon.out");
  ASSERT_TRUE(daemon.wait_for("listening for the 3D LiDAR", 60s)) << daemon.output();
  std::string broken = config_text(port, log);
  broken = replaced(broken, "\n  clear_frames: 3 ", "\n  clear_frames: -2 ");
  broken = replaced(broken, "\n    friction: 0.3 ", "\n    friction: lots ");
  std::ofstream(config) << broken;
  ASSERT_EQ(::kill(daemon.pid(), SIGHUP), 0);
  ASSERT_TRUE(daemon.wait_for("reload refused", 30s)) << daemon.output();
  const std::string out = daemon.output();
  EXPECT_NE(out.find("clear_frames"), std::string::npos) << out;
  EXPECT_NE(out.find("friction"), std::string::npos) << out;
  // Still running, still on the bus: heartbeats keep coming after the refusal.
  const std::size_t lines = count_lines(slurp(log));
  std::this_thread::sleep_for(500ms);
  EXPECT_FALSE(daemon.exited(0ms).has_value()) << daemon.output();
  EXPECT_GT(count_lines(slurp(log)), lines);
  // The old configuration still holds its port: the LiDAR is decided on (a good reload would say "reloaded").
  EXPECT_EQ(out.find("reloaded"), std::string::npos);
  {
    Process player({FIELDGUARD_UDP_PLAYER, "--pcap", pcap_, "--map", "2368:" + std::to_string(port)},
                   dir.path() / "player.out");
    ASSERT_TRUE(daemon.wait_for("every required sensor heard", 60s)) << daemon.output();
    ::kill(player.pid(), SIGTERM);
  }
  // A good config again: reloaded, and the daemon still ends cleanly.
  std::ofstream(config) << config_text(port, log);
  ASSERT_EQ(::kill(daemon.pid(), SIGHUP), 0);
  ASSERT_TRUE(daemon.wait_for("reloaded", 30s)) << daemon.output();
  std::this_thread::sleep_for(300ms);
  ASSERT_EQ(::kill(daemon.pid(), SIGTERM), 0);
  EXPECT_EQ(daemon.exited(10s), 0) << daemon.output();

  // Across both reloads the controller sees one node (issue 27): one Address Claimed, and each message's alive
  // counter going on by one, never starting again.
  const auto db = test::dbc::parse_file(kSource + "/config/fieldguard.dbc");
  std::map<std::string, long long> last_alive;
  int claims = 0;
  std::size_t checked = 0;
  for (const auto& f : read_candump(slurp(log))) {
    if (((f.id >> 8U) & 0x3FF00U) == 0xEE00U) ++claims;
    if (is_node_frame(f.id)) continue;
    const auto* m = db.by_can_id(f.id);
    ASSERT_NE(m, nullptr) << std::hex << f.id;
    const auto v = test::dbc::decode(*m, f.data);
    const auto a = v.find("AliveCounter");
    if (a == v.end()) continue;
    const auto alive = static_cast<long long>(a->second);
    if (auto it = last_alive.find(m->name); it != last_alive.end()) {
      EXPECT_EQ(alive, (it->second + 1) % 16) << m->name << " at " << f.us;
      ++checked;
    }
    last_alive[m->name] = alive;
  }
  EXPECT_EQ(claims, 1) << "a reload with the same NAME claims nothing again";
  EXPECT_GT(checked, 8U) << "heartbeats and stop requests before and after the reloads";
}

// A bound AF_UNIX datagram socket standing where systemd's notify socket would be.
class NotifySocket {
 public:
  explicit NotifySocket(fs::path path) : path_(std::move(path)) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::memcpy(addr.sun_path, path_.c_str(), std::min(path_.string().size() + 1, sizeof(addr.sun_path) - 1));
    EXPECT_EQ(::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0) << std::strerror(errno);
  }
  ~NotifySocket() { ::close(fd_); }
  NotifySocket(const NotifySocket&) = delete;
  NotifySocket& operator=(const NotifySocket&) = delete;
  NotifySocket(NotifySocket&&) = delete;
  NotifySocket& operator=(NotifySocket&&) = delete;
  // Every message that arrives within `d`.
  std::vector<std::string> collect(std::chrono::milliseconds d) {
    std::vector<std::string> out;
    const auto end = WallClock::now() + d;
    while (WallClock::now() < end) {
      char buf[4096];
      const ssize_t n = ::recv(fd_, buf, sizeof buf, MSG_DONTWAIT);
      if (n > 0) {
        out.emplace_back(buf, static_cast<std::size_t>(n));
      } else {
        std::this_thread::sleep_for(5ms);
      }
    }
    return out;
  }
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  int fd_ = -1;
};

int count_with(const std::vector<std::string>& msgs, const std::string& text) {
  return static_cast<int>(
      std::count_if(msgs.begin(), msgs.end(), [&](const std::string& m) { return m.find(text) != std::string::npos; }));
}

// The tid of the daemon's (first) perception worker, named by the daemon.
std::optional<pid_t> worker_tid(pid_t pid) {
  for (const auto& e : fs::directory_iterator("/proc/" + std::to_string(pid) + "/task")) {
    if (slurp(e.path() / "comm").rfind("fg-perception", 0) == 0)
      return static_cast<pid_t>(std::stol(e.path().filename()));
  }
  return std::nullopt;
}

TEST_F(RunE2e, NotifyReadyThenWatchdogWhileHealthyAndNoneWhileAWorkerHangs) {
  const std::uint16_t port = free_udp_port();
  const auto log = dir.path() / "can.log";
  std::string text = config_text(port, log);
  text = replaced(text, "\n  workers: 2 ", "\n  workers: 1 ");  // one worker: its hang stalls the pipeline
  const auto config = dir.path() / "run.yaml";
  std::ofstream(config) << text;
  NotifySocket sock(dir.path() / "notify");
  Process daemon(daemon_argv(config), dir.path() / "daemon.out",
                 {{"NOTIFY_SOCKET", sock.path().string()}, {"WATCHDOG_USEC", "1000000"}}, true);
  ASSERT_TRUE(daemon.wait_for("listening for the 3D LiDAR", 60s)) << daemon.output();
  // Nothing heard yet: no READY.
  auto msgs = sock.collect(300ms);
  EXPECT_EQ(count_with(msgs, "READY=1"), 0);
  Process player(player_argv(port), dir.path() / "player.out");
  ASSERT_TRUE(daemon.wait_for("every required sensor heard", 60s)) << daemon.output();
  msgs = sock.collect(1500ms);
  // READY first (it waited in the socket), then pings at most every quarter of WatchdogSec.
  ASSERT_FALSE(msgs.empty());
  EXPECT_EQ(msgs.front().rfind("READY=1\nSTATUS=", 0), 0U) << msgs.front();
  // Every status begins with the decision (the operator's first question), and names the sensors switched off
  // in this configuration as off.
  for (const auto& m : msgs) {
    const auto at = m.find("STATUS=");
    if (at == std::string::npos) continue;
    const std::string status = m.substr(at + 7);
    EXPECT_TRUE(status.rfind("STOP ", 0) == 0 || status.rfind("GO", 0) == 0) << status;
    EXPECT_NE(status.find("scan2d off, gnss off, ahrs off"), std::string::npos) << status;
  }
  EXPECT_EQ(count_with(msgs, "READY=1"), 1);
  EXPECT_GE(count_with(msgs, "WATCHDOG=1"), 3) << daemon.output();
  EXPECT_LE(count_with(msgs, "WATCHDOG=1"), 8);
  // Rotations detected by now: the status says how long detection takes (median, max, how many rotations).
  const auto timed = std::find_if(msgs.begin(), msgs.end(), [](const std::string& m) {
    return m.find("STATUS=") != std::string::npos && m.find(" | detection ") != std::string::npos;
  });
  ASSERT_NE(timed, msgs.end()) << daemon.output();
  const std::string after = timed->substr(timed->find(" | detection ") + 13);
  EXPECT_GT(std::stod(after), 0.0) << *timed;
  EXPECT_NE(after.find(" ms (max "), std::string::npos) << *timed;

  // Hang the worker: ptrace-stop that one thread (PTRACE_INTERRUPT stops the tracee alone; the io thread
  // goes on receiving, deciding and sending). Rotations pile up behind it, as behind a worker stuck in a
  // loop: the daemon still decides (STOP, pipeline late) but no longer feeds the watchdog.
  const auto tid = worker_tid(daemon.pid());
  ASSERT_TRUE(tid.has_value());
  ASSERT_EQ(::ptrace(PTRACE_SEIZE, *tid, nullptr, nullptr), 0) << std::strerror(errno);
  ASSERT_EQ(::ptrace(PTRACE_INTERRUPT, *tid, nullptr, nullptr), 0) << std::strerror(errno);
  int st = 0;
  ASSERT_EQ(::waitpid(*tid, &st, __WALL), *tid);
  ASSERT_TRUE(daemon.wait_for("pipeline stalled", 30s)) << daemon.output();
  sock.collect(100ms);  // a ping sent just before the stall was noticed
  msgs = sock.collect(1500ms);
  EXPECT_EQ(count_with(msgs, "WATCHDOG=1"), 0) << "pinged while the pipeline is stalled";
  EXPECT_GE(count_with(msgs, "STATUS="), 1);
  EXPECT_GE(count_with(msgs, "pipeline stalled"), 1);
  EXPECT_FALSE(daemon.exited(0ms).has_value());
  // Let it go: the worker catches up and the pings come back.
  ASSERT_EQ(::ptrace(PTRACE_DETACH, *tid, nullptr, nullptr), 0) << std::strerror(errno);
  msgs = sock.collect(2000ms);
  EXPECT_GE(count_with(msgs, "WATCHDOG=1"), 1) << daemon.output();
  ::kill(player.pid(), SIGTERM);
  ASSERT_EQ(::kill(daemon.pid(), SIGTERM), 0);
  EXPECT_EQ(daemon.exited(10s), 0) << daemon.output();
  msgs = sock.collect(100ms);
  EXPECT_GE(count_with(msgs, "STOPPING=1"), 1);
  // The CAN log says why it stopped while the worker hung.
  const Decoded d = decode_log(slurp(log));
  EXPECT_TRUE(
      std::any_of(d.stops.begin(), d.stops.end(), [](const Stop& s) { return s.command == 1 && s.pipeline_late; }));
}

}  // namespace
}  // namespace fieldguard
