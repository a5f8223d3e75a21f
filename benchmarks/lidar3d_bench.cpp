// Packets to obstacles for each 3D LiDAR the daemon takes: the simulator's pedestrian scene as an HDL-32E, an
// RS-LiDAR-32 (MSOP and its DIFOP) and a VLP-16 at 10 Hz, each rotation's datagrams through lidar3d::Stream (what
// replay and the daemon decode with, model auto) and the rotation it emits through the fieldguard.yaml pipeline and
// its hold. The sensors give different point counts a rotation, so the figure to compare is the time per point
// (ns_per_point); the issue's bound: an RS-32 rotation within 10 % of the HDL-32E's per point.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "fieldguard/config/config.hpp"
#include "fieldguard/drivers/lidar3d_stream.hpp"
#include "fieldguard/engine/samples.hpp"
#include "fieldguard/perception/obstacle_hold.hpp"
#include "fieldguard/perception/pipeline.hpp"
#include "sim/scenes.hpp"
#include "sim/simulator.hpp"

namespace {

using namespace fieldguard;

const app::Config& config() {
  static const app::Config c = [] {
    auto r = app::load_config_file(std::string(FIELDGUARD_TEST_DATA) + "/../../config/fieldguard.yaml");
    if (!r.ok()) {
      std::fprintf(stderr, "fieldguard.yaml: %s\n", r.issues.front().to_string().c_str());
      std::exit(2);
    }
    return r.config;
  }();
  return c;
}

constexpr std::uint64_t kRotation = 30;  // the pedestrian crossing at 5 m, of a 720-rotation capture
constexpr int kSceneRotations = 720;

struct Capture {
  std::vector<sim::TimedPacket> packets;  // rotation kRotation's datagrams (and a DIFOP before them)
};

Capture simulate(sim::SensorModel model) {
  sim::SceneSetup setup;
  setup.seed = 1;
  setup.rotations = kSceneRotations;
  sim::SimSettings settings;
  settings.sensor = model;
  settings.start_time_ns = 1718449170LL * 1000000000LL;
  setup.period_s = sim::Simulator::period_for(settings.rate_hz, model, settings.returns);
  sim::Simulator simulator(std::move(*sim::build_scene("pedestrian", setup)), settings);
  Capture c;
  std::vector<sim::TimedPacket> packets;
  for (std::uint64_t r = 0; r <= kRotation; ++r) {
    packets.clear();
    (void)simulator.rotation(r, packets);
    if (r == 0) {  // the DIFOP of the first second: the RS-32's angles
      for (const auto& p : packets) {
        if (p.port == 7788) c.packets.push_back(p);
      }
    }
    if (r == kRotation) c.packets.insert(c.packets.end(), packets.begin(), packets.end());
  }
  return c;
}

const Capture& capture(int sensor) {
  static const std::vector<Capture> all = {simulate(sim::SensorModel::Hdl32e), simulate(sim::SensorModel::Rs32),
                                           simulate(sim::SensorModel::Vlp16)};
  return all.at(static_cast<std::size_t>(sensor));
}

constexpr const char* kNames[] = {"HDL-32E", "RS-32", "VLP-16"};

// The stream and the pipeline live across runs as in the daemon: each run pushes the rotation's datagrams, and the
// first data packet completes the rotation the run before pushed, which is then detected.
void BM_PacketsToObstaclesBySensor(benchmark::State& state) {
  const Capture& c = capture(static_cast<int>(state.range(0)));
  lidar3d::Stream stream(app::lidar3d_stream_options(config().lidar));
  perception::Pipeline pipe(config().perception);
  perception::ObstacleHold hold(config().perception.hold);
  std::vector<LidarFrame> done;
  std::size_t points = 0;
  std::size_t obstacles = 0;
  const auto run = [&] {
    for (auto& d : done) stream.recycle(std::move(d));
    done.clear();
    for (const auto& p : c.packets) {
      if (const auto ch = stream.channel_of(p.port)) {
        (void)stream.push(*ch, ByteSpan(p.bytes.data(), p.bytes.size()), Stamp{p.pcap_time_ns}, done);
      }
    }
    for (const auto& d : done) {
      auto r = pipe.process(d.points);
      (void)hold.apply(d.host_stamp.ns, r);
      points = d.points.size();
      obstacles = r.obstacles.size();
      benchmark::DoNotOptimize(r.obstacles.data());
    }
  };
  run();  // the first push only starts a rotation
  run();
  std::vector<double> ns;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    run();
    const auto t1 = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(t1 - t0).count();
    state.SetIterationTime(dt);
    ns.push_back(dt * 1e9);
  }
  if (points == 0) state.SkipWithError("no rotation came out");
  std::sort(ns.begin(), ns.end());
  const double median_ns = ns[ns.size() / 2];
  state.SetLabel(kNames[state.range(0)]);
  state.counters["points"] = static_cast<double>(points);
  state.counters["obstacles"] = static_cast<double>(obstacles);
  state.counters["median_us"] = median_ns * 1e-3;
  state.counters["ns_per_point"] = points > 0 ? median_ns / static_cast<double>(points) : 0.0;
}
BENCHMARK(BM_PacketsToObstaclesBySensor)
    ->DenseRange(0, 2)
    ->UseManualTime()
    ->Iterations(60)
    ->Unit(benchmark::kMicrosecond);

// Decoding alone: the same datagrams into lidar3d::Stream, the rotations it emits handed back.
void BM_DecodeBySensor(benchmark::State& state) {
  const Capture& c = capture(static_cast<int>(state.range(0)));
  lidar3d::Stream stream(app::lidar3d_stream_options(config().lidar));
  std::vector<LidarFrame> done;
  std::size_t points = 0;
  for (auto _ : state) {
    for (auto& d : done) {
      points = d.points.size();
      stream.recycle(std::move(d));
    }
    done.clear();
    for (const auto& p : c.packets) {
      if (const auto ch = stream.channel_of(p.port)) {
        (void)stream.push(*ch, ByteSpan(p.bytes.data(), p.bytes.size()), Stamp{p.pcap_time_ns}, done);
      }
    }
    benchmark::DoNotOptimize(done.data());
  }
  state.SetLabel(kNames[state.range(0)]);
  state.counters["points"] = static_cast<double>(points);
  state.counters["ns_per_point"] =
      benchmark::Counter(static_cast<double>(points) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_DecodeBySensor)->DenseRange(0, 2)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
