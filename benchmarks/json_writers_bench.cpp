// The hand-written JSON writers whose output must stay byte-identical, beside the same line built with
// nlohmann::ordered_json (issue 28: one JSON library wherever it costs no speed on a hot path):
//   obstacles  obstacles_json_line(), replay's --obstacles-out, once per frame on replay's output thread: a
//              fused frame with pose (levelling full, plane coordinates per obstacle) and 20 obstacles, 5.4 kB
//              (the simulator's scenes replay with up to 14 obstacles a frame, the orchard up to 55); and the
//              same frame with no obstacle
//   truth      the simulator's truth_json_line(), once per rotation: 6 objects and 20 terrain features
// The nlohmann versions write the same keys in the same order, the values rounded to the same decimals and
// -0 written as 0. Before the timings the program prints whether the two lines hold the same JSON values and
// where their text differs.
//
// Figures (RelWithDebInfo, g++ 12, nlohmann 3.11.2, the shared 2-core machine with other builds running,
// load 1.4-4; CPU time, medians of 5 repetitions, three runs: --benchmark_repetitions=5 --benchmark_min_time=0.5):
//   obstacles, 20          hand-written 55.5-60.0 us   nlohmann 81.1-86.4 us (tree 55.8-60.8, dump 21.6-23.0)
//   obstacles, none        hand-written  1.63-1.70 us  nlohmann  2.99-3.09 us
//   truth, 26 objects      hand-written 25.6-26.7 us   nlohmann 49.0-50.6 us
// Same values: yes for both (each line parsed back with nlohmann: equal). Same text: no. nlohmann writes the
// shortest form that reads back the same double, so 51 of the obstacles line's 689 values change ("-1.150"
// -1.15, "0.000" 0.0, "0.0000" 0.0, the stamp "1718449170.100000" 1718449170.1) and 44 of the truth line's 486;
// the truth line also loses the space after ',' and ':' (nlohmann's one-line dump has no separator option).
// nlohmann has no fixed-decimals output, so neither file can stay byte-identical on it, and it is 1.4-1.5 times
// (obstacles) and 1.9 times (truth) slower: both writers stay hand-written. docs/measurements.md, "JSON writers".

#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/perception/obstacle.hpp"
#include "fieldguard/sync/synced_frame.hpp"
#include "fieldguard/writers/obstacles_jsonl.hpp"
#include "sim/truth_writer.hpp"

