// fieldguard-sim --session: the GNSS, AHRS and 2D LiDAR streams beside the HDL-32E capture, each decoded by
// the project's own decoders (nmea::StreamParser, xsens::StreamParser, scip::Session as replay runs them)
// and held against the simulator's pose truth; the uneven-drive scene's attitude, pole and low box.
#include <gtest/gtest.h>

#include <GeographicLib/LocalCartesian.hpp>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "fieldguard/drivers/nmea_stream.hpp"
#include "fieldguard/drivers/scip_session.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"
#include "fieldguard/drivers/xsens_stream.hpp"
#include "fieldguard/io/byte_log.hpp"
#include "fieldguard/io/pcap_reader.hpp"
#include "sim/geodesy.hpp"
#include "sim/scenes.hpp"
#include "sim/simulator.hpp"
#include "support/shared_output.hpp"
#include "tools/tools_test_support.hpp"

namespace fieldguard::sim {
namespace {

constexpr int kRotations = 100;  // 10 s: 5.5 s driving, 2 s braking, 2.5 s standing before the box
constexpr double kDurationS = kRotations * 0.10009728;  // 181 packets of 552.96 us a rotation
constexpr std::int64_t kStartNs = 1718449170LL * 1000000000LL;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using Json = nlohmann::json;

std::vector<Json> read_jsonl(const std::string& path) {
  std::vector<Json> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    auto v = Json::parse(line, nullptr, /*allow_exceptions=*/false);
    EXPECT_FALSE(v.is_discarded()) << path << ": not JSON: " << line;
    if (!v.is_discarded()) out.push_back(std::move(v));
  }
  return out;
}

double num(const Json& v, std::string_view key) {
  const auto m = v.find(key);
  EXPECT_TRUE(m != v.end() && m->is_number()) << key;
  return m != v.end() && m->is_number() ? m->get<double>() : kNaN;
}

std::vector<io::ByteLogRecord> read_log(const std::string& path) {
  std::vector<io::ByteLogRecord> out;
  auto r = io::ByteLogReader::open(path);
  EXPECT_TRUE(r.has_value()) << path;
  if (!r) return out;
  while (auto rec = r->next()) out.push_back(std::move(*rec));
  EXPECT_FALSE(r->truncated()) << path;
  EXPECT_TRUE(r->error().empty()) << r->error();
  return out;
}

struct Stats {
  double mean = 0.0;
  double sd = 0.0;
};
Stats stats(const std::vector<double>& v) {
  Stats s;
  if (v.empty()) return s;
  s.mean = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  double q = 0.0;
  for (const double x : v) q += (x - s.mean) * (x - s.mean);
  s.sd = std::sqrt(q / static_cast<double>(v.size()));
  return s;
}

class SimSession : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One session per build, shared by this suite's test processes (ctest runs each test in its own).
    std::string errors;
    dir_ = new std::string(testing::shared_output(
        FIELDGUARD_TEST_WORK,
        "uneven-drive-" + std::to_string(kRotations) + "-seed3-" + testing::stamp_of(FIELDGUARD_SIM),
        [&](const std::string& d) {
          const auto r = tools_test::run(FIELDGUARD_SIM, "--scene uneven-drive --session '" + d + "' --rotations " +
                                                             std::to_string(kRotations) + " --seed 3 --quiet");
          errors = r.errors;
          return r.exit_code == 0;
        }));
    ASSERT_FALSE(dir_->empty()) << errors;
    for (const auto& v : read_jsonl(path("pose.truth.jsonl"))) {
      if (v.contains("session")) {
        header_ = new Json(v.at("session"));
        continue;
      }
      truth_[v.at("sensor").get<std::string>()].push_back(v);
    }
  }
  static void TearDownTestSuite() {
    delete header_;
    delete dir_;
    truth_.clear();
  }
  static std::string path(const std::string& name) { return *dir_ + "/" + name; }

  static std::string* dir_;
  static Json* header_;
  static std::map<std::string, std::vector<Json>> truth_;
};
std::string* SimSession::dir_ = nullptr;
Json* SimSession::header_ = nullptr;
std::map<std::string, std::vector<Json>> SimSession::truth_;

