// `fieldguard replay --workers N` and `--can-log`: the same bytes for any worker count, and the stop requests
// the daemon would have sent for a simulated pedestrian, checked against the simulator's ground truth.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"
#include "app/sim_can_support.hpp"
#include "fieldguard/config/config.hpp"
#include "fieldguard/output/safety_params.hpp"
#include "io/pcap_builder.hpp"
#include "output/dbc_reader.hpp"

namespace fieldguard {
namespace {

using testing::count_lines;
using testing::LogFrame;
using testing::read_candump;
using testing::slurp;

namespace fs = std::filesystem;
using testing::run_fieldguard;
using testing::summary_number;

const std::string kSource = FIELDGUARD_SOURCE_DIR;
const std::string kConfig = kSource + "/config/fieldguard.yaml";
const std::string kHdl = std::string(FIELDGUARD_TEST_DATA) + "/hdl32e_monterey_600.pcap";
constexpr int kRotations = 60;  // 10 per crossing band: the pedestrian walks 1.6 m a rotation

std::string replay(const std::string& config, const std::string& pcap, const std::string& extra) {
  return "replay --quiet --config '" + config + "' --pcap '" + pcap + "' " + extra;
}

// One simulator capture of the pedestrian scene shared by the tests (writing it takes a few seconds).
class SimCapture : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    capture_ = std::make_unique<testing::PedestrianCapture>(kRotations);
    ASSERT_TRUE(capture_->ok) << capture_->command;
    pcap_ = capture_->pcap;
    truth_ = capture_->truth;
  }
  static void TearDownTestSuite() { capture_.reset(); }

  static std::unique_ptr<testing::PedestrianCapture> capture_;
  static std::string pcap_;
  static std::string truth_;
};
std::unique_ptr<testing::PedestrianCapture> SimCapture::capture_;
std::string SimCapture::pcap_;
std::string SimCapture::truth_;

// Runs replay with --workers 1 and 4; the obstacles, the CAN log (and the bird's-eye pictures, drawn by the
// workers) must be the same bytes.
void expect_identical_for_any_workers(const std::string& pcap, std::size_t rotations, bool bev) {
  testing::TempDir dir;
  std::string obstacles[2];
  std::string can[2];
  std::vector<std::string> pictures[2];
  const int counts[2] = {1, 4};
  for (int i = 0; i < 2; ++i) {
    const auto o = dir.path() / ("o" + std::to_string(counts[i]) + ".jsonl");
    const auto c = dir.path() / ("c" + std::to_string(counts[i]) + ".log");
    const auto b = dir.path() / ("bev" + std::to_string(counts[i]));
    const auto r = run_fieldguard(replay(kConfig, pcap,
                                         "--workers " + std::to_string(counts[i]) + " --obstacles-out '" + o.string() +
                                             "' --can-log '" + c.string() + "'" +
                                             (bev ? " --bev-dir '" + b.string() + "'" : std::string())));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("workers           " + std::to_string(counts[i]) + ", 0 frames lost"), std::string::npos)
        << r.output;
    // The summary's pipeline time: a median above zero, and each stage's after it.
    const std::string timed = "  pipeline time     median ";
    const auto at = r.output.find(timed);
    ASSERT_NE(at, std::string::npos) << r.output;
    EXPECT_GT(std::stod(r.output.substr(at + timed.size())), 0.0) << r.output;
    EXPECT_NE(r.output.find(", voxel ", at), std::string::npos) << r.output;
    obstacles[i] = slurp(o);
    can[i] = slurp(c);
    if (bev) {
      std::vector<fs::path> files;
      for (const auto& e : fs::directory_iterator(b)) files.push_back(e.path());
      std::sort(files.begin(), files.end());
      EXPECT_EQ(files.size(), rotations);
      for (const auto& f : files) pictures[i].push_back(f.filename().string() + ":" + slurp(f));
    }
  }
  EXPECT_TRUE(pictures[0] == pictures[1]) << "--bev-dir differs between --workers 1 and 4";
  EXPECT_EQ(count_lines(obstacles[0]), rotations);
  EXPECT_GT(count_lines(can[0]), rotations * 3);
  EXPECT_TRUE(obstacles[0] == obstacles[1]) << "--obstacles-out differs between --workers 1 and 4";
  EXPECT_TRUE(can[0] == can[1]) << "--can-log differs between --workers 1 and 4";
}

