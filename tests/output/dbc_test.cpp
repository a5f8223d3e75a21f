// config/fieldguard.dbc against the layouts and the encoder, through the test-only reader (dbc_reader.hpp),
// which shares no code with src/output.

#include "fieldguard/output/dbc.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "fieldguard/output/can_encoder.hpp"
#include "fieldguard/output/crc8.hpp"
#include "output/dbc_reader.hpp"

namespace fieldguard::output {
namespace {

namespace dbc = fieldguard::test::dbc;

std::string read_text(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

const std::string kCommitted = std::string(FIELDGUARD_SOURCE_DIR) + "/config/fieldguard.dbc";

TEST(Dbc, CommittedFileIsWhatTheLayoutsPrint) {
  const std::string committed = read_text(kCommitted);
  ASSERT_FALSE(committed.empty()) << kCommitted << " is missing: build fieldguard-dbc and run "
                                  << "`build/tools/fieldguard-dbc > config/fieldguard.dbc`";
  EXPECT_EQ(committed, dbc_text(CanParams{}))
      << "config/fieldguard.dbc is stale: regenerate it with `build/tools/fieldguard-dbc > config/fieldguard.dbc`";
}

TEST(Dbc, DescribesEveryMessageWithExtendedIdsAndItsConventions) {
  const dbc::Database db = dbc::parse_file(kCommitted);
  const CanEncoder enc(CanParams{});
  ASSERT_EQ(db.messages.size(), kMessageCount);
  for (const MessageLayout& m : message_layouts()) {
    const dbc::Message& dm = db.by_name(m.name);
    SCOPED_TRACE(dm.name);
    EXPECT_TRUE(dm.extended());
    EXPECT_EQ(dm.dbc_id, enc.id_of(m.id) | 0x80000000U);
    EXPECT_EQ(dm.dlc, 8U);
    // A multiplexed message has its multiplexor and every other signal once per multiplexor value (16 for a 4-bit
    // Index); each of them in the DBC is multiplexed.
    const std::size_t per = m.multiplexor.empty() ? 1 : 16;
    EXPECT_EQ(dm.signals.size(), m.multiplexor.empty() ? m.signals.size() : 1 + (m.signals.size() - 1) * per);
    for (const dbc::Signal& s : dm.signals) {
      EXPECT_EQ(s.multiplexor, !m.multiplexor.empty() && s.name == m.multiplexor) << s.name;
      EXPECT_EQ(s.mux_value.has_value(), !m.multiplexor.empty() && s.name != m.multiplexor) << s.name;
    }
    EXPECT_FALSE(dm.comment.empty());
  }
  const dbc::Message& obstacle = db.by_name("FG_OBSTACLE");
  EXPECT_EQ(obstacle.signal("XMin_15").mux_value, 15U);
  EXPECT_EQ(obstacle.signal("SizeClass_3").values.at(1), "LARGE");
  // A value the table names is inside the declared range: NO_OBSTACLE (raw 65535) is 655.35 m and 475.35 deg.
  for (const char* name : {"NearestDistance", "NearestBearing"}) {
    const dbc::Signal& s = db.by_name("FG_OBSTACLE_SUMMARY").signal(name);
    EXPECT_LE(65535.0 * s.factor + s.offset, s.max + 1e-9) << name;
  }
  const dbc::Message& stop = db.by_name("FG_STOP_REQUEST");
  EXPECT_NE(stop.comment.find("CRC-8/SAE-J1850"), std::string::npos);
  EXPECT_NE(stop.comment.find("poly 0x1D"), std::string::npos);
  EXPECT_EQ(stop.cycle_ms, 100U);
  EXPECT_EQ(db.by_name("FG_HEARTBEAT").cycle_ms, 100U);
  EXPECT_EQ(stop.signal("Command").values.at(1), "STOP");
  EXPECT_EQ(stop.signal("Command").values.at(0), "GO");
  EXPECT_EQ(db.by_name("FG_OBSTACLE_SUMMARY").signal("NearestDistance").unit, "m");
  EXPECT_EQ(db.by_name("FG_OBSTACLE_SUMMARY").signal("NearestDistance").values.at(65535), "NO_OBSTACLE");
}

TEST(Dbc, OtherAddressesChangeTheIds) {
  CanParams p;
  p.source_address = 0x2A;
  p.controller_address = 0x13;
  const dbc::Database db = dbc::parse(dbc_text(p));
  EXPECT_EQ(db.by_name("FG_STOP_REQUEST").can_id(), 0x0CEF132AU);
  EXPECT_EQ(db.by_name("FG_HEARTBEAT").can_id(), 0x18FF122AU);
}

// The proof that DBC and encoder agree: encode, decode with the DBC, get the values back.
class DbcRoundTrip : public ::testing::Test {
 protected:
  dbc::Database db = dbc::parse_file(kCommitted);
  CanEncoder enc{CanParams{}};

  const dbc::Message& message_of(const CanFrame& f) {
    const dbc::Message* m = db.by_can_id(f.id);
    if (m == nullptr) throw std::runtime_error("frame id not in the DBC");
    return *m;
  }
};

double clamp_step(double v, double lo, double hi) { return std::clamp(v, lo, hi); }

TEST_F(DbcRoundTrip, ObstacleFramesDecodeToTheirValues) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> x(-30.F, 120.F);  // beyond the signal range at both ends
  std::uniform_real_distribution<float> y(-110.F, 110.F);
  std::uniform_real_distribution<float> size(0.1F, 5.F);
  std::uniform_real_distribution<float> height(-1.F, 14.F);
  std::uniform_int_distribution<std::uint32_t> points(0, 400);
  std::uniform_real_distribution<float> bearing(-180.F, 180.F);
  for (std::uint32_t frame = 0; frame < 200; ++frame) {
    std::vector<perception::Obstacle> obs(frame % 12);
    for (auto& o : obs) {
      o.min = {x(rng), y(rng), -0.5F};
      o.max = {o.min[0] + size(rng), o.min[1] + size(rng), 1.F};
      o.distance_m = std::max(0.F, o.min[0]) + static_cast<float>(frame % 3);
      o.bearing_deg = bearing(rng);
      o.height_above_ground_m = height(rng);
      o.points = points(rng);
      o.size_class = o.points % 2 == 0 ? perception::SizeClass::Small : perception::SizeClass::Large;
    }
    std::vector<CanFrame> out;
    enc.encode_frame(FrameReport{frame, FrameStatus::Ok, obs}, out);
    std::vector<perception::Obstacle> sorted = obs;
    std::stable_sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) {
      return std::tie(a.distance_m, a.bearing_deg) < std::tie(b.distance_m, b.bearing_deg);
    });
    ASSERT_EQ(out.size(), 1 + std::min<std::size_t>(obs.size(), 8));