TEST_F(SimSession, WritesTheRecordLayout) {
  for (const char* f : {"lidar.pcap", "lidar.truth.jsonl", "gnss.log", "ahrs.log", "scan2d.log", "pose.truth.jsonl"}) {
    EXPECT_TRUE(std::filesystem::exists(path(f))) << f;
  }
  ASSERT_NE(header_, nullptr);
  EXPECT_NEAR(header_->at("origin").at("lat_deg").get<double>(), 48.1, 1e-9);
  EXPECT_EQ(truth_["gnss"].size(), static_cast<std::size_t>(std::ceil(kDurationS * 10.0)));
  EXPECT_EQ(truth_["ahrs"].size(), static_cast<std::size_t>(std::ceil(kDurationS * 100.0)));
  EXPECT_EQ(truth_["scan2d"].size(), static_cast<std::size_t>(std::ceil(kDurationS * 40.0)));
}

TEST_F(SimSession, GnssDecodesWithRtkNoiseAt10Hz) {
  const auto records = read_log(path("gnss.log"));
  nmea::StreamParser parser;
  std::vector<nmea::Sentence> sentences;
  std::vector<std::int64_t> gga_host_ns;
  for (const auto& r : records) {
    EXPECT_EQ(r.direction, io::Direction::FromSensor);
    const std::size_t before = sentences.size();
    parser.push(std::span<const std::uint8_t>(r.bytes), sentences);
    for (std::size_t i = before; i < sentences.size(); ++i) {
      if (std::holds_alternative<nmea::Gga>(sentences[i])) gga_host_ns.push_back(r.host_time.ns);
    }
  }
  parser.finish(sentences);
  EXPECT_EQ(parser.counters().rejected(), 0U);
  EXPECT_EQ(parser.counters().noise_bytes, 0U);
  std::vector<nmea::Gga> gga;
  std::vector<nmea::Rmc> rmc;
  std::vector<nmea::Hdt> hdt;
  for (const auto& s : sentences) {
    if (const auto* g = std::get_if<nmea::Gga>(&s)) gga.push_back(*g);
    if (const auto* m = std::get_if<nmea::Rmc>(&s)) rmc.push_back(*m);
    if (const auto* h = std::get_if<nmea::Hdt>(&s)) hdt.push_back(*h);
  }
  const auto& truth = truth_["gnss"];
  ASSERT_EQ(gga.size(), truth.size());
  ASSERT_EQ(rmc.size(), truth.size());
  ASSERT_EQ(hdt.size(), truth.size());
  std::vector<double> north;
  std::vector<double> east;
  std::vector<double> up;
  std::vector<double> heading;
  for (std::size_t k = 0; k < gga.size(); ++k) {
    ASSERT_TRUE(gga[k].lat_deg && gga[k].lon_deg && gga[k].alt_m && gga[k].utc_seconds_of_day);
    EXPECT_EQ(gga[k].quality.value_or(0), 4);  // RTK fixed
    // 10 Hz on the UTC tenth: 10:59:30.0 + k/10.
    EXPECT_NEAR(*gga[k].utc_seconds_of_day, 10 * 3600 + 59 * 60 + 30 + 0.1 * static_cast<double>(k), 1e-6);
    const double t_epoch_ns = static_cast<double>(kStartNs) + 1e8 * static_cast<double>(k);
    const double latency_ms = (static_cast<double>(gga_host_ns[k]) - t_epoch_ns) * 1e-6;
    EXPECT_GT(latency_ms, 20.0);
    EXPECT_LT(latency_ms, 60.0);
    const Json& ant = truth[k].at("antenna");
    const double lat = num(ant, "lat_deg");
    north.push_back((*gga[k].lat_deg - lat) * kPi / 180.0 * 6366000.0);
    east.push_back((*gga[k].lon_deg - num(ant, "lon_deg")) * kPi / 180.0 * 6389000.0 * std::cos(lat * kPi / 180.0));
    up.push_back(*gga[k].alt_m + gga[k].geoid_sep_m.value_or(kNaN) - num(ant, "h_m"));
    EXPECT_TRUE(rmc[k].valid);
    EXPECT_NEAR(*rmc[k].lat_deg, *gga[k].lat_deg, 1e-9);
    heading.push_back(hdt[k].heading_deg.value_or(kNaN) - num(truth[k], "heading_deg"));
    if (k == 0) {
      EXPECT_NEAR(lat, 48.1, 0.01);
      EXPECT_EQ(rmc[k].day.value_or(0), 15);
      EXPECT_EQ(rmc[k].month.value_or(0), 6);
      EXPECT_EQ(rmc[k].year.value_or(0), 2024);
    }
  }
  const Stats n = stats(north);
  const Stats e = stats(east);
  const Stats u = stats(up);
  const Stats h = stats(heading);
  std::printf(
      "GNSS error over %zu epochs: north %.4f +- %.4f m, east %.4f +- %.4f m, up %.4f +- %.4f m, heading %.3f +- %.3f "
      "deg\n",
      gga.size(), n.mean, n.sd, e.mean, e.sd, u.mean, u.sd, h.mean, h.sd);
  // RTK fixed: about 1 cm a horizontal axis (correlated over seconds: 101 epochs see a part of it).
  for (const Stats& s : {n, e}) {
    EXPECT_LT(std::abs(s.mean), 0.03);
    EXPECT_GT(s.sd, 0.002);
    EXPECT_LT(s.sd, 0.025);
  }
  EXPECT_LT(std::abs(u.mean), 0.06);
  EXPECT_GT(h.sd, 0.05);
  EXPECT_LT(h.sd, 0.2);
}

