// Compensation costs (geo/): projection of one GNSS fix, the per-fix chain (projection, attitude, lever arm,
// track), per-point deskew of a full 5 Hz HDL-32E rotation (139,008 points, 32 lasers x 4,344 firings in
// 0.2 s) into the level frame and into plane coordinates, and the lifting of a 1,081-step 2D scan.
//   bench_geo [--benchmark_filter=...] [--benchmark_repetitions=5]
// Deskew runs with exact per-point poses (pose_step_us 0) and with the default 100 us pose steps.
// BM_CompensateFrame is the whole per-frame job (FrameCompensator::compensate): a 0.2 s frame of 69,504
// points (32 lasers x 2,172 firings), 20 AHRS samples, 2 GGA fixes bracketing the window and a 1,081-step
// scan, without and with plane output.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/geo/attitude.hpp"
#include "fieldguard/geo/deskew.hpp"
#include "fieldguard/geo/frame_compensator.hpp"
#include "fieldguard/geo/pose_track.hpp"
#include "fieldguard/geo/projection.hpp"
#include "fieldguard/geo/scan_lift.hpp"

namespace {

using namespace fieldguard;
using namespace fieldguard::geo;

constexpr std::int64_t kT0 = 1'718'449'170'000'000'000;
Stamp at_s(double s) { return Stamp{kT0 + std::llround(s * 1e9)}; }

// One 0.2 s rotation of a 32-beam sensor with `firings` firings: 4344 (139,008 points, 5 Hz HDL-32E
// density) or 2172 (69,504).
std::vector<LidarPoint> synthetic_rotation(int firings) {
  std::vector<LidarPoint> pts;
  pts.reserve(static_cast<std::size_t>(firings) * 32);
  for (int f = 0; f < firings; ++f) {
    const double az = 2.0 * std::numbers::pi * f / firings;
    for (int l = 0; l < 32; ++l) {
      const double el = (-30.67 + 1.33 * l) * std::numbers::pi / 180.0;
      const double r = 5.0 + 40.0 * std::fabs(std::sin(3.0 * az + l));
      LidarPoint p;
      p.x = static_cast<float>(r * std::cos(el) * std::cos(az));
      p.y = static_cast<float>(r * std::cos(el) * std::sin(az));
      p.z = static_cast<float>(r * std::sin(el));
      p.time_s = static_cast<float>(0.2 * (f + l / 32.0) / firings);
      p.ring = static_cast<std::uint16_t>(l);
      pts.push_back(p);
    }
  }
  return pts;
}

std::vector<LidarPoint> rotation_139k() { return synthetic_rotation(4344); }

PoseTrack rocking_track() {
  PoseTrack track;
  for (int i = 0; i <= 100; ++i) {
    const double t = 0.01 * i - 0.25;
    (void)track.add_attitude(at_s(t), quaternion_of({6.0 * std::sin(5.0 * t), 5.0 * std::sin(3.0 * t), 20.0}));
  }
  for (int i = 0; i <= 10; ++i) {
    const double t = 0.1 * i - 0.25;
    (void)track.add_position(at_s(t), Eigen::Vector3d(448688.0 + 3.0 * t, 4418598.0, 45.0));
  }
  return track;
}

void BM_ProjectFix(benchmark::State& state) {
  const GaussKrueger gk(ProjectionParams{});
  double lat = 39.9;
  for (auto _ : state) {
    lat += 1e-9;
    auto r = gk.forward({lat, 116.4, 45.0});
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ProjectFix);

void BM_FixChain(benchmark::State& state) {
  // What the app does per GNSS fix: project, attitude at the fix time, lever arm, into the track.
  const GaussKrueger gk(ProjectionParams{});
  const AttitudeModel model(AhrsParams{});
  PoseTrack track;
  for (int i = 0; i < 4000; ++i)
    (void)track.add_attitude(at_s(0.01 * i), model.vehicle_in_plane({2.0, 1.0, 30.0}, -0.38));
  double t = 0.0;
  for (auto _ : state) {
    t += 1e-6;
    const auto fix = gk.forward({39.9 + t * 1e-6, 116.4, 45.0});
    const auto att = track.attitude_at(at_s(t));
    const Eigen::Vector3d ref = reference_from_antenna(fix->enu(), att->q, {0.4, 0.0, 2.8});
    benchmark::DoNotOptimize(track.add_position(at_s(t), ref));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FixChain);

void BM_DeskewLevel(benchmark::State& state) {
  const std::vector<LidarPoint> pts = rotation_139k();
  const PoseTrack track = rocking_track();
  DeskewParams dp;
  dp.lidar.x_m = 1.8;
  dp.lidar.z_m = 2.2;
  dp.pose_step_s = static_cast<double>(state.range(0)) * 1e-6;
  const Deskewer d(dp);
  std::vector<SourcedPoint> out;
  out.reserve(pts.size());
  for (auto _ : state) {
    out.clear();
    auto s = d.to_level(pts, at_s(0.0), track, at_s(0.1), out);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(pts.size()));
  state.counters["points"] = static_cast<double>(out.size());
}
BENCHMARK(BM_DeskewLevel)->ArgName("pose_step_us")->Arg(0)->Arg(100)->Unit(benchmark::kMillisecond);

void BM_DeskewPlane(benchmark::State& state) {
  const std::vector<LidarPoint> pts = rotation_139k();
  const PoseTrack track = rocking_track();
  DeskewParams dp;
  dp.pose_step_s = static_cast<double>(state.range(0)) * 1e-6;
  const Deskewer d(dp);
  std::vector<PlanePoint> out;
  out.reserve(pts.size());
  for (auto _ : state) {
    out.clear();
    auto s = d.to_plane(pts, at_s(0.0), track, out);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(pts.size()));
}
BENCHMARK(BM_DeskewPlane)->ArgName("pose_step_us")->Arg(0)->Arg(100)->Unit(benchmark::kMillisecond);

void BM_LiftScan(benchmark::State& state) {
  scip::Scan scan;
  scan.first_step = 0;
  scan.last_step = 1080;
  for (int i = 0; i <= 1080; ++i) scan.ranges_mm.push_back(static_cast<std::uint32_t>(1000 + 7 * i));
  ScanLiftParams p;
  p.scanner.x_m = 2.0;
  p.scanner.pitch_deg = 10.0;
  p.lidar.x_m = 1.8;
  p.lidar.z_m = 2.2;
  const ScanLifter lifter(p);
  std::vector<SourcedPoint> out;
  out.reserve(1081);
  for (auto _ : state) {
    out.clear();
    auto s = lifter.lift(scan, scip::Geometry{}, 0.0F, out);
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(state.iterations() * 1081);
}
BENCHMARK(BM_LiftScan)->Unit(benchmark::kMicrosecond);

sync::SyncedFrame frame_70k() {
  sync::SyncedFrame f;
  f.window_start = at_s(0.0);
  f.window_end = at_s(0.2);
  f.rotations = 1;
  f.points = synthetic_rotation(2172);
  for (int i = 0; i < 20; ++i) {
    const double t = -0.0025 + 0.0105 * i;  // ~95 Hz over the window (the last 2.5 ms before its end)
    xsens::MtData2 d;
    d.euler_deg = xsens::Vec3{6.0 * std::sin(5.0 * t), 5.0 * std::sin(3.0 * t), 20.0};
    f.ahrs.push_back(sync::TimedAttitude{at_s(t), at_s(t + 0.002), d});
  }
  for (int i = 0; i < 2; ++i) {
    nmea::Gga g;
    g.lat_deg = 39.9 + 1e-6 * i;
    g.lon_deg = 116.4;
    g.quality = 4;
    g.alt_m = 45.0;
    g.geoid_sep_m = -8.5;
    const double t = -0.05 + 0.3 * i;
    f.gnss.push_back(sync::TimedGnss{at_s(t), at_s(t + 0.03), g});
  }
  sync::TimedScan s;
  s.time = at_s(0.09);
  s.scan.first_step = 0;
  s.scan.last_step = 1080;
  for (int i = 0; i <= 1080; ++i) s.scan.ranges_mm.push_back(static_cast<std::uint32_t>(1000 + 7 * i));
  f.scan2d = s;
  return f;
}

void BM_CompensateFrame(benchmark::State& state) {
  const sync::SyncedFrame f = frame_70k();
  CompensationParams p;
  p.lidar.x_m = 1.8;
  p.lidar.z_m = 2.2;
  p.scanner.x_m = 2.0;
  p.scanner.pitch_deg = 10.0;
  p.antenna_m = Eigen::Vector3d(0.4, 0.0, 2.8);
  p.plane_points = state.range(0) != 0;
  const FrameCompensator comp(p);
  CompensatedFrame out;
  for (auto _ : state) {
    comp.compensate(f, out);
    benchmark::DoNotOptimize(out.points.data());
  }
  if (out.levelling != Levelling::Full || out.points.size() != f.points.size() + 1081) {
    state.SkipWithError("the frame was not fully compensated: the benchmark measures the wrong path");
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(f.points.size() + 1081));
  state.counters["points"] = static_cast<double>(out.points.size());
}
BENCHMARK(BM_CompensateFrame)->ArgName("plane_points")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
