// What recording a frame costs, beside what detecting it costs, on one simulated HDL-32E rotation at 10 Hz of the
// pedestrian scene (about 55,000 points):
//   BM_DetectFrame         the detection pipeline on the frame (the work the view must never delay)
//   BM_EncodeFrame         FrameEncoder: the frame's Foxglove JSON messages (base64 point bytes), no file
//   BM_RecordFrame/zstd..  the same through McapRecorder into a file: encoding, chunking, compression, the write
//   BM_CopyIntoViewSlot    what the io thread does for the view: copy the frame into a slot (LiveView::frame)
//   BM_DrawPicture         the bird's-eye picture with cairo (replay --bev-dir, the status page), and its PNG
// The live daemon does all but the last on the view's own thread: these figures say how much of a core the view
// needs (a 10 Hz LiDAR gives it 100 ms a frame), and the copy what the io thread pays.

#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>
#include <vector>

#include "fieldguard/config/config.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/perception/pipeline.hpp"
#include "fieldguard/writers/bev.hpp"
#include "fieldguard/writers/frame_messages.hpp"
#include "fieldguard/writers/mcap_recorder.hpp"
#include "sim_frames.hpp"

namespace {

using namespace fieldguard;

struct Frame {
  app::Config cfg;
  LidarFrame frame;
  perception::FrameResult result;
  std::vector<perception::LabeledPoint> labelled;
  output::safety::Decision decision;
};

const Frame& frame() {
  static const Frame f = [] {
    Frame out;
    auto loaded = app::load_config_file(std::string(FIELDGUARD_SOURCE_DIR) + "/config/fieldguard.yaml");
    if (!loaded.ok()) throw std::runtime_error("config/fieldguard.yaml does not load");
    out.cfg = loaded.config;
    const bench::SimRotation r = bench::simulate_rotation("pedestrian", 10.0, 5, 120);
    out.frame.index = 5;
    out.frame.host_stamp.ns = 1718449170LL * 1000000000LL + 500000000LL;
    out.frame.points = r.points;
    perception::Pipeline p(out.cfg.perception);
    p.process(out.frame.points, out.result);
    const auto labelled = p.last_points();
    out.labelled.assign(labelled.begin(), labelled.end());
    out.decision.stop = !out.result.obstacles.empty();
    out.decision.zone = {0.4, 17.4, 2.0, false};
    return out;
  }();
  return f;
}

void BM_DetectFrame(benchmark::State& state) {
  const Frame& f = frame();
  perception::Pipeline p(f.cfg.perception);
  perception::FrameResult result;
  for (auto _ : state) {
    p.process(f.frame.points, result);
    benchmark::DoNotOptimize(result.obstacles.data());
  }
  state.counters["points"] = static_cast<double>(f.frame.points.size());
}
BENCHMARK(BM_DetectFrame)->Unit(benchmark::kMillisecond);

void BM_EncodeFrame(benchmark::State& state) {
  const Frame& f = frame();
  app::FrameEncoder encoder(f.cfg);
  std::size_t bytes = 0;
  for (auto _ : state) {
    bytes = 0;
    encoder.encode(f.frame, f.result, f.labelled, nullptr, &f.decision,
                   [&](app::Topic, std::int64_t, std::string_view json) { bytes += json.size(); });
    benchmark::DoNotOptimize(bytes);
  }
  state.counters["json_bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_EncodeFrame)->Unit(benchmark::kMillisecond);

void BM_RecordFrame(benchmark::State& state, app::McapCompression compression) {
  const Frame& f = frame();
  const std::string path = (std::filesystem::temp_directory_path() / "fieldguard_bench.mcap").string();
  app::McapRecorder recorder(f.cfg);
  app::McapRecording rec;
  rec.path = path;
  rec.options.compression = compression;
  rec.max_bytes = 200'000'000;  // a bounded series, as live: the benchmark never fills the disk
  rec.max_files = 1;
  if (!recorder.open(rec)) {
    state.SkipWithError(recorder.error().c_str());
    return;
  }
  for (auto _ : state) {
    if (!recorder.frame(f.frame, f.result, f.labelled, nullptr, &f.decision)) {
      state.SkipWithError(recorder.error().c_str());
      break;
    }
  }
  const auto before_close = recorder.stats();
  static_cast<void>(recorder.close());
  state.counters["MB_per_frame"] = static_cast<double>(recorder.stats().bytes) * 1e-6 /
                                   static_cast<double>(std::max<std::uint64_t>(1, before_close.frames));
  for (std::uint64_t i = 1; i <= recorder.stats().files; ++i)
    std::filesystem::remove(app::McapRecorder::numbered(path, i));
}
BENCHMARK_CAPTURE(BM_RecordFrame, zstd, app::McapCompression::Zstd)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RecordFrame, lz4, app::McapCompression::Lz4)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RecordFrame, none, app::McapCompression::None)->Unit(benchmark::kMillisecond);

// LiveView::frame()'s copy into a warm slot: the io thread's whole share of the view.
void BM_CopyIntoViewSlot(benchmark::State& state) {
  const Frame& f = frame();
  app::DetectedFrame d;
  d.frame = f.frame;
  d.result = f.result;
  d.labelled = f.labelled;
  LidarFrame slot_frame;
  std::vector<perception::Obstacle> slot_obstacles;
  std::vector<perception::LabeledPoint> slot_labelled;
  for (auto _ : state) {
    slot_frame = d.frame;
    slot_obstacles = d.result.obstacles;
    slot_labelled = d.labelled;
    benchmark::DoNotOptimize(slot_frame.points.data());
    benchmark::DoNotOptimize(slot_labelled.data());
  }
}
BENCHMARK(BM_CopyIntoViewSlot)->Unit(benchmark::kMicrosecond);

void BM_DrawPicture(benchmark::State& state) {
  const Frame& f = frame();
  const perception::Box3 zone{{0.4, -2.0, -10.0}, {17.4, 2.0, 10.0}};
  const app::BevCaption caption{f.frame.index, f.frame.host_stamp, false, &f.decision, 3};
  std::size_t bytes = 0;
  for (auto _ : state) {
    const app::Picture p = app::render_bev(f.labelled, f.result.obstacles, f.cfg.perception, zone, caption);
    if (state.range(0) != 0) bytes = p.png().size();
    benchmark::DoNotOptimize(p.width());
  }
  state.counters["png_bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_DrawPicture)->Arg(0)->Arg(1)->ArgName("png")->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