TEST_F(SimSession, AhrsDecodesAt100HzWithSmallAttitudeNoise) {
  const auto records = read_log(path("ahrs.log"));
  xsens::StreamParser parser;
  std::vector<xsens::StreamItem> items;
  std::vector<std::int64_t> host;
  for (const auto& r : records) {
    const std::size_t before = items.size();
    parser.push(std::span<const std::uint8_t>(r.bytes), items);
    for (std::size_t i = before; i < items.size(); ++i) host.push_back(r.host_time.ns);
  }
  parser.finish(items);
  EXPECT_EQ(parser.counters().rejected(), 0U);
  EXPECT_EQ(parser.counters().garbage_bytes, 0U);
  EXPECT_EQ(parser.counters().unknown_data_ids, 0U);
  const auto& truth = truth_["ahrs"];
  ASSERT_EQ(items.size(), truth.size());
  std::vector<double> droll;
  std::vector<double> dpitch;
  std::vector<double> dyaw;
  std::vector<double> latency_ms;
  std::uint32_t extra_ticks = 0;
  for (std::size_t k = 0; k < items.size(); ++k) {
    const auto* m = std::get_if<xsens::MtData2>(&items[k]);
    ASSERT_NE(m, nullptr);
    ASSERT_TRUE(m->packet_counter && m->sample_time_fine && m->euler_deg);
    EXPECT_EQ(m->euler_frame, xsens::CoordinateSystem::Enu);
    EXPECT_EQ(*m->packet_counter, static_cast<std::uint16_t>(k));
    EXPECT_EQ(*m->sample_time_fine, static_cast<std::uint32_t>(num(truth[k], "sample_time_fine")));
    if (k > 0) {
      const auto* prev = std::get_if<xsens::MtData2>(&items[k - 1]);
      // 100 Hz on a 10 kHz clock that runs 20 ppm fast: 100 ticks, 101 every 500th sample.
      const auto d = static_cast<std::uint32_t>(*m->sample_time_fine - *prev->sample_time_fine);
      EXPECT_TRUE(d == 100 || d == 101) << k << ": " << d;
      extra_ticks += d - 100;
    }
    droll.push_back(m->euler_deg->x - num(truth[k], "roll_deg"));
    dpitch.push_back(m->euler_deg->y - num(truth[k], "pitch_deg"));
    dyaw.push_back(m->euler_deg->z - num(truth[k], "yaw_deg"));
    latency_ms.push_back((static_cast<double>(host[k]) - static_cast<double>(kStartNs) - 1e7 * static_cast<double>(k)) *
                         1e-6);
  }
  const Stats r = stats(droll);
  const Stats p = stats(dpitch);
  const Stats y = stats(dyaw);
  const Stats l = stats(latency_ms);
  std::printf(
      "AHRS error over %zu samples: roll %.4f +- %.4f, pitch %.4f +- %.4f, yaw %.4f +- %.4f deg; latency %.2f +- %.2f "
      "ms\n",
      items.size(), r.mean, r.sd, p.mean, p.sd, y.mean, y.sd, l.mean, l.sd);
  for (const Stats& s : {r, p, y}) {
    EXPECT_LT(std::abs(s.mean), 0.02);
    EXPECT_GT(s.sd, 0.04);
    EXPECT_LT(s.sd, 0.12);
  }
  EXPECT_EQ(extra_ticks, 2U);                         // 1000 intervals x 100 ticks x 20 ppm
  EXPECT_NEAR(num(truth[0], "yaw_deg"), 30.0, 1e-9);  // path heading 60 deg (compass) = ENU yaw 30 deg
  EXPECT_GT(*std::min_element(latency_ms.begin(), latency_ms.end()), 1.0);
  EXPECT_LT(*std::max_element(latency_ms.begin(), latency_ms.end()), 6.0);
  EXPECT_GT(l.sd, 0.1);  // jitter
}