namespace {

using namespace fieldguard;
using Json = nlohmann::ordered_json;

// ---- the inputs ------------------------------------------------------------------------------------------

struct ObstacleFrame {
  LidarFrame frame;
  perception::FrameResult result;
  app::FusionInfo fusion;
  Mounting lidar;
};

ObstacleFrame obstacle_frame(std::size_t n) {
  ObstacleFrame f;
  f.frame.index = 1234;
  f.frame.host_stamp.ns = 1718449170100000000LL;  // a whole tenth of a second: "1718449170.100000"
  f.frame.partial = false;
  f.frame.points.resize(95720);
  f.fusion.levelling = geo::Levelling::Full;
  f.fusion.rotations = 2;
  f.fusion.scan_points = 358;
  f.fusion.missing = sync::bit(sync::SensorKind::Gnss);
  geo::PlaneCoord ref;
  ref.easting_m = 470204.952;
  ref.northing_m = 5329622.681;
  ref.up_m = 520.201;
  ref.zone = 4;
  f.fusion.reference = ref;
  f.fusion.attitude = geo::EulerDeg{1.858, -3.096, 29.706};
  f.lidar.x_m = 1.2;
  f.lidar.z_m = 2.1;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> x(-5.F, 60.F);
  std::uniform_real_distribution<float> y(-15.F, 15.F);
  std::uniform_real_distribution<float> size(0.01F, 3.F);
  for (std::size_t i = 0; i < n; ++i) {
    perception::Obstacle o;
    o.min = {x(rng), y(rng), -1.15F};
    o.max = {o.min[0] + size(rng), o.min[1] + size(rng), -1.15F + size(rng)};
    o.obb_center = {0.5F * (o.min[0] + o.max[0]), 0.5F * (o.min[1] + o.max[1])};
    o.obb_length_m = o.max[0] - o.min[0];
    o.obb_width_m = i % 5 == 0 ? 0.F : o.max[1] - o.min[1];  // "0.000": a one-line cluster
    o.obb_yaw_rad = 0.0214F * static_cast<float>(i);
    o.points = 12 + 7 * static_cast<std::uint32_t>(i);
    o.distance_m = std::hypot(o.min[0], o.min[1]);
    o.bearing_deg = std::atan2(o.obb_center[1], o.obb_center[0]) * 57.29578F;
    o.height_above_ground_m = o.max[2] + 1.15F;
    o.size_class = i % 3 == 0 ? perception::SizeClass::Large : perception::SizeClass::Small;
    if (i % 4 == 0) o.sources = perception::kSeenBy3d | perception::kSeenBy2d;
    o.held = i == 7;
    f.result.obstacles.push_back(o);
  }
  return f;
}

sim::FrameTruth truth_frame() {
  sim::FrameTruth t;
  t.frame = 1234;
  t.stamp_ns = 1718449170100628000LL;
  t.period_s = 0.100086;
  t.roll_deg = 0.512;
  t.pitch_deg = -1.25;
  t.sensor_world = {12.5, -0.75, 0.95};
  t.returns = 53355;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> x(-5.0, 60.0);
  std::uniform_real_distribution<double> y(-15.0, 15.0);
  std::uniform_real_distribution<double> size(0.05, 3.0);
  const auto object = [&](std::string id, sim::ObjectClass cls) {
    sim::ObjectTruth o;
    o.id = std::move(id);
    o.cls = cls;
    o.box.min = {x(rng), y(rng), -0.95};
    o.box.max = {o.box.min.x + size(rng), o.box.min.y + size(rng), -0.95 + size(rng)};
    o.hits = 339;
    o.raised_hits = 298;
    o.distance_m = std::hypot(o.box.min.x, o.box.min.y);
    return o;
  };
  for (int i = 0; i < 6; ++i)
    t.objects.push_back(object("implement-" + std::to_string(i + 1), sim::ObjectClass::Implement));
  for (int i = 0; i < 20; ++i) t.terrain.push_back(object("clod-" + std::to_string(i + 1), sim::ObjectClass::Clod));
  return t;
}

// ---- the same lines with nlohmann ------------------------------------------------------------------------

// v rounded to `decimals` decimals, -0 as 0: the value "%.*f" prints (nlohmann then writes it shortest).
double fixed(double v, int decimals) {
  static constexpr std::array<double, 7> kScale{1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6};
  const double s = kScale[static_cast<std::size_t>(decimals)];
  return std::nearbyint(v * s) / s + 0.0;
}

Json vec(const float* v, int n) {
  Json a = Json::array();
  for (int i = 0; i < n; ++i) a.push_back(fixed(static_cast<double>(v[i]), 3));
  return a;
}

Json obstacles_json_nlohmann(const LidarFrame& frame, const perception::FrameResult& result,
                             const app::FusionInfo* fusion, const Mounting* lidar) {
  Json j = {{"version", app::kObstaclesJsonVersion},
            {"frame", frame.index},
            {"stamp", fixed(frame.host_stamp.seconds(), 6)},
            {"partial", frame.partial},
            {"points_in", frame.points.size()}};
  if (fusion != nullptr) {
    const app::FusionInfo& f = *fusion;
    Json missing = Json::array();
    for (const sync::SensorKind k : sync::kAllSensors) {
      if ((f.missing & sync::bit(k)) != 0) missing.push_back(sync::to_string(k));
    }
    Json fj = {{"levelling", fieldguard::app::levelling_name(f.levelling)},
               {"rotations", f.rotations},
               {"scan_points", f.scan_points},
               {"missing", std::move(missing)},
               {"timed_out", f.timed_out},
               {"dropped_points", f.stats.lidar.dropped() + f.stats.scan.dropped()}};
    if (f.attitude) {
      Json pose = Json::object();
      if (f.reference) {
        pose["easting"] = fixed(f.reference->easting_m, 3);
        pose["northing"] = fixed(f.reference->northing_m, 3);
        pose["up"] = fixed(f.reference->up_m, 3);
        pose["zone"] = f.reference->zone;
      }
      pose["roll"] = fixed(f.attitude->roll_deg, 3);
      pose["pitch"] = fixed(f.attitude->pitch_deg, 3);
      pose["yaw"] = fixed(f.attitude->yaw_deg, 3);
      fj["pose"] = std::move(pose);
    }
    j["fusion"] = std::move(fj);
  }
  const std::optional<perception::FramePose> pose =
      fusion != nullptr && lidar != nullptr ? app::detection_pose(*fusion, *lidar) : std::nullopt;
  Json obstacles = Json::array();
  for (const auto& o : result.obstacles) {
    Json oj = {{"min", vec(o.min.data(), 3)},
               {"max", vec(o.max.data(), 3)},
               {"points", o.points},
               {"obb",
                {{"center", vec(o.obb_center.data(), 2)},
                 {"length", fixed(static_cast<double>(o.obb_length_m), 3)},
                 {"width", fixed(static_cast<double>(o.obb_width_m), 3)},
                 {"yaw_deg", fixed(static_cast<double>(o.obb_yaw_rad) * (180.0 / std::numbers::pi), 2)}}},
               {"distance", fixed(static_cast<double>(o.distance_m), 3)},
               {"bearing", fixed(static_cast<double>(o.bearing_deg), 2)},
               {"height", fixed(static_cast<double>(o.height_above_ground_m), 3)},
               {"class", perception::to_string(o.size_class)}};
    if ((o.sources & perception::kSeenBy2d) != 0)
      oj["seen_by"] = (o.sources & perception::kSeenBy3d) != 0 ? "3d+2d" : "2d";
    if (o.held) oj["held"] = true;
    if (pose) {
      const double x = 0.5 * (static_cast<double>(o.min[0]) + static_cast<double>(o.max[0]));
      const double y = 0.5 * (static_cast<double>(o.min[1]) + static_cast<double>(o.max[1]));
      const double c = std::cos(pose->yaw_rad);
      const double sn = std::sin(pose->yaw_rad);
      oj["plane"] = Json::array({fixed(pose->x_m + c * x - sn * y, 3), fixed(pose->y_m + sn * x + c * y, 3),
                                 fixed(pose->z_m + static_cast<double>(o.min[2]), 3)});
    }
    obstacles.push_back(std::move(oj));
  }
  j["obstacles"] = std::move(obstacles);
  return j;
}

Json truth_objects(const std::vector<sim::ObjectTruth>& list) {
  const auto v3 = [](const sim::Vec3& v) { return Json::array({fixed(v.x, 3), fixed(v.y, 3), fixed(v.z, 3)}); };
  Json a = Json::array();
  for (const auto& o : list) {
    a.push_back({{"id", o.id},
                 {"class", sim::to_string(o.cls)},
                 {"min", v3(o.box.min)},
                 {"max", v3(o.box.max)},
                 {"hits", o.hits},
                 {"raised_hits", o.raised_hits},
                 {"distance_m", fixed(static_cast<double>(o.distance_m), 3)}});
  }
  return a;
}

Json truth_json_nlohmann(const sim::FrameTruth& t) {
  const long long us = t.stamp_ns / 1000;
  return {{"frame", t.frame},
          {"stamp", static_cast<double>(us) / 1e6},  // exact microseconds: the double nearest to them
          {"period_s", fixed(t.period_s, 6)},
          {"sensor", std::string(t.sensor)},
          {"roll_deg", fixed(t.roll_deg, 3)},
          {"pitch_deg", fixed(t.pitch_deg, 3)},
          {"sensor_world",
           Json::array({fixed(t.sensor_world.x, 3), fixed(t.sensor_world.y, 3), fixed(t.sensor_world.z, 3)})},
          {"returns", t.returns},
          {"objects", truth_objects(t.objects)},
          {"terrain", truth_objects(t.terrain)}};
}

// ---- agreement -------------------------------------------------------------------------------------------

// The scalar tokens of a JSON line (numbers, strings, literals), in order.
std::vector<std::string> tokens(std::string_view s) {
  std::vector<std::string> out;
  std::string cur;
  for (const char c : s) {
    if (c == ',' || c == ':' || c == '[' || c == ']' || c == '{' || c == '}' || c == ' ') {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  return out;
}

void report(const char* what, const std::string& hand, const std::string& lib) {
  const bool same_values = nlohmann::json::parse(hand) == nlohmann::json::parse(lib);
  const auto a = tokens(hand);
  const auto b = tokens(lib);
  std::size_t differ = 0;
  std::string examples;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    if (a[i] == b[i]) continue;
    if (++differ <= 6) examples += " " + a[i] + "->" + b[i];
  }
  std::fprintf(stderr, "%s: hand-written %zu bytes, nlohmann %zu bytes; same JSON values: %s; same text: %s\n", what,
               hand.size(), lib.size(), same_values ? "yes" : "NO", hand == lib ? "yes" : "no");
  std::fprintf(stderr, "  %zu of %zu values written differently, e.g.%s\n", differ, a.size(), examples.c_str());
}

// ---- the timings -----------------------------------------------------------------------------------------

void BM_ObstaclesHandWritten(benchmark::State& state) {
  const auto f = obstacle_frame(static_cast<std::size_t>(state.range(0)));
  std::size_t bytes = 0;
  for (auto _ : state) {
    std::string line = app::obstacles_json_line(f.frame, f.result, &f.fusion, &f.lidar);
    bytes = line.size();
    benchmark::DoNotOptimize(line);
  }
  state.counters["bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_ObstaclesHandWritten)->Arg(0)->Arg(20)->Unit(benchmark::kMicrosecond);

void BM_ObstaclesNlohmann(benchmark::State& state) {
  const auto f = obstacle_frame(static_cast<std::size_t>(state.range(0)));
  std::size_t bytes = 0;
  for (auto _ : state) {
    std::string line = obstacles_json_nlohmann(f.frame, f.result, &f.fusion, &f.lidar).dump();
    bytes = line.size();
    benchmark::DoNotOptimize(line);
  }
  state.counters["bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_ObstaclesNlohmann)->Arg(0)->Arg(20)->Unit(benchmark::kMicrosecond);

// The two halves of the nlohmann line: building the tree, and dumping it.
void BM_ObstaclesNlohmannBuild(benchmark::State& state) {
  const auto f = obstacle_frame(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    Json j = obstacles_json_nlohmann(f.frame, f.result, &f.fusion, &f.lidar);
    benchmark::DoNotOptimize(j);
  }
}
BENCHMARK(BM_ObstaclesNlohmannBuild)->Arg(20)->Unit(benchmark::kMicrosecond);

void BM_ObstaclesNlohmannDump(benchmark::State& state) {
  const auto f = obstacle_frame(static_cast<std::size_t>(state.range(0)));
  const Json j = obstacles_json_nlohmann(f.frame, f.result, &f.fusion, &f.lidar);
  for (auto _ : state) {
    std::string line = j.dump();
    benchmark::DoNotOptimize(line);
  }
}
BENCHMARK(BM_ObstaclesNlohmannDump)->Arg(20)->Unit(benchmark::kMicrosecond);

void BM_TruthHandWritten(benchmark::State& state) {
  const auto t = truth_frame();
  for (auto _ : state) {
    std::string line = sim::truth_json_line(t);
    benchmark::DoNotOptimize(line);
  }
}
BENCHMARK(BM_TruthHandWritten)->Unit(benchmark::kMicrosecond);

void BM_TruthNlohmann(benchmark::State& state) {
  const auto t = truth_frame();
  for (auto _ : state) {
    std::string line = truth_json_nlohmann(t).dump();
    benchmark::DoNotOptimize(line);
  }
}
BENCHMARK(BM_TruthNlohmann)->Unit(benchmark::kMicrosecond);

}  // namespace

int main(int argc, char** argv) {
  {
    const auto f = obstacle_frame(20);
    report("obstacles", app::obstacles_json_line(f.frame, f.result, &f.fusion, &f.lidar),
           obstacles_json_nlohmann(f.frame, f.result, &f.fusion, &f.lidar).dump());
    const auto t = truth_frame();
    report("truth", sim::truth_json_line(t), truth_json_nlohmann(t).dump());
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