TEST_F(SimCapture, WorkersGiveByteIdenticalOutput) { expect_identical_for_any_workers(pcap_, kRotations, false); }

TEST(ReplayWorkers, ByteIdenticalOnTheRealHdl32eCapture) {
  // 2 full and 2 partial rotations (replay_cli_test).
  expect_identical_for_any_workers(kHdl, 4, true);
}

TEST(ReplayWorkers, BadCountIsRefused) {
  for (const char* bad : {"0", "65", "two", "-1", "4x"}) {
    const auto r = run_fieldguard(replay(kConfig, kHdl, std::string("--workers ") + bad));
    EXPECT_EQ(r.exit_code, 2) << bad << "\n" << r.output;
    EXPECT_NE(r.output.find("--workers takes a whole number of worker threads from 1 to 64"), std::string::npos)
        << r.output;
  }
}

TEST(ReplayWorkers, CountFromTheConfigUnlessGiven) {
  testing::TempDir dir;
  std::string text = slurp(kConfig);
  const std::string key = "\n  workers: 1 ";
  ASSERT_NE(text.find(key), std::string::npos);
  text.replace(text.find(key), key.size(), "\n  workers: 3 ");
  const auto cfg = (dir.path() / "three.yaml").string();
  std::ofstream(cfg) << text;
  auto r = run_fieldguard(replay(cfg, kHdl, ""));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("workers           3, 0 frames lost"), std::string::npos) << r.output;
  r = run_fieldguard(replay(cfg, kHdl, "--workers 2"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("workers           2, 0 frames lost"), std::string::npos) << r.output;
}