// Decodes scan2d.log the way replay does: the recorded commands reset the session, the replies feed it.
std::vector<scip::Scan> decode_scans(const std::vector<io::ByteLogRecord>& records, std::vector<std::int64_t>& host,
                                     std::uint64_t& problems) {
  scip::Session session;
  std::vector<scip::Scan> scans;
  problems = 0;
  for (const auto& r : records) {
    if (r.direction == io::Direction::ToSensor) {
      if (r.bytes.size() >= 7 && std::memcmp(r.bytes.data(), "SCIP2.0", 7) == 0) (void)session.connect();
      continue;
    }
    const scip::SessionEvents ev = session.on_bytes(std::span<const std::uint8_t>(r.bytes));
    problems += ev.decode_errors + ev.parser_errors + ev.refusals.size() + ev.sensor_status.size();
    for (const auto& s : ev.scans) {
      scans.push_back(s);
      host.push_back(r.host_time.ns);
    }
  }
  problems += session.client().counters().unexpected_replies;
  return scans;
}

TEST_F(SimSession, Scan2dSessionDecodesAt40Hz) {
  const auto records = read_log(path("scan2d.log"));
  ASSERT_FALSE(records.empty());
  // The conversation starts as the daemon's client starts it.
  ASSERT_EQ(records[0].direction, io::Direction::ToSensor);
  EXPECT_EQ(std::string(records[0].bytes.begin(), records[0].bytes.end()), "SCIP2.0\n");
  std::vector<std::int64_t> host;
  std::uint64_t problems = 0;
  const auto scans = decode_scans(records, host, problems);
  EXPECT_EQ(problems, 0U);
  const auto& truth = truth_["scan2d"];
  ASSERT_EQ(scans.size(), truth.size());
  for (std::size_t k = 0; k < scans.size(); ++k) {
    EXPECT_EQ(scans[k].ranges_mm.size(), 1081U);
    EXPECT_EQ(scans[k].timestamp_ms, static_cast<std::uint32_t>(num(truth[k], "timestamp_ms")));
    if (k > 0) {
      // 40 Hz on the sensor's ms counter (its crystal runs 35 ppm slow: now and then 24 ms).
      const std::uint32_t d = (scans[k].timestamp_ms - scans[k - 1].timestamp_ms) & 0xFFFFFFU;
      EXPECT_TRUE(d == 25 || d == 24) << k << ": " << d;
      EXPECT_GT(host[k], host[k - 1]);
    }
    const double latency_ms =
        (static_cast<double>(host[k]) - static_cast<double>(kStartNs) - 25e6 * static_cast<double>(k)) * 1e-6;
    EXPECT_GT(latency_ms, 18.75);  // sent after the last step
    EXPECT_LT(latency_ms, 22.0);
  }
}