    const auto s = dbc::decode(message_of(out[0]), out[0].data);
    EXPECT_EQ(message_of(out[0]).name, "FG_OBSTACLE_SUMMARY");
    EXPECT_EQ(s.at("ObstacleCount"), static_cast<double>(obs.size()));
    EXPECT_EQ(s.at("FrameCounter"), static_cast<double>(frame));
    EXPECT_EQ(s.at("ListTruncated"), obs.size() > 8 ? 1.0 : 0.0);
    if (obs.empty()) {
      EXPECT_EQ(dbc::raw_value(message_of(out[0]).signal("NearestDistance"), out[0].data), 65535U);
    } else {
      EXPECT_NEAR(s.at("NearestDistance"), clamp_step(static_cast<double>(sorted[0].distance_m), 0, 600), 0.0051);
      EXPECT_NEAR(s.at("NearestBearing"), static_cast<double>(sorted[0].bearing_deg), 0.0051);
    }
    bool any_clamped = false;
    for (std::size_t i = 1; i < out.size(); ++i) {
      const perception::Obstacle& o = sorted[i - 1];
      const auto d = dbc::decode(message_of(out[i]), out[i].data);
      SCOPED_TRACE("frame " + std::to_string(frame) + " obstacle " + std::to_string(i - 1));
      EXPECT_EQ(message_of(out[i]).name, "FG_OBSTACLE");
      EXPECT_EQ(d.at("Index"), static_cast<double>(i - 1));
      EXPECT_EQ(d.at("SizeClass_" + std::to_string(i - 1)), static_cast<double>(o.size_class));
      // Multiplexed on Index in the DBC: the nearest obstacle's XMin is XMin_0, and only its own are decoded.
      const std::string suffix = "_" + std::to_string(i - 1);
      EXPECT_EQ(d.count("XMin_" + std::to_string(i)), 0U);
      const auto check = [&](const char* name, float v, double lo, double hi, double step) {
        const double want = clamp_step(static_cast<double>(v), lo, hi);
        any_clamped |= want != static_cast<double>(v) && std::abs(want - static_cast<double>(v)) > step / 2;
        EXPECT_NEAR(d.at(name + suffix), want, step / 2 + 1e-6) << name;
      };
      check("XMin", o.min[0], -102.4, 102.3, 0.1);
      check("XMax", o.max[0], -102.4, 102.3, 0.1);
      check("YMin", o.min[1], -102.4, 102.3, 0.1);
      check("YMax", o.max[1], -102.4, 102.3, 0.1);
      check("Height", o.height_above_ground_m, 0, 12.6, 0.2);
      EXPECT_EQ(d.at("Points_" + std::to_string(i - 1)), std::min(255.0, static_cast<double>(o.points)));
      any_clamped |= o.points > 255;
    }
    if (!obs.empty() && any_clamped) {
      EXPECT_EQ(s.at("Saturated"), 1.0);
    }
  }
}