TEST(ReplayCan, UnwritableLogIsBadInput) {
  const auto r = run_fieldguard(replay(kConfig, kHdl, "--can-log /nonexistent-dir/can.log"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--can-log"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("/nonexistent-dir/can.log"), std::string::npos) << r.output;
}

TEST(ReplayCan, FailedLogWriteIsAFailure) {
  // /dev/full opens, and every flush fails with ENOSPC: a disk filling up during the replay.
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const auto r = run_fieldguard(replay(kConfig, kHdl, "--can-log /dev/full"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("cannot write /dev/full"), std::string::npos) << r.output;
}

struct Stop {
  int command = -1;
  bool obstacle = false;
  bool starting_up = false;
};

// What a run must show: at least `inside` rotations with the pedestrian in the zone by `inside_margin` (each
// STOP, obstacle in zone), `go` rotations after clear_frames with it `far_margin` away (each GO), and `entries`
// GO -> STOP changes at a rotation where it is in the zone.
struct Expect {
  double inside_margin = 0.3;
  double far_margin = 1.5;
  int inside = 0;
  int go = 0;
  int entries = 0;
};

void check_can_log(const std::string& config, const std::string& pcap, const std::string& truth_path, const Expect& e) {
  testing::TempDir dir;
  const auto log = dir.path() / "can.log";
  const auto obstacles = dir.path() / "o.jsonl";
  const auto r = run_fieldguard(
      replay(config, pcap, "--can-log '" + log.string() + "' --obstacles-out '" + obstacles.string() + "'"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string text = slurp(log);

  // can-utils' own reader accepts every line.
  const auto asc = dir.path() / "can.asc";
  const std::string cmd = "log2asc -I '" + log.string() + "' -O '" + asc.string() + "' can0";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const std::string asc_text = slurp(asc);
  std::size_t asc_frames = 0;
  for (std::size_t at = asc_text.find(" Rx "); at != std::string::npos; at = asc_text.find(" Rx ", at + 1))
    ++asc_frames;
  EXPECT_EQ(asc_frames, count_lines(text)) << asc_text.substr(0, 2000);

  const auto db = test::dbc::parse_file(kSource + "/config/fieldguard.dbc");
  const auto& summary = db.by_name("FG_OBSTACLE_SUMMARY");
  const auto& stop = db.by_name("FG_STOP_REQUEST");
  const auto& heartbeat = db.by_name("FG_HEARTBEAT");

  const auto loaded = app::load_config_file(config);
  ASSERT_TRUE(loaded.ok());
  const auto& safety = loaded.config.safety;
  const int clear = safety.clear_frames;
  ASSERT_GE(clear, 2);
  const double zx0 = safety.zone.rear_x_m;
  const double zx1 = safety.zone.front_x_m + output::safety::zone_length_m(safety.zone, std::nullopt);
  const double zy = safety.zone.half_width_m;

  // Each rotation's stop request follows its summary at the same stamp; the others are the periodic ones.
  std::map<long long, Stop> by_frame;
  std::vector<Stop> before_first_frame;
  std::vector<long long> heartbeats;
  long long frame_at = -1;  // the stamp of the current rotation's summary; -1 outside a rotation's batch
  long long frame_counter = -1;
  long long last_us = 0;
  for (const auto& f : read_candump(text)) {
    EXPECT_EQ(f.iface, "can0");
    EXPECT_GE(f.us, last_us) << "the log goes back in time";
    last_us = f.us;
    if (testing::is_node_frame(f.id)) continue;
    const auto* m = db.by_can_id(f.id);
    ASSERT_NE(m, nullptr) << std::hex << f.id;
    const auto v = test::dbc::decode(*m, f.data);
    if (m == &summary) {
      frame_at = f.us;
      frame_counter = static_cast<long long>(v.at("FrameCounter"));
    } else if (m == &heartbeat) {
      heartbeats.push_back(f.us);
      frame_at = -1;
    } else if (m == &stop) {
      Stop s{static_cast<int>(v.at("Command")), v.at("ReasonObstacle") == 1.0, v.at("ReasonStartingUp") == 1.0};
      if (frame_at == f.us) {
        EXPECT_EQ(by_frame.count(frame_counter), 0U) << "two decisions for rotation " << frame_counter;
        by_frame[frame_counter] = s;
        frame_at = -1;
      } else if (by_frame.empty()) {
        before_first_frame.push_back(s);
      }
    }
  }
  ASSERT_EQ(by_frame.size(), static_cast<std::size_t>(kRotations));
  // Start-up: STOP, starting up, every heartbeat period from the first packet until the first decision.
  ASSERT_FALSE(before_first_frame.empty());
  for (const auto& s : before_first_frame) {
    EXPECT_EQ(s.command, 1);
    EXPECT_TRUE(s.starting_up);
  }
  ASSERT_GT(heartbeats.size(), static_cast<std::size_t>(kRotations / 2));
  for (std::size_t i = 1; i < heartbeats.size(); ++i) {
    EXPECT_EQ(heartbeats[i] - heartbeats[i - 1], 100000) << "heartbeat " << i;
  }

  // Truth: the pedestrian's box per rotation, paired with the replay's rotation by stamp.
  const auto truth = testing::json_lines(slurp(truth_path));
  const auto detected = testing::json_lines(slurp(obstacles));
  ASSERT_EQ(truth.size(), static_cast<std::size_t>(kRotations));
  ASSERT_EQ(detected.size(), truth.size());
  enum class Where { Inside, Far, Between };
  std::vector<Where> where;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    EXPECT_NEAR(detected[k].at("stamp").get<double>(), truth[k].at("stamp").get<double>(), 1e-3) << k;
    Where w = Where::Far;
    for (const auto& o : truth[k].at("objects")) {
      if (o.at("id").get<std::string>() != "pedestrian") continue;
      const auto lo = o.at("min").get<std::vector<double>>();
      const auto hi = o.at("max").get<std::vector<double>>();
      // Inside: overlapping the zone by more than 0.3 m and seen; far: 1.5 m clear of it.
      const double m = e.inside_margin;
      const bool inside =
          lo[0] < zx1 - m && hi[0] > zx0 + m && lo[1] < zy - m && hi[1] > -zy + m && o.at("hits").get<double>() >= 5;
      const double f = e.far_margin;
      const bool far = lo[0] > zx1 + f || hi[0] < zx0 - f || lo[1] > zy + f || hi[1] < -zy - f;
      w = inside ? Where::Inside : (far ? Where::Far : Where::Between);
    }
    where.push_back(w);
  }
  int inside = 0;
  int go_checked = 0;
  int held = 0;
  for (int k = 0; k < kRotations; ++k) {
    const Stop& s = by_frame.at(k);
    if (where[static_cast<std::size_t>(k)] == Where::Inside) {
      ++inside;
      EXPECT_EQ(s.command, 1) << "rotation " << k << ": the pedestrian is in the stop zone";
      EXPECT_TRUE(s.obstacle) << "rotation " << k;
      // Go needs `clear` clear rotations: the next clear - 1 stay STOP, whatever the pedestrian does.
      for (int j = k + 1; j < std::min(k + clear, kRotations); ++j) {
        EXPECT_EQ(by_frame.at(j).command, 1) << "rotation " << j << " follows an obstacle in the zone at " << k;
        ++held;
      }
    }
    bool far_long_enough = k >= clear;
    for (int j = k - clear + 1; far_long_enough && j <= k; ++j) {
      far_long_enough = where[static_cast<std::size_t>(j)] == Where::Far;
    }
    if (far_long_enough) {
      ++go_checked;
      EXPECT_EQ(s.command, 0) << "rotation " << k << ": the pedestrian has been far from the zone for " << clear
                              << " rotations";
    }
  }
  EXPECT_GE(inside, e.inside);
  EXPECT_GE(held, e.inside > 0 ? clear - 1 : 0);
  EXPECT_GE(go_checked, e.go);
  int entries = 0;
  for (int k = 1; k < kRotations; ++k) {
    if (by_frame.at(k - 1).command == 0 && by_frame.at(k).command == 1) {
      EXPECT_EQ(where[static_cast<std::size_t>(k)], Where::Inside)
          << "rotation " << k << " stops, but not for the pedestrian";
      ++entries;
    }
  }
  EXPECT_GE(entries, e.entries);
  // The summary counts the decisions.
  const auto pos = r.output.find("stop decisions    ");
  ASSERT_NE(pos, std::string::npos) << r.output;
  long long stops = 0;
  long long gos = 0;
  long long changes = 0;
  ASSERT_EQ(
      std::sscanf(r.output.c_str() + pos, "stop decisions %lld stop, %lld go, %lld changes", &stops, &gos, &changes),
      3);
  EXPECT_EQ(stops + gos, kRotations);
  long long stop_frames = 0;
  for (const auto& [k, s] : by_frame) stop_frames += s.command == 1 ? 1 : 0;
  EXPECT_EQ(stops, stop_frames);
  EXPECT_GE(changes, 2);
  EXPECT_EQ(summary_number(r.output, "can frames"), static_cast<long long>(count_lines(text)));
}

TEST_F(SimCapture, CanLogStopsForThePedestrianInTheZoneAndGoesWhenClear) {
  // The shipped zone (17.4 m ahead at the unknown-speed 30 km/h, 2 m each side): the crossings at 5, 10 and 15 m
  // are inside it, those at 20 m and beyond are not.
  check_can_log(kConfig, pcap_, truth_, Expect{0.3, 1.5, 20, 20, 0});
}

TEST_F(SimCapture, CanLogStopsWhenThePedestrianWalksIntoANarrowZone) {
  // A zone 0.6 m wide: each crossing walks into it and out again, so every band shows GO -> STOP on entry.
  testing::TempDir dir;
  std::string text = slurp(kConfig);
  const std::string key = "\n    half_width_m: 2.0 ";
  ASSERT_NE(text.find(key), std::string::npos);
  text.replace(text.find(key), key.size(), "\n    half_width_m: 0.3 ");
  const auto cfg = (dir.path() / "narrow.yaml").string();
  std::ofstream(cfg) << text;
  check_can_log(cfg, pcap_, truth_, Expect{0.1, 0.05, 8, 3, 2});
}

}  // namespace
}  // namespace fieldguard