TEST_F(SimSession, LowBoxInFrontIsSeenByThe2dScanNotByThe3dLidar) {
  // The last LiDAR rotation: the tractor stands, the box 1 m in front of the bumper.
  const auto frames = read_jsonl(path("lidar.truth.jsonl"));
  ASSERT_EQ(frames.size(), static_cast<std::size_t>(kRotations));
  const Json& last = frames.back();
  const Json* box = nullptr;
  for (const auto& o : last.at("objects")) {
    if (o.at("id") == "box-1") box = &o;
  }
  ASSERT_NE(box, nullptr);
  EXPECT_EQ(box->at("class"), "box");
  const auto mn = box->at("min").get<std::vector<double>>();
  const auto mx = box->at("max").get<std::vector<double>>();
  // Sensor frame: near face 1.0 m beyond the bumper (0.3 m ahead of the sensor; more where the tractor
  // stands nose up, as the box's bounds turn with the attitude), 0.4 m tall.
  EXPECT_GT(mn[0], 1.1);
  EXPECT_LT(mn[0], 1.5);
  EXPECT_NEAR(mx[2] - mn[2], 0.4, 0.06);
  // Geometry: every point of the box lies below the lowest beam (-30.67 deg) at its horizontal distance.
  double far = 0.0;
  for (const double x : {mn[0], mx[0]}) {
    for (const double y : {mn[1], mx[1]}) far = std::max(far, std::hypot(x, y));
  }
  const double beam_z = -far * std::tan(30.67 * kPi / 180.0);
  std::printf(
      "low box: sensor-frame x %.3f..%.3f, top z %.3f; the lowest beam at its far corner (%.3f m) is at z %.3f\n",
      mn[0], mx[0], mx[2], far, beam_z);
  EXPECT_LT(mx[2], beam_z - 0.1);
  EXPECT_EQ(num(*box, "hits"), 0.0);

  // The decoded HDL-32E points of that rotation: none in the box (grown by 10 cm).
  auto reader = io::PcapReader::open(path("lidar.pcap"));
  ASSERT_TRUE(reader.has_value());
  velodyne::Stream stream{velodyne::StreamOptions{}};
  std::vector<LidarFrame> decoded;
  while (auto d = reader->next()) stream.push(d->payload, d->host_time, decoded);
  stream.finish(decoded);
  ASSERT_EQ(decoded.size(), frames.size());
  std::size_t in_box = 0;
  std::size_t ahead_low = 0;
  for (const LidarPoint& p : decoded.back().points) {
    const auto x = static_cast<double>(p.x);
    const auto y = static_cast<double>(p.y);
    const auto z = static_cast<double>(p.z);
    if (x > mn[0] - 0.1 && x < mx[0] + 0.1 && y > mn[1] - 0.1 && y < mx[1] + 0.1 && z > mn[2] - 0.1 &&
        z < mx[2] + 0.1) {
      ++in_box;
    }
    if (x > 0.0 && x < 2.5 && std::abs(y) < 1.0) ++ahead_low;
  }
  EXPECT_EQ(in_box, 0U);
  EXPECT_EQ(ahead_low, 0U);  // nothing at all in the blind zone ahead

  // The 2D scan of the same moment: the box's face at 0.95 m from the scanner (0.35 m ahead of the sensor),
  // across +-10 deg around straight ahead.
  std::vector<std::int64_t> host;
  std::uint64_t problems = 0;
  const auto scans = decode_scans(read_log(path("scan2d.log")), host, problems);
  ASSERT_FALSE(scans.empty());
  EXPECT_EQ(truth_["scan2d"].back().at("front_target"), "box-1");
  const scip::Scan& s = scans.back();
  std::vector<double> face;
  for (int step = 500; step <= 580; ++step) {
    const double a = (step - 540) * 0.25 * kPi / 180.0;
    face.push_back(s.ranges_mm[static_cast<std::size_t>(step)] * 1e-3 * std::cos(a));
  }
  const Stats f = stats(face);
  std::printf("2D scan on the box: forward distance %.3f +- %.3f m over %zu steps\n", f.mean, f.sd, face.size());
  EXPECT_NEAR(f.mean, 0.95, 0.03);
  EXPECT_LT(f.sd, 0.02);
}

TEST_F(SimSession, PoleIsInTheTruth) {
  bool in_header = false;
  for (const auto& o : header_->at("objects")) {
    if (o.at("id") == "pole-1") {
      in_header = true;
      EXPECT_EQ(o.at("class"), "pole");
      EXPECT_NEAR(o.at("world_max").at(2).get<double>() - o.at("world_min").at(2).get<double>(), 2.0, 0.05);
      EXPECT_NEAR(num(o, "base_lat_deg"), 48.1, 0.01);
    }
  }
  EXPECT_TRUE(in_header);
  std::size_t seen = 0;
  const auto frames = read_jsonl(path("lidar.truth.jsonl"));
  for (const auto& f : frames) {
    for (const auto& o : f.at("objects")) {
      if (o.at("id") == "pole-1" && num(o, "hits") >= 3) ++seen;
    }
  }
  EXPECT_GT(seen, frames.size() * 9 / 10);
}

TEST(SimSessionScene, UnevenDriveRollsAndPitchesUpTo8Degrees) {
  SceneSetup setup;
  setup.rotations = 600;
  setup.period_s = Simulator::period_for(10.0);
  const auto scene = build_scene("uneven-drive", setup);
  ASSERT_TRUE(scene.has_value());
  double max_roll = 0.0;
  double max_pitch = 0.0;
  double end_speed = 1.0;
  for (double t = 0.0; t < 600 * setup.period_s; t += 0.01) {
    const SensorPose p = scene->pose_at(t);
    max_roll = std::max(max_roll, std::abs(p.roll_deg));
    max_pitch = std::max(max_pitch, std::abs(p.pitch_deg));
    end_speed = scene->travel_at(t).second;
  }
  std::printf("uneven-drive (600 rotations): max |roll| %.2f deg, max |pitch| %.2f deg\n", max_roll, max_pitch);
  EXPECT_GT(max_roll, 6.0);
  EXPECT_GT(max_pitch, 6.0);
  EXPECT_LE(std::max(max_roll, max_pitch), 8.5);
  EXPECT_NEAR(std::max(max_roll, max_pitch), 8.0, 0.5);
  EXPECT_EQ(end_speed, 0.0);
}