TEST_F(DbcRoundTrip, StopAndHeartbeatDecodeToTheirValues) {
  for (int i = 0; i < 40; ++i) {
    StopRequest r;
    r.command = static_cast<StopCommand>(i % 3);
    r.reasons.obstacle_in_zone = (i & 1) != 0;
    r.reasons.sensor_fault = (i & 2) != 0;
    r.reasons.pipeline_late = (i & 4) != 0;
    r.reasons.starting_up = (i & 8) != 0;
    r.reasons.shutting_down = (i & 16) != 0;
    const CanFrame f = enc.encode_stop(r);
    const dbc::Message& m = message_of(f);
    EXPECT_EQ(m.name, "FG_STOP_REQUEST");
    const auto d = dbc::decode(m, f.data);
    EXPECT_EQ(m.signal("Command").values.at(static_cast<std::int64_t>(d.at("Command"))),
              i % 3 == 0 ? "GO" : (i % 3 == 1 ? "STOP" : "ERROR"));
    EXPECT_EQ(d.at("ReasonObstacle"), (i & 1) != 0 ? 1.0 : 0.0);
    EXPECT_EQ(d.at("ReasonSensorFault"), (i & 2) != 0 ? 1.0 : 0.0);
    EXPECT_EQ(d.at("ReasonPipelineLate"), (i & 4) != 0 ? 1.0 : 0.0);
    EXPECT_EQ(d.at("ReasonStartingUp"), (i & 8) != 0 ? 1.0 : 0.0);
    EXPECT_EQ(d.at("ReasonShuttingDown"), (i & 16) != 0 ? 1.0 : 0.0);
    EXPECT_EQ(d.at("AliveCounter"), static_cast<double>(i % 16));
    EXPECT_EQ(d.at("Crc"), static_cast<double>(crc8<kCrc8SaeJ1850>(std::span<const std::uint8_t>(f.data.data(), 7))));

    Heartbeat hb;
    hb.lidar3d = static_cast<SensorHealth>(i % 4);
    hb.ahrs = static_cast<SensorHealth>((i + 1) % 4);
    hb.frames_lost = static_cast<std::uint64_t>(i) * 1000U;
    const CanFrame h = enc.encode_heartbeat(hb);
    const dbc::Message& hm = message_of(h);
    EXPECT_EQ(hm.name, "FG_HEARTBEAT");
    const auto hd = dbc::decode(hm, h.data);
    EXPECT_EQ(hd.at("Lidar3d"), static_cast<double>(i % 4));
    EXPECT_EQ(hd.at("Ahrs"), static_cast<double>((i + 1) % 4));
    EXPECT_EQ(hd.at("Lidar2d"), 3.0);  // Unknown
    EXPECT_EQ(hd.at("FramesLost"), static_cast<double>((i * 1000) % 65536));
    EXPECT_EQ(hd.at("AliveCounter"), static_cast<double>(i % 16));
  }
}

