// The stop decision per frame: a frame of obstacles through safety::Monitor::update, with every sensor fresh.
//   bench_safety_monitor [--benchmark_filter=...]
// Obstacles are scattered over the perception ROI (x -10..50 m, y -10..10 m), a fixed seed, so that some
// fall in the zone and most do not; the "in_zone" variant puts every one in it (the zone check cannot stop
// early, and the nearest is searched over all of them). Ticks (no frame) are the heartbeat-rate calls.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

#include "fieldguard/output/safety_monitor.hpp"

namespace {

using namespace fieldguard;
using namespace fieldguard::output::safety;

std::vector<perception::Obstacle> scatter(int n, bool in_zone) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> x(in_zone ? 1.F : -10.F, in_zone ? 15.F : 50.F);
  std::uniform_real_distribution<float> y(in_zone ? -1.5F : -10.F, in_zone ? 1.5F : 10.F);
  std::uniform_real_distribution<float> size(0.3F, 2.5F);
  std::uniform_real_distribution<float> yaw(-1.5F, 1.5F);
  std::vector<perception::Obstacle> v(static_cast<std::size_t>(n));
  for (auto& o : v) {
    const float cx = x(rng);
    const float cy = y(rng);
    const float l = size(rng);
    const float w = 0.5F * size(rng);
    o.obb_center = {cx, cy};
    o.obb_length_m = l;
    o.obb_width_m = w;
    o.obb_yaw_rad = yaw(rng);
    o.min = {cx - 0.5F * (l + w), cy - 0.5F * (l + w), -0.5F};
    o.max = {cx + 0.5F * (l + w), cy + 0.5F * (l + w), 1.5F};
    o.distance_m = cx;
  }
  return v;
}

Input fresh(std::int64_t now_ns) {
  Input in;
  in.now = Stamp{now_ns};
  for (auto& s : in.sensors) s.last_data = Stamp{now_ns - 5'000'000};
  return in;
}

void run_frames(benchmark::State& state, bool in_zone) {
  Params p;
  p.sensor(Sensor::Ahrs).required = true;
  p.sensor(Sensor::Gnss).required = true;
  Monitor m(p);
  const auto obstacles = scatter(static_cast<int>(state.range(0)), in_zone);
  std::int64_t now = 1'000'000'000;
  std::int64_t stops = 0;
  std::int64_t events = 0;
  for (auto _ : state) {
    now += 200'000'000;
    FrameInput f{obstacles, Stamp{now - 60'000'000}, 4.0};
    Input in = fresh(now);
    in.frame = &f;
    const Decision d = m.update(in);
    stops += d.stop ? 1 : 0;
    events += d.event ? 1 : 0;
    benchmark::DoNotOptimize(d);
  }
  state.counters["obstacles"] = static_cast<double>(obstacles.size());
  state.counters["stops"] = static_cast<double>(stops);
  state.counters["events"] = static_cast<double>(events);
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_MonitorFrame(benchmark::State& state) { run_frames(state, false); }
void BM_MonitorFrameAllInZone(benchmark::State& state) { run_frames(state, true); }

void BM_MonitorTick(benchmark::State& state) {
  Monitor m{Params{}};
  std::int64_t now = 1'000'000'000;
  for (auto _ : state) {
    now += 10'000'000;
    const Decision d = m.update(fresh(now));
    benchmark::DoNotOptimize(d);
  }
}

}  // namespace

BENCHMARK(BM_MonitorFrame)->Arg(0)->Arg(50)->Arg(500);
BENCHMARK(BM_MonitorFrameAllInZone)->Arg(50);
BENCHMARK(BM_MonitorTick);
BENCHMARK_MAIN();
