// Encoding one pipeline frame's CAN messages: the summary, up to 8 obstacle messages (nearest first out of
// N), the stop request and the heartbeat; and formatting them as candump log lines.

#include <benchmark/benchmark.h>

#include <random>
#include <string>
#include <vector>

#include "fieldguard/output/can_encoder.hpp"
#include "fieldguard/output/can_sink.hpp"

namespace {

using namespace fieldguard;

std::vector<perception::Obstacle> obstacles(std::size_t n) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> x(1.F, 50.F);
  std::uniform_real_distribution<float> y(-10.F, 10.F);
  std::vector<perception::Obstacle> v(n);
  for (auto& o : v) {
    o.min = {x(rng), y(rng), -1.F};
    o.max = {o.min[0] + 0.6F, o.min[1] + 0.6F, 0.8F};
    o.distance_m = o.min[0];
    o.bearing_deg = 10.F;
    o.height_above_ground_m = 1.7F;
    o.points = 60;
  }
  return v;
}

void BM_EncodeFrame(benchmark::State& state) {
  const auto obs = obstacles(static_cast<std::size_t>(state.range(0)));
  output::CanEncoder enc(output::CanParams{});
  std::vector<output::CanFrame> out;
  out.reserve(32);
  std::uint32_t frame = 0;
  for (auto _ : state) {
    out.clear();
    enc.encode_frame(output::FrameReport{frame++, output::FrameStatus::Ok, obs}, out);
    out.push_back(enc.encode_stop(output::StopRequest{output::StopCommand::Stop, {true}}));
    out.push_back(enc.encode_heartbeat(output::Heartbeat{}));
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.counters["frames_out"] = static_cast<double>(out.size());
}
BENCHMARK(BM_EncodeFrame)->Arg(0)->Arg(3)->Arg(20)->Arg(200);

void BM_CandumpLines(benchmark::State& state) {
  const auto obs = obstacles(20);
  output::CanEncoder enc(output::CanParams{});
  std::vector<output::CanFrame> frames;
  enc.encode_frame(output::FrameReport{1, output::FrameStatus::Ok, obs}, frames);
  std::size_t bytes = 0;
  for (auto _ : state) {
    for (const auto& f : frames) {
      const std::string line = output::candump_line(f, Stamp{1'718'449'170'200'000'000}, "can0");
      bytes += line.size();
      benchmark::DoNotOptimize(line.data());
    }
  }
  state.counters["lines"] = static_cast<double>(frames.size());
  benchmark::DoNotOptimize(bytes);
}
BENCHMARK(BM_CandumpLines);

}  // namespace
BENCHMARK_MAIN();