// The reader itself, on somebody else's DBC and real frames: a J1939 demo DBC and a truck's candump log.
TEST(DbcReader, DecodesRealJ1939FramesWithAThirdPartyDbc) {
  const dbc::Database db = dbc::parse_file(std::string(FIELDGUARD_TEST_DATA) + "/can/css_j1939_demo.dbc");
  const dbc::Message& eec1 = db.by_name("EEC1");
  const dbc::Message& ccvs1 = db.by_name("CCVS1");
  EXPECT_TRUE(eec1.extended());
  EXPECT_EQ((eec1.can_id() >> 8) & 0x3FFFFU, 61444U);   // PGN of EEC1
  EXPECT_EQ((ccvs1.can_id() >> 8) & 0x3FFFFU, 65265U);  // PGN of CCVS1
  std::ifstream log(std::string(FIELDGUARD_TEST_DATA) + "/can/j1939_truck_idle_first300.log");
  ASSERT_TRUE(log);
  std::string line;
  int eec1_frames = 0;
  int ccvs_frames = 0;
  double rpm_min = 1e9;
  double rpm_max = 0;
  while (std::getline(log, line)) {
    const auto hash = line.find('#');
    const std::uint32_t id = static_cast<std::uint32_t>(std::stoul(line.substr(hash - 8, 8), nullptr, 16));
    std::vector<std::uint8_t> data;
    for (std::size_t i = hash + 1; i + 1 < line.size(); i += 2) {
      data.push_back(static_cast<std::uint8_t>(std::stoul(line.substr(i, 2), nullptr, 16)));
    }
    const std::uint32_t pgn = (id >> 8) & 0x3FFFFU;
    if (pgn == 61444U) {
      ++eec1_frames;
      const double rpm = dbc::decode(eec1, data).at("EngineSpeed");
      rpm_min = std::min(rpm_min, rpm);
      rpm_max = std::max(rpm_max, rpm);
    } else if (pgn == 65265U) {
      ++ccvs_frames;
      EXPECT_EQ(dbc::decode(ccvs1, data).at("WheelBasedVehicleSpeed"), 0.0);  // parked
    }
  }
  EXPECT_EQ(eec1_frames, 84);
  EXPECT_EQ(ccvs_frames, 9);
  // Idling (the capture's notes: 650-654 rpm over the whole recording); this slice: 647.75-652.25.
  EXPECT_DOUBLE_EQ(rpm_min, 647.75);
  EXPECT_DOUBLE_EQ(rpm_max, 652.25);
}

TEST(DbcReader, ReadsBigEndianAndSignedSignals) {
  const dbc::Database db = dbc::parse(
      "BO_ 291 M: 8 X\n"
      " SG_ Be : 7|16@0+ (1,0) [0|65535] \"\" Y\n"
      " SG_ Neg : 16|8@1- (0.5,1) [-63|64.5] \"V\" Y\n"
      "\n"
      "VAL_ 291 Be 4660 \"magic\" 0 \"zero\" ;\n");
  const dbc::Message& m = db.by_name("M");
  EXPECT_FALSE(m.extended());
  const std::vector<std::uint8_t> data{0x12, 0x34, 0xFE, 0, 0, 0, 0, 0};
  EXPECT_EQ(dbc::raw_value(m.signal("Be"), data), 0x1234U);
  EXPECT_EQ(dbc::physical_value(m.signal("Neg"), data), 0.0);  // -2 * 0.5 + 1
  EXPECT_EQ(m.signal("Be").values.at(4660), "magic");
  EXPECT_THROW((void)dbc::parse("BO_ 1 M: 8 X\n SG_ broken\n"), std::runtime_error);
}

}  // namespace
}  // namespace fieldguard::output
