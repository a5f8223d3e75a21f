// Sync: hand-off through the lock-free worker pool, and frame assembly per 5 Hz frame.
//
//   bench_sync --benchmark_repetitions=5 --benchmark_report_aggregates_only=true

#include <benchmark/benchmark.h>

#include <atomic>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "fieldguard/sync/frame_assembler.hpp"
#include "fieldguard/sync/ordered_pool.hpp"
#include "fieldguard/sync/synchronizer.hpp"

namespace {

using fieldguard::LidarFrame;
using fieldguard::LidarPoint;
using fieldguard::Stamp;
namespace sync = fieldguard::sync;

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kT0 = 1'718'449'170'000'000'000LL;

// Items through submit -> worker -> in-order poll, with back-pressure (the replay mode), in batches of 256 that
// are drained before the next. The work is trivial, so this is the cost of the hand-off itself: the lock-free
// queues, the free list, the wake-ups and the reorder map.
void BM_PoolHandoff(benchmark::State& state) {
  sync::PoolParams p;
  p.workers = static_cast<std::size_t>(state.range(0));
  p.queue_capacity = 64;
  sync::OrderedPool<std::uint64_t, std::uint64_t> pool(p, [](std::uint64_t& v) { return v * 3; });
  std::uint64_t sum = 0;
  const auto sink = [&](const auto& r) { sum += *r.output; };
  constexpr std::uint64_t kBatch = 256;
  std::uint64_t i = 0;
  for (auto _ : state) {
    for (std::uint64_t b = 0; b < kBatch; ++b) {
      std::uint64_t v = i++;
      while (!pool.try_submit(v)) pool.poll_wait(sink);
    }
    while (pool.outstanding() > 0) pool.poll_wait(sink);
  }
  pool.stop(sync::Drain::Yes);
  pool.poll(sink);
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(static_cast<std::int64_t>(i));
}
BENCHMARK(BM_PoolHandoff)->Arg(1)->Arg(2)->Arg(4)->UseRealTime();

// Frame-sized inputs (one 5 Hz HDL-32E rotation of points each) through the pool, 8 at a time: submission swaps
// each with a slot's earlier input, so the caller refills a used buffer and nothing is allocated per frame.
void BM_PoolHandoffFrame(benchmark::State& state) {
  sync::PoolParams p;
  p.workers = 2;
  p.queue_capacity = 8;
  sync::OrderedPool<sync::SyncedFrame, std::size_t> pool(p, [](sync::SyncedFrame& f) { return f.points.size(); });
  std::size_t sum = 0;
  const auto sink = [&](const auto& r) { sum += *r.output; };
  sync::SyncedFrame f;
  std::int64_t n = 0;
  for (auto _ : state) {
    for (int b = 0; b < 8; ++b, ++n) {
      f.points.resize(139'008);
      while (!pool.try_submit(f)) pool.poll_wait(sink);
    }
    while (pool.outstanding() > 0) pool.poll_wait(sink);
  }
  pool.stop(sync::Drain::Yes);
  pool.poll(sink);
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(n);
}
BENCHMARK(BM_PoolHandoffFrame)->UseRealTime();

// The daemon's hand-off from a worker back to the io thread, one frame at a time (the live case: a rotation
// every 100 ms, each decided alone): submit on the io thread, the worker finishes it, and the io thread
// delivers it. Time per frame from submit to delivery, the work itself being trivial.
//   BM_DecisionWake:      the worker wakes the io thread (PoolParams::on_result -> asio post), as `run` does.
//   BM_DecisionTimerPoll: the io thread polls on a timer of range(0) ms, as `run` did (5 ms) before.
void BM_DecisionWake(benchmark::State& state) {
  boost::asio::io_context io;
  std::atomic<bool> pending{false};
  std::function<void()> drain;
  sync::PoolParams p;
  p.workers = 1;
  p.on_result = [&] {
    if (pending.exchange(true)) return;
    boost::asio::post(io, [&] {
      pending.store(false);
      drain();
    });
  };
  sync::OrderedPool<std::uint64_t, std::uint64_t> pool(p, [](std::uint64_t& v) { return v * 3; });
  std::uint64_t delivered = 0;
  drain = [&] { pool.poll([&](const auto&) { ++delivered; }); };
  const auto work = boost::asio::make_work_guard(io);  // run_one() waits for the worker's post
  std::uint64_t i = 0;
  for (auto _ : state) {
    std::uint64_t v = i++;
    pool.submit(v);
    while (delivered < i) io.run_one();
  }
  pool.stop(sync::Drain::Yes);
  state.SetItemsProcessed(static_cast<std::int64_t>(i));
}
BENCHMARK(BM_DecisionWake)->UseRealTime()->Unit(benchmark::kMicrosecond);

void BM_DecisionTimerPoll(benchmark::State& state) {
  boost::asio::io_context io;
  sync::PoolParams p;
  p.workers = 1;
  sync::OrderedPool<std::uint64_t, std::uint64_t> pool(p, [](std::uint64_t& v) { return v * 3; });
  std::uint64_t delivered = 0;
  boost::asio::steady_timer timer(io);
  const auto period = std::chrono::milliseconds(state.range(0));
  std::function<void()> arm = [&] {
    timer.expires_after(period);
    timer.async_wait([&](const boost::system::error_code& ec) {
      if (ec) return;
      pool.poll([&](const auto&) { ++delivered; });
      arm();
    });
  };
  arm();
  std::uint64_t i = 0;
  for (auto _ : state) {
    std::uint64_t v = i++;
    pool.submit(v);
    while (delivered < i) io.run_one();
  }
  timer.cancel();
  pool.stop(sync::Drain::Yes);
  state.SetItemsProcessed(static_cast<std::int64_t>(i));
}
BENCHMARK(BM_DecisionTimerPoll)->Arg(5)->UseRealTime()->Unit(benchmark::kMicrosecond);

LidarFrame rotation(std::uint64_t index, std::int64_t t, std::int64_t period, std::size_t points) {
  LidarFrame f;
  f.index = index;
  f.sensor_stamp = Stamp{t};
  f.host_stamp = Stamp{t + 700'000};
  f.points.resize(points);
  for (std::size_t i = 0; i < points; ++i) {
    f.points[i].time_s =
        static_cast<float>(static_cast<double>(period) * 1e-9 * static_cast<double>(i) / static_cast<double>(points));
  }
  return f;
}

// One 5 Hz frame through the Synchronizer: clock mapping of every sample, 1 rotation (139,008 points, a full
// HDL-32E turn), 8 scans, 2 GGA, 20 AHRS samples, then the frame built (points copied once).
void BM_FrameAssembly5Hz(benchmark::State& state) {
  const auto points = static_cast<std::size_t>(state.range(0));
  const std::int64_t period = 200 * kMs;
  sync::Synchronizer s;
  std::vector<sync::SyncedFrame> out;
  LidarFrame proto = rotation(0, kT0, period, points);
  std::int64_t t = kT0;
  std::uint64_t k = 0;
  std::size_t frames = 0;
  for (auto _ : state) {
    state.PauseTiming();
    LidarFrame r = proto;  // the decoder's output; its copy is not sync's cost
    r.index = k;
    r.sensor_stamp = Stamp{t};
    r.host_stamp = Stamp{t + 700'000};
    state.ResumeTiming();
    for (int a = 0; a < 20; ++a) {
      fieldguard::xsens::MtData2 m;
      m.sample_time_fine = static_cast<std::uint32_t>((t - kT0 + a * 10 * kMs) / 100'000);
      s.push_ahrs(std::move(m), Stamp{t + a * 10 * kMs + 500'000});
    }
    for (int c = 0; c < 8; ++c) {
      fieldguard::scip::Scan sc;
      sc.timestamp_ms = static_cast<std::uint32_t>(((t - kT0) / kMs + c * 25) & 0xFFFFFF);
      s.push_scan(std::move(sc), Stamp{t + c * 25 * kMs + 2 * kMs});
    }
    for (int g = 0; g < 2; ++g) {
      fieldguard::nmea::Gga gga;
      gga.utc_seconds_of_day = static_cast<double>((t + g * 100 * kMs) % 86'400'000'000'000LL) * 1e-9;
      s.push_gnss(fieldguard::nmea::Sentence{gga}, Stamp{t + g * 100 * kMs + 30 * kMs});
    }
    s.push_lidar(std::move(r));
    out.clear();
    s.poll(Stamp{t + period}, out);
    frames += out.size();
    t += period;
    ++k;
  }
  benchmark::DoNotOptimize(frames);
  state.SetItemsProcessed(state.iterations());
  state.counters["frames_out"] = static_cast<double>(frames);
}
BENCHMARK(BM_FrameAssembly5Hz)->Arg(139'008)->Arg(0)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
