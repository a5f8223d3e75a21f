// The simulator's VLP-16 and RS-LiDAR-32 (and the HDL-32E's dual return) against the project's decoders: every
// rotation decodes full, every point lies where the simulator cast it (to the distance unit and the 0.01-degree
// azimuths), the RS-32's DIFOP carries the simulator's angle table, dual-return pairs decode, and the command line
// chooses the sensor and the return mode.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "fieldguard/drivers/robosense_stream.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"
#include "fieldguard/io/pcap_reader.hpp"
#include "sim/rs32.hpp"
#include "sim/scenes.hpp"
#include "sim/simulator.hpp"
#include "tools/tools_test_support.hpp"

namespace fieldguard::sim {
namespace {

using tools_test::read_file;
using tools_test::run;
using tools_test::ScratchDir;

constexpr std::int64_t kStartNs = 1718449170LL * 1000000000LL;
constexpr int kRotations = 4;

struct Capture {
  Sensor sensor;
  std::vector<TimedPacket> packets;  // all rotations, in order
  std::vector<FrameTruth> truth;
  int packets_per_rotation = 0;
  double period_s = 0.0;
};

// The orchard: trees with porous crowns (dual-return echoes) and open ground.
Capture simulate(SensorModel model, ReturnMode mode, const std::string& scene = "orchard", int rotations = kRotations) {
  SceneSetup setup;
  setup.rotations = rotations;
  setup.period_s = Simulator::period_for(10.0, model, mode);
  SimSettings settings;
  settings.start_time_ns = kStartNs;
  settings.sensor = model;
  settings.returns = mode;
  settings.keep_cast_points = true;
  Simulator sim(*build_scene(scene, setup), settings);
  Capture c{sim.sensor(), {}, {}, sim.packets_per_rotation(), sim.period_s()};
  for (int k = 0; k < rotations; ++k) c.truth.push_back(sim.rotation(static_cast<std::uint64_t>(k), c.packets));
  return c;
}

bool is_difop(const TimedPacket& p) { return p.port == rs32::kDifopPort; }

// The rotations as the daemon's streams assemble them.
std::vector<LidarFrame> decode_stream(const Capture& c, std::uint64_t& rejected) {
  std::vector<LidarFrame> frames;
  if (c.sensor.model == SensorModel::Rs32) {
    robosense::Stream stream;
    for (const TimedPacket& p : c.packets) {
      if (is_difop(p)) {
        stream.push_difop(p.bytes);
      } else {
        stream.push_msop(p.bytes, Stamp{p.pcap_time_ns}, frames);
      }
    }
    stream.finish(frames);
    rejected = stream.counters().msop_rejected() + stream.counters().difop_rejected();
    return frames;
  }
  velodyne::Stream stream(velodyne::StreamOptions{});  // the model detected from the stream
  for (const TimedPacket& p : c.packets) stream.push(p.bytes, Stamp{p.pcap_time_ns}, frames);
  stream.finish(frames);
  rejected = stream.counters().rejected();
  EXPECT_EQ(stream.model(), c.sensor.model == SensorModel::Vlp16 ? velodyne::Model::VLP16 : velodyne::Model::HDL32E);
  return frames;
}

// One packet at a time, with the project's decoders (an RS-32's DIFOPs calibrate its decoder).
class PacketDecoder {
 public:
  explicit PacketDecoder(const Sensor& s) {
    if (s.model == SensorModel::Rs32) {
      rs_.emplace();
      return;
    }
    const auto model = s.model == SensorModel::Vlp16 ? velodyne::Model::VLP16 : velodyne::Model::HDL32E;
    velodyne::DecoderOptions options;
    options.model = model;
    velodyne_.emplace(velodyne::default_calibration(model), options);
  }
  // False for a DIFOP (taken) or a packet the decoder refuses.
  bool decode(const TimedPacket& p, std::vector<LidarPoint>& out) {
    if (velodyne_) return velodyne_->decode(p.bytes, out).has_value();
    if (is_difop(p)) {
      const auto difop = robosense::parse_difop(p.bytes);
      EXPECT_TRUE(difop.has_value());
      if (difop) (void)rs_->apply(*difop);
      return false;
    }
    return rs_->decode(p.bytes, out).has_value();
  }

