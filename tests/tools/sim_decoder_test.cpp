// The simulator's encoder against the project's decoder: a simulated capture, read back with the real pcap
// reader and Velodyne stream, must put the points on the simulated surfaces, with the simulated stamps.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "fieldguard/drivers/velodyne_stream.hpp"
#include "fieldguard/io/pcap_reader.hpp"
#include "sim/hdl32e.hpp"
#include "sim/pcap_writer.hpp"
#include "sim/scenes.hpp"
#include "sim/simulator.hpp"
#include "tools/tools_test_support.hpp"

namespace fieldguard::sim {
namespace {

constexpr int kRotations = 4;
constexpr std::int64_t kStartS = 1718449170;

// A decoded point in double precision.
struct Pt {
  double x;
  double y;
  double z;
};
Pt pt(const LidarPoint& p) { return {static_cast<double>(p.x), static_cast<double>(p.y), static_cast<double>(p.z)}; }

struct Capture {
  std::vector<FrameTruth> truth;
  std::vector<LidarFrame> frames;
  velodyne::StreamCounters counters;
  std::uint64_t datagrams = 0;
};

// Simulates the flat scene, writes it with the simulator's pcap writer and decodes it with the project's.
Capture simulate_and_decode(const std::string& scene_name, const tools_test::ScratchDir& dir) {
  SceneSetup setup;
  setup.rotations = kRotations;
  setup.period_s = Simulator::period_for(10.0);
  SimSettings settings;
  settings.start_time_ns = kStartS * 1000000000LL;
  Simulator sim(*build_scene(scene_name, setup), settings);
  PcapWriter w;
  const std::string path = dir.file(scene_name + ".pcap");
  EXPECT_TRUE(w.open(path));
  Capture c;
  std::vector<TimedPacket> packets;
  for (int k = 0; k < kRotations; ++k) {
    packets.clear();
    c.truth.push_back(sim.rotation(static_cast<std::uint64_t>(k), packets));
    for (const TimedPacket& p : packets) EXPECT_TRUE(w.write_udp(p.bytes, p.pcap_time_ns, 2368, 2368));
  }
  EXPECT_TRUE(w.close());

  auto reader = io::PcapReader::open(path);
  EXPECT_TRUE(reader.has_value());
  if (!reader) return c;
  velodyne::StreamOptions options;  // model detected from the stream, last-firing timestamps
  velodyne::Stream stream(options);
  while (auto d = reader->next()) {
    ++c.datagrams;
    EXPECT_EQ(d->dst_port, 2368);
    stream.push(d->payload, d->host_time, c.frames);
  }
  stream.finish(c.frames);
  c.counters = stream.counters();
  return c;
}

TEST(SimDecoder, FlatSceneDecodesOntoTheSimulatedSurfaces) {
  tools_test::ScratchDir dir("decoder");
  const Capture c = simulate_and_decode("flat", dir);
  ASSERT_EQ(c.frames.size(), static_cast<std::size_t>(kRotations));
  EXPECT_EQ(c.datagrams, static_cast<std::uint64_t>(kRotations * 181));
  EXPECT_EQ(c.counters.rejected(), 0U);
  for (std::size_t k = 0; k < c.frames.size(); ++k) {
    const LidarFrame& f = c.frames[k];
    const FrameTruth& t = c.truth[k];
    // Every rotation starts at the cut with a packet: same stamp and same number of points. Only the first is
    // partial (the assembler cannot know it began at the cut); the last, ending on the cut like the others, is
    // emitted whole with its last packet (the steady azimuth step tells it), as every rotation is.
    EXPECT_EQ(f.host_stamp.ns, t.stamp_ns) << "frame " << k;
    EXPECT_EQ(f.points.size(), t.returns) << "frame " << k;
    EXPECT_EQ(f.packets, 181U);
    EXPECT_EQ(f.partial, k == 0) << "frame " << k;

    const ObjectTruth* implement = nullptr;
    for (const ObjectTruth& o : t.objects) {
      if (o.id == "implement-1") implement = &o;
    }
    ASSERT_NE(implement, nullptr);
    std::size_t ground = 0;
    std::size_t on_implement = 0;
    for (const LidarPoint& lp : f.points) {
      const Pt p = pt(lp);
      const double r = std::hypot(p.x, p.y);
      if (p.x > 1.0 && r > 2.0 && r < 9.0 && std::abs(p.y) < 3.0) {  // clear of the bale (y 3.4..4.6)
        // Flat bare ground 0.95 m below the sensor; 1 cm range noise (4 sigma plus the 2 mm unit).
        ++ground;
        EXPECT_NEAR(p.z, -0.95, 0.045) << "ground point at " << p.x << ", " << p.y;
      }
      const Aabb& b = implement->box;
      if (p.x > b.min.x - 0.5 && p.x < b.max.x + 0.5 && std::abs(p.y) < 2.0 && p.z > -0.85) {
        ++on_implement;
        EXPECT_GE(p.x, b.min.x - 0.05);
        EXPECT_LE(p.x, b.max.x + 0.05);
        EXPECT_GE(p.y, b.min.y - 0.05);
        EXPECT_LE(p.y, b.max.y + 0.05);
        EXPECT_LE(p.z, b.max.z + 0.05);
      }
    }
    EXPECT_GT(ground, 1000U);
    // Every return on the implement (except its lowest few cm, where the ground is) decodes inside its box.
    EXPECT_GT(on_implement, implement->hits * 8 / 10);
    EXPECT_LE(on_implement, implement->hits);
  }
}

TEST(SimDecoder, TimestampsAndAzimuthsAgree) {
  tools_test::ScratchDir dir("decoder_time");
  const Capture c = simulate_and_decode("flat", dir);
  ASSERT_FALSE(c.frames.empty());
  // Sensor time (from the us-past-the-hour field, marking the last firing) of the first point of a rotation is
  // the rotation's start, 542.592 us before its first packet's time.
  for (std::size_t k = 0; k < c.frames.size(); ++k) {
    const LidarFrame& f = c.frames[k];
    const std::int64_t start_ns = kStartS * 1000000000LL + static_cast<std::int64_t>(k) * 181 * hdl32e::kPacketNs;
    EXPECT_NEAR(static_cast<double>(f.sensor_stamp.ns - start_ns), 0.0, 1500.0) << "frame " << k;
    // Azimuth grows through the rotation from 0 and the points' time offsets span one period.
    EXPECT_LT(f.points.front().azimuth_cdeg, 20);
    EXPECT_GT(f.points.back().azimuth_cdeg, 35970);
    EXPECT_NEAR(static_cast<double>(f.points.back().time_s - f.points.front().time_s), 0.1, 0.002);
  }
  // A point's azimuth is where the simulated ray pointed: a ground point at azimuth a lies along (cos a, -sin a).
  for (const LidarPoint& lp : c.frames[1].points) {
    const Pt p = pt(lp);
    const double a = lp.azimuth_cdeg * kPi / 18000.0;
    const double r = std::hypot(p.x, p.y);
    if (r < 2.0) continue;
    EXPECT_NEAR(p.x / r, std::cos(a), 2e-4);
    EXPECT_NEAR(p.y / r, -std::sin(a), 2e-4);
  }
}

TEST(SimDecoder, PedestrianPointsFallInItsBox) {
  tools_test::ScratchDir dir("decoder_ped");
  const Capture c = simulate_and_decode("pedestrian", dir);
  ASSERT_EQ(c.frames.size(), c.truth.size());
  for (std::size_t k = 0; k < c.frames.size(); ++k) {
    const ObjectTruth* ped = nullptr;
    for (const ObjectTruth& o : c.truth[k].objects) {
      if (o.cls == ObjectClass::Pedestrian) ped = &o;
    }
    ASSERT_NE(ped, nullptr);
    // Points above the furrows and clods (0.3 m over the ground) near the pedestrian: all inside its box.
    std::uint32_t inside = 0;
    const Aabb& b = ped->box;
    for (const LidarPoint& lp : c.frames[k].points) {
      const Pt p = pt(lp);
      if (p.x < b.min.x - 1.0 || p.x > b.max.x + 1.0 || p.y < b.min.y - 1.0 || p.y > b.max.y + 1.0) continue;
      if (p.z < b.min.z + 0.3) continue;
      EXPECT_TRUE(p.x >= b.min.x - 0.06 && p.x <= b.max.x + 0.06 && p.y >= b.min.y - 0.06 && p.y <= b.max.y + 0.06 &&
                  p.z <= b.max.z + 0.06)
          << "frame " << k << " point " << p.x << " " << p.y << " " << p.z;
      ++inside;
    }
    EXPECT_GT(inside, ped->hits / 2) << "frame " << k;
    EXPECT_LE(inside, ped->hits) << "frame " << k;
  }
}

}  // namespace
}  // namespace fieldguard::sim