TEST(SimSessionDeterminism, SameSeedSameBytesOtherSeedOtherNoise) {
  tools_test::ScratchDir dir("session_det");
  for (const char* run : {"a", "b", "c"}) {
    const std::string seed = std::string(run) == "c" ? "8" : "7";
    const auto r = tools_test::run(FIELDGUARD_SIM, "--scene uneven-drive --rotations 10 --quiet --seed " + seed +
                                                       " --session '" + dir.file(run) + "'");
    ASSERT_EQ(r.exit_code, 0) << r.errors;
  }
  for (const char* f : {"lidar.pcap", "lidar.truth.jsonl", "gnss.log", "ahrs.log", "scan2d.log", "pose.truth.jsonl"}) {
    const std::string a = tools_test::read_file(dir.file(std::string("a/") + f));
    EXPECT_FALSE(a.empty()) << f;
    EXPECT_TRUE(a == tools_test::read_file(dir.file(std::string("b/") + f))) << f;
    // The noise follows the seed; the true poses do not (the seed moves only clods, which the pose truth
    // does not list).
    if (std::string(f) != "pose.truth.jsonl") {
      EXPECT_FALSE(a == tools_test::read_file(dir.file(std::string("c/") + f))) << f;
    }
  }
}

TEST(SimSessionCli, BadSessionOptionsAreRefused) {
  tools_test::ScratchDir dir("session_cli");
  for (const std::string& bad :
       {std::string("--antenna 1,2"), std::string("--antenna 0,0,99"), std::string("--origin 95,0,0"),
        std::string("--heading 360"), std::string("--heading x")}) {
    const auto r = tools_test::run(
        FIELDGUARD_SIM, "--scene uneven-drive --rotations 2 --quiet --session '" + dir.file("x") + "' " + bad);
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_NE(r.errors.find(bad.substr(0, bad.find(' '))), std::string::npos) << r.errors;
  }
  // A session directory that cannot be created is a write failure.
  tools_test::write_file(dir.file("file"), "x");
  const auto r = tools_test::run(FIELDGUARD_SIM,
                                 "--scene uneven-drive --rotations 2 --quiet --session '" + dir.file("file/sub") + "'");
  EXPECT_EQ(r.exit_code, 1);
}

TEST(SimGeodesy, WorldToGeodeticAgreesWithGeographicLib) {
  const FieldPlacement place({48.1, 11.6, 520.0}, 60.0);
  const GeographicLib::LocalCartesian reference(48.1, 11.6, 520.0);
  for (const Vec3 w :
       {Vec3{0.0, 0.0, 0.0}, Vec3{1000.0, 0.0, 0.0}, Vec3{120.0, -45.0, 3.0}, Vec3{-300.0, 800.0, -2.0}}) {
    const Vec3 enu = place.enu_of(w);
    double lat = 0.0;
    double lon = 0.0;
    double h = 0.0;
    reference.Reverse(enu.x, enu.y, enu.z, lat, lon, h);
    const Geodetic g = place.to_geodetic(w);
    EXPECT_NEAR(g.lat_deg, lat, 1e-10) << w.x << " " << w.y;  // 0.01 mm
    EXPECT_NEAR(g.lon_deg, lon, 1e-10) << w.x << " " << w.y;
    EXPECT_NEAR(g.h_m, h, 1e-5) << w.x << " " << w.y;
  }
  // World x at compass heading 60 deg: 0.866 east, 0.5 north; world y (left) at -30 deg: 0.5 west, 0.866 north.
  const Vec3 fwd = place.enu_of({1.0, 0.0, 0.0});
  EXPECT_NEAR(fwd.x, std::sin(60.0 * kPi / 180.0), 1e-12);
  EXPECT_NEAR(fwd.y, 0.5, 1e-12);
  const Vec3 left = place.enu_of({0.0, 1.0, 0.0});
  EXPECT_NEAR(left.x, -0.5, 1e-12);
  EXPECT_NEAR(left.y, std::sin(60.0 * kPi / 180.0), 1e-12);
  EXPECT_DOUBLE_EQ(place.enu_yaw_deg(), 30.0);
}

}  // namespace
}  // namespace fieldguard::sim