 private:
  std::optional<velodyne::Decoder> velodyne_;
  std::optional<robosense::Decoder> rs_;
};

// The decoders' ring of each slot: the rank of its laser's vertical angle, 0 = lowest.
std::array<std::uint16_t, kSlots> rings(const Sensor& s) {
  std::array<std::uint16_t, kSlots> out{};
  for (std::size_t slot = 0; slot < kSlots; ++slot) {
    const double v = s.vertical_deg[slot % s.lasers];
    for (std::size_t l = 0; l < s.lasers; ++l) {
      if (s.vertical_deg[l] < v) ++out[slot];
    }
  }
  return out;
}

bool inside(const Aabb& b, const LidarPoint& p) {
  const auto in = [](double v, double lo, double hi) { return v >= lo && v <= hi; };
  return in(static_cast<double>(p.x), b.min.x, b.max.x) && in(static_cast<double>(p.y), b.min.y, b.max.y) &&
         in(static_cast<double>(p.z), b.min.z, b.max.z);
}

double distance(const LidarPoint& a, const Vec3& b) {
  return std::hypot(static_cast<double>(a.x) - b.x, static_cast<double>(a.y) - b.y, static_cast<double>(a.z) - b.z);
}

class SimSensors : public ::testing::TestWithParam<std::tuple<SensorModel, ReturnMode>> {
 protected:
  static const Capture& capture() {
    // One simulation per parameter, shared by the tests (a few seconds each under a sanitizer).
    static std::map<std::tuple<SensorModel, ReturnMode>, Capture> cache;
    auto it = cache.find(GetParam());
    if (it == cache.end())
      it = cache.emplace(GetParam(), simulate(std::get<0>(GetParam()), std::get<1>(GetParam()))).first;
    return it->second;
  }
};

TEST_P(SimSensors, EveryRotationDecodesFull) {
  const Capture& c = capture();
  std::uint64_t rejected = 0;
  const std::vector<LidarFrame> frames = decode_stream(c, rejected);
  EXPECT_EQ(rejected, 0U);
  // The RS-32's horizontal corrections (+-0.3 degree) put some firings of a rotation's first and last groups on the
  // other side of the cut: the assembler's rotations then begin with the packet before the simulator's (which counts
  // in both), trade a few points with their neighbours, and the last rotation's overhang comes out on its own.
  const bool corrected = c.sensor.model == SensorModel::Rs32;
  const std::size_t slack = corrected ? 4 * kSlots : 0;  // points across the cut: two groups, two echoes
  ASSERT_EQ(frames.size(), static_cast<std::size_t>(kRotations) + (corrected ? 1 : 0));
  std::uint64_t decoded = 0;
  std::uint64_t returns = 0;
  for (const LidarFrame& f : frames) decoded += f.points.size();
  for (const FrameTruth& t : c.truth) returns += t.returns;
  EXPECT_EQ(decoded, returns) << "every return decodes, in one rotation or the next";
  const auto period_ns = static_cast<std::int64_t>(c.packets_per_rotation) * c.sensor.packet_ns();
  for (std::size_t k = 0; k < c.truth.size(); ++k) {
    const LidarFrame& f = frames[k];
    const FrameTruth& t = c.truth[k];
    EXPECT_EQ(t.sensor, c.sensor.name);
    const bool early = corrected && k > 0;  // begun with the previous rotation's last packet
    EXPECT_NEAR(static_cast<double>(f.host_stamp.ns),
                static_cast<double>(t.stamp_ns - (early ? c.sensor.packet_ns() : 0)), 1000.0)
        << "frame " << k;
    EXPECT_NEAR(static_cast<double>(f.points.size()), static_cast<double>(t.returns), static_cast<double>(slack))
        << "frame " << k;
    // The first rotation is partial (the assembler cannot know it began at the cut); the last one may be (it ends
    // with the stream, whether or not the assembler saw its cut coming), with all its points.
    if (k > 0 && k + 1 < c.truth.size()) {
      EXPECT_FALSE(f.partial) << "frame " << k;
      EXPECT_EQ(f.packets, static_cast<std::uint32_t>(c.packets_per_rotation + (early ? 1 : 0))) << "frame " << k;
    }
    // Sensor time: of the frame's first point, a firing of the rotation's first groups.
    const std::int64_t start_ns = kStartNs + static_cast<std::int64_t>(k) * period_ns;
    EXPECT_NEAR(static_cast<double>(f.sensor_stamp.ns - start_ns), 0.0, 2.0 * static_cast<double>(c.sensor.group_ns))
        << "frame " << k;
    ASSERT_FALSE(f.points.empty());
    EXPECT_LT(f.points.front().azimuth_cdeg, 100);
    EXPECT_GT(f.points.back().azimuth_cdeg, 35900);
    EXPECT_NEAR(static_cast<double>(f.points.back().time_s - f.points.front().time_s), c.period_s, 0.002);
  }
  for (std::size_t k = c.truth.size(); k < frames.size(); ++k) {
    EXPECT_TRUE(frames[k].partial);
    EXPECT_LT(frames[k].points.size(), slack);
  }
}

TEST_P(SimSensors, PointsDecodeWhereTheSimulatorCastThem) {
  const Capture& c = capture();
  PacketDecoder decoder(c.sensor);
  const auto ring = rings(c.sensor);
  // A Velodyne point's time is relative to its packet's timestamp, the last firing; an RS-32's to the first.
  const double reference_s =
      c.sensor.model == SensorModel::Rs32 ? 0.0 : static_cast<double>(c.sensor.last_firing_ns()) * 1e-9;
  std::size_t matched = 0;
  std::vector<LidarPoint> points;
  for (const TimedPacket& p : c.packets) {
    points.clear();
    if (!decoder.decode(p, points)) {
      EXPECT_TRUE(is_difop(p));
      continue;
    }
    ASSERT_EQ(points.size(), p.cast.size());
    std::vector<bool> used(p.cast.size(), false);
    for (const LidarPoint& lp : points) {
      // The cast point of the same firing (laser and time); of its two echoes, the nearer one.
      const double fired_s = static_cast<double>(lp.time_s) + reference_s;
      std::size_t best = p.cast.size();
      for (std::size_t i = 0; i < p.cast.size(); ++i) {
        const CastPoint& cp = p.cast[i];
        if (used[i] || ring[cp.slot] != lp.ring || std::abs(static_cast<double>(cp.time_ns) * 1e-9 - fired_s) > 3e-7) {
          continue;
        }
        if (best == p.cast.size() || distance(lp, cp.position) < distance(lp, p.cast[best].position)) best = i;
      }
      ASSERT_LT(best, p.cast.size()) << "a point of ring " << lp.ring << " at " << fired_s << " s not cast";
      used[best] = true;
      const CastPoint& cp = p.cast[best];
      // The distance to half its unit; the direction to the block azimuths' 0.01 degree and their interpolation.
      const double half_unit = 0.5 * c.sensor.distance_unit_m;
      EXPECT_NEAR(static_cast<double>(lp.range_m), cp.range_m, half_unit + 1e-5);
      EXPECT_LE(distance(lp, cp.position), half_unit + 2.5e-4 * cp.range_m + 1e-5)
          << "range " << cp.range_m << " azimuth " << lp.azimuth_cdeg << " ring " << lp.ring;
      ++matched;
    }
  }
  EXPECT_GT(matched, static_cast<std::size_t>(kRotations) * 10000U);
}

using SimDualReturn = SimSensors;

TEST_P(SimDualReturn, PairsDecode) {
  const Capture& c = capture();
  std::size_t pairs_with_two = 0;
  for (const TimedPacket& p : c.packets) {
    if (is_difop(p)) continue;
    const std::size_t base = c.sensor.model == SensorModel::Rs32 ? 42 : 0;
    const auto u16 = [&](std::size_t o) {
      const unsigned first = p.bytes[o];
      const unsigned second = p.bytes[o + 1];
      return c.sensor.model == SensorModel::Rs32 ? (first << 8U) | second : first | (second << 8U);
    };
    for (std::size_t b = 0; b < kBlocks; b += 2) {
      const std::size_t even = base + 100 * b;
      const std::size_t odd = even + 100;
      ASSERT_EQ(u16(even + 2), u16(odd + 2)) << "the blocks of a pair share the azimuth";
      for (std::size_t s = 0; s < kSlots; ++s) {
        const std::size_t e = even + 4 + 3 * s;
        const std::size_t o = odd + 4 + 3 * s;
        if (u16(e) == u16(o) && p.bytes[e + 2] == p.bytes[o + 2]) continue;  // one echo (or none) in both
        ++pairs_with_two;
        ASSERT_NE(u16(e), 0U);
        ASSERT_NE(u16(o), 0U);
        if (c.sensor.model == SensorModel::Rs32) {
          EXPECT_GE(p.bytes[e + 2], p.bytes[o + 2]) << "RS-32: the strongest echo in the even block";
        } else {
          EXPECT_GT(u16(e), u16(o)) << "Velodyne: the last echo in the even block";
        }
      }
    }
  }
  EXPECT_GT(pairs_with_two, 1000U);

  // Decoded, a pair of echoes gives two points at one firing time; hits count firings, not echoes.
  std::uint64_t rejected = 0;
  const std::vector<LidarFrame> frames = decode_stream(c, rejected);
  ASSERT_GE(frames.size(), c.truth.size());
  std::size_t second_echoes = 0;
  for (std::size_t k = 0; k < c.truth.size(); ++k) {
    const auto crown = std::find_if(c.truth[k].objects.begin(), c.truth[k].objects.end(),
                                    [](const ObjectTruth& o) { return o.cls == ObjectClass::Crown && o.hits > 200; });
    ASSERT_NE(crown, c.truth[k].objects.end());
    Aabb box = crown->box;
    box.min = box.min - Vec3{0.1, 0.1, 0.1};
    box.max = box.max + Vec3{0.1, 0.1, 0.1};
    std::map<std::pair<std::uint16_t, float>, int> firings;  // (ring, time) of the points in the crown
    std::size_t in_box = 0;
    for (const LidarPoint& lp : frames[k].points) {
      second_echoes += lp.return_type == ReturnType::Last || lp.return_type == ReturnType::SecondStrongest ? 1 : 0;
      if (!inside(box, lp)) continue;
      ++in_box;
      ++firings[{lp.ring, lp.time_s}];
    }
    EXPECT_GT(in_box, firings.size()) << "some firings echo twice inside the crown";
    EXPECT_LE(crown->hits, firings.size()) << crown->id;
  }
  EXPECT_GT(second_echoes, 1000U);
}

std::string param_name(const ::testing::TestParamInfo<std::tuple<SensorModel, ReturnMode>>& info) {
  const Sensor s = make_sensor(std::get<0>(info.param), std::get<1>(info.param));
  return std::string(s.name) + "_" + std::string(to_string(s.mode));
}

const auto kModels = ::testing::Values(SensorModel::Vlp16, SensorModel::Rs32, SensorModel::Hdl32e);
INSTANTIATE_TEST_SUITE_P(Sensors, SimSensors,
                         ::testing::Combine(kModels, ::testing::Values(ReturnMode::Strongest, ReturnMode::Dual)),
                         param_name);
INSTANTIATE_TEST_SUITE_P(Sensors, SimDualReturn, ::testing::Combine(kModels, ::testing::Values(ReturnMode::Dual)),
                         param_name);

TEST(SimRs32, DifopCarriesTheSimulatedUnit) {
  const Capture c = simulate(SensorModel::Rs32, ReturnMode::Dual, "flat", 12);  // 1.2 s: DIFOPs at 0 s and 1 s
  ASSERT_FALSE(c.packets.empty());
  ASSERT_TRUE(is_difop(c.packets.front())) << "the first DIFOP comes before any MSOP";
  std::vector<std::int64_t> difop_times;
  for (const TimedPacket& p : c.packets) {
    if (!is_difop(p)) continue;
    difop_times.push_back(p.pcap_time_ns);
    const auto d = robosense::parse_difop(p.bytes);
    ASSERT_TRUE(d.has_value());
    EXPECT_EQ(d->rpm, 600);
    EXPECT_EQ(d->return_mode, robosense::ReturnMode::Dual);
    EXPECT_EQ(d->distance_unit, robosense::DistanceUnit::HalfCm);
    ASSERT_TRUE(d->utc_time.has_value());
    EXPECT_EQ(d->utc_time->ns, p.pcap_time_ns);
    ASSERT_TRUE(d->calibration.has_value());
    for (std::size_t ch = 0; ch < rs32::kChannels; ++ch) {
      EXPECT_NEAR(d->calibration->vert_deg[ch], c.sensor.vertical_deg[ch], 1e-9) << "channel " << ch;
      EXPECT_NEAR(d->calibration->horiz_deg[ch], c.sensor.horizontal_deg[ch], 1e-9) << "channel " << ch;
    }
  }
  EXPECT_EQ(difop_times, (std::vector<std::int64_t>{kStartNs, kStartNs + 1000000000}));
  // An MSOP header's time is its first firing; packets are recorded at their last.
  std::int64_t msop = 0;
  for (const TimedPacket& p : c.packets) {
    if (is_difop(p)) continue;
    const auto h = robosense::read_msop_header(p.bytes);
    ASSERT_TRUE(h.has_value());
    const std::int64_t first_ns = kStartNs + msop * c.sensor.packet_ns();
    EXPECT_EQ(h->sensor_time.ns, first_ns / 1000 * 1000);
    EXPECT_EQ(p.pcap_time_ns, (first_ns + c.sensor.last_firing_ns()) / 1000 * 1000);
    EXPECT_FLOAT_EQ(h->temperature_c, 25.F);
    ++msop;
  }
  EXPECT_EQ(msop, 12 * c.packets_per_rotation);
}

TEST(SimSensorRates, FollowTheSensor) {
  // Whole packets per rotation at each sensor's own packet duration.
  EXPECT_EQ(make_sensor(SensorModel::Hdl32e).packets_per_rotation(10.0), 181);
  EXPECT_EQ(make_sensor(SensorModel::Hdl32e, ReturnMode::Dual).packets_per_rotation(10.0), 362);
  EXPECT_EQ(make_sensor(SensorModel::Vlp16).packets_per_rotation(10.0), 75);  // 12 x 110.592 us
  EXPECT_EQ(make_sensor(SensorModel::Vlp16, ReturnMode::Dual).packets_per_rotation(10.0), 151);
  EXPECT_EQ(make_sensor(SensorModel::Rs32).packets_per_rotation(10.0), 150);  // 12 x 55.52 us
  EXPECT_EQ(make_sensor(SensorModel::Rs32).packets_per_rotation(5.0), 300);
  EXPECT_EQ(make_sensor(SensorModel::Rs32, ReturnMode::Dual).packets_per_rotation(20.0), 150);
  EXPECT_TRUE(make_sensor(SensorModel::Vlp16).rate_supported(7.5));
  EXPECT_FALSE(make_sensor(SensorModel::Rs32).rate_supported(7.5));
  EXPECT_TRUE(make_sensor(SensorModel::Rs32).rate_supported(20.0));
  EXPECT_NEAR(Simulator::period_for(10.0, SensorModel::Rs32), 150 * 666.24e-6, 1e-12);
}

// The datagrams of a capture: (destination port, payload size, byte at `probe` or 0).
std::vector<std::tuple<std::uint16_t, std::size_t, std::uint8_t>> datagrams(const std::string& path,
                                                                            std::size_t probe) {
  std::vector<std::tuple<std::uint16_t, std::size_t, std::uint8_t>> out;
  auto reader = io::PcapReader::open(path);
  EXPECT_TRUE(reader.has_value()) << path;
  if (!reader) return out;
  while (auto d = reader->next()) {
    out.emplace_back(d->dst_port, d->payload.size(), d->payload.size() > probe ? d->payload[probe] : 0);
  }
  return out;
}

TEST(SimSensorCli, SensorAndReturnChooseThePackets) {
  ScratchDir dir("sensor_cli");
  const auto rs =
      run(FIELDGUARD_SIM, "--scene flat --rotations 2 --sensor rs32 --return dual --pcap " + dir.file("r.pcap"));
  ASSERT_EQ(rs.exit_code, 0) << rs.errors;
  EXPECT_NE(rs.errors.find("RS-LiDAR-32 dual return: 2 rotations at 10.0064 Hz (300 data packets each)"),
            std::string::npos)
      << rs.errors;
  const auto r = datagrams(dir.file("r.pcap"), 300);  // DIFOP byte 300: return mode
  ASSERT_EQ(r.size(), 1U + 2U * 300U);
  EXPECT_EQ(r.front(), std::make_tuple(std::uint16_t{7788}, std::size_t{1248}, std::uint8_t{0x00}));
  for (std::size_t i = 1; i < r.size(); ++i) EXPECT_EQ(std::get<0>(r[i]), 6699);
  EXPECT_NE(read_file(dir.file("r.truth.jsonl")).find(R"("sensor": "rs32")"), std::string::npos);

  // A session's lidar.pcap holds the chosen sensor's packets.
  ASSERT_EQ(
      run(FIELDGUARD_SIM, "--scene flat --rotations 2 --quiet --sensor vlp16 --session " + dir.file("s")).exit_code, 0);
  const auto v = datagrams(dir.file("s/lidar.pcap"), 1204);
  ASSERT_EQ(v.size(), 2U * 75U);
  for (const auto& [port, size, return_byte] : v) {
    EXPECT_EQ(port, 2368);
    EXPECT_EQ(size, 1206U);
    EXPECT_EQ(return_byte, 0x37);
  }
  EXPECT_NE(read_file(dir.file("s/lidar.truth.jsonl")).find(R"("sensor": "vlp16")"), std::string::npos);
  EXPECT_FALSE(read_file(dir.file("s/gnss.log")).empty());

  const auto help = run(FIELDGUARD_SIM, "--help");
  for (const char* word : {"--sensor", "--return", "hdl32e", "vlp16", "rs32", "DIFOP", "dual"}) {
    EXPECT_NE(help.output.find(word), std::string::npos) << word;
  }
}

TEST(SimSensorCli, BadSensorReturnOrRateIsRefused) {
  const std::string common = "--scene flat --pcap /nonexistent/x.pcap ";
  const std::pair<std::string, std::string> cases[] = {
      {"--sensor hdl64", "fieldguard-sim: --sensor: wants hdl32e, vlp16 or rs32, not 'hdl64'"},
      {"--return last", "fieldguard-sim: --return: wants strongest or dual, not 'last'"},
      {"--sensor rs32 --rate 15",
       "fieldguard-sim: --rate: wants 5, 10 or 20 Hz (the RS-LiDAR-32's 300, 600 or 1200 rpm), not '15'"},
      {"--rate 25 --sensor vlp16",
       "fieldguard-sim: --rate: wants a number of Hz from 5 to 20 (the VLP-16's range), "
       "not '25'"},
      {"--rate 10x", "fieldguard-sim: --rate: wants a number of Hz from 5 to 20 (the HDL-32E's range), not '10x'"},
  };
  for (const auto& [args, message] : cases) {
    const auto r = run(FIELDGUARD_SIM, common + args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(r.errors.rfind(message, 0), 0U) << args << "\n" << r.errors;
  }
}

}  // namespace
}  // namespace fieldguard::sim
