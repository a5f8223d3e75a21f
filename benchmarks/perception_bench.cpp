// Obstacle detection, each stage and the whole pipeline, side by side with the stock-PCL way of doing the
// same step, in the same run on the same frames, and packets to obstacles:
//   bench_perception [--benchmark_filter=...]
// Frames: rotations of the scene simulator (tools/sim, linked in, run at start: nothing to download or keep),
// decoded from its UDP payloads by our velodyne::Stream: the `shed` scene at 10 Hz (~69,300 points) and 5 Hz
// (~138,600 points), the acceptance frames (nearly every ray returns); and, as a field for comparison, the
// `pedestrian` scene at 10 and 5 Hz (a person crossing at 10 m; the sky returns nothing).
// Every iteration runs ours three times, then PCL's three times, on the same input, timing each with the
// thread's CPU clock (and std::chrono for wall time). Counters: medians of the warm runs (after a run of the
// same side) and of the cold ones (the first after the other side's), and their ratios (x_faster_than_pcl,
// x_faster_cold). CPU time is the steady measure on a shared machine. A summary table follows the runs.
// Settings: config/fieldguard.yaml and config/published.yaml through the app's loader; stock PCL with the
// published values (CropBox ROI and negative body box, VoxelGrid 0.15 m, SACSegmentation plane RANSAC 60
// iterations 0.3 m, EuclideanClusterExtraction 0.6 m over search::KdTree with 10..240 points).
// Packets to obstacles: the rotation's UDP payloads pushed into velodyne::Stream, the rotation it emits through
// the fieldguard.yaml pipeline (one thread, buffers reused across rotations as the daemon does).
// Near field (2D LiDAR): the stage alone on a 1081-step scan against the frame's zone ground, and the whole
// fieldguard.yaml pipeline on the frame with and without that scan merged in, alternated in each iteration.
#include <benchmark/benchmark.h>
#include <pcl/ModelCoefficients.h>
#include <pcl/common/common.h>
#include <pcl/filters/crop_box.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <numbers>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "fieldguard/config/config.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"
#include "fieldguard/perception/cluster_absorb.hpp"
#include "fieldguard/perception/cluster_join.hpp"
#include "fieldguard/perception/cluster_split.hpp"
#include "fieldguard/perception/crop.hpp"
#include "fieldguard/perception/euclidean_cluster.hpp"
#include "fieldguard/perception/near_field.hpp"
#include "fieldguard/perception/obstacle_hold.hpp"
#include "fieldguard/perception/pipeline.hpp"
#include "fieldguard/perception/ransac_ground.hpp"
#include "fieldguard/perception/voxel_grid.hpp"
#include "fieldguard/perception/zone_ground.hpp"
#include "sim/rng.hpp"
#include "sim_frames.hpp"

namespace {

using namespace fieldguard;
using namespace fieldguard::perception;
using PclCloud = pcl::PointCloud<pcl::PointXYZ>;

// ---- settings ----

PipelineParams load_params(const char* file) {
  // FIELDGUARD_TEST_DATA is <source>/tests/data.
  const auto r = app::load_config_file(std::string(FIELDGUARD_TEST_DATA) + "/../../config/" + file);
  if (!r.ok()) {
    std::fprintf(stderr, "%s: %s\n", file, r.issues.front().to_string().c_str());
    std::exit(2);
  }
  return r.config.perception;
}
const PipelineParams& fieldguard_params() {
  static const PipelineParams p = load_params("fieldguard.yaml");
  return p;
}
const PipelineParams& published() {
  static const PipelineParams p = load_params("published.yaml");
  return p;
}

// ---- frames and the inputs of every stage, ours and PCL's, computed once ----

struct Frame {
  std::string name;
  std::vector<sim::TimedPacket> packets;  // the rotation's UDP payloads
  std::vector<LidarPoint> points;         // as velodyne::Stream decodes them
  PclCloud::Ptr pcl_points{new PclCloud};
  // Our stage inputs (published settings, so both sides see the same data sizes).
  Cloud cropped, voxels, above;
  // PCL's.
  PclCloud::Ptr pcl_cropped{new PclCloud}, pcl_voxels{new PclCloud}, pcl_above{new PclCloud};
};

void pcl_crop(const PclCloud::Ptr& in, PclCloud& out, const PipelineParams& p) {
  const auto v4 = [](const std::array<double, 3>& a) {
    return Eigen::Vector4f(static_cast<float>(a[0]), static_cast<float>(a[1]), static_cast<float>(a[2]), 1.F);
  };
  PclCloud::Ptr roi(new PclCloud);
  pcl::CropBox<pcl::PointXYZ> crop;
  crop.setInputCloud(in);
  crop.setMin(v4(p.roi.min));
  crop.setMax(v4(p.roi.max));
  crop.filter(*roi);
  pcl::CropBox<pcl::PointXYZ> body;
  body.setInputCloud(roi);
  body.setMin(v4(p.body.min));
  body.setMax(v4(p.body.max));
  body.setNegative(true);
  body.filter(out);
}

void pcl_voxel(const PclCloud::Ptr& in, PclCloud& out, double leaf) {
  pcl::VoxelGrid<pcl::PointXYZ> vg;
  vg.setInputCloud(in);
  const auto l = static_cast<float>(leaf);
  vg.setLeafSize(l, l, l);
  vg.filter(out);
}

std::size_t pcl_ground(const PclCloud::Ptr& in, pcl::PointIndices& inliers, int iterations, double distance) {
  pcl::SACSegmentation<pcl::PointXYZ> seg;
  seg.setOptimizeCoefficients(true);
  seg.setModelType(pcl::SACMODEL_PLANE);
  seg.setMethodType(pcl::SAC_RANSAC);
  seg.setMaxIterations(iterations);
  seg.setDistanceThreshold(distance);
  seg.setInputCloud(in);
  pcl::ModelCoefficients coeff;
  seg.segment(inliers, coeff);
  return inliers.indices.size();
}

std::size_t pcl_clusters(const PclCloud::Ptr& in, double tolerance, int min_pts, int max_pts) {
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(in);
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
  ec.setClusterTolerance(tolerance);
  ec.setMinClusterSize(static_cast<pcl::uindex_t>(min_pts));
  ec.setMaxClusterSize(static_cast<pcl::uindex_t>(max_pts));
  ec.setSearchMethod(tree);
  ec.setInputCloud(in);
  std::vector<pcl::PointIndices> clusters;
  ec.extract(clusters);
  return clusters.size();
}

// The stock-PCL pipeline, published settings: crop, voxel grid, RANSAC plane, the rest clustered, boxes.
std::size_t pcl_pipeline(const PclCloud::Ptr& in) {
  const PipelineParams& p = published();
  PclCloud::Ptr cropped(new PclCloud), voxels(new PclCloud), above(new PclCloud);
  pcl_crop(in, *cropped, p);
  pcl_voxel(cropped, *voxels, p.voxel.leaf_m);
  pcl::PointIndices::Ptr ground(new pcl::PointIndices);
  pcl_ground(voxels, *ground, p.ground.ransac.iterations, p.ground.ransac.distance_m);
  pcl::ExtractIndices<pcl::PointXYZ> extract;
  extract.setInputCloud(voxels);
  extract.setIndices(ground);
  extract.setNegative(true);
  extract.filter(*above);
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(above);
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
  ec.setClusterTolerance(p.cluster.tolerance_m);
  ec.setMinClusterSize(static_cast<pcl::uindex_t>(p.filters.min_points));
  ec.setMaxClusterSize(static_cast<pcl::uindex_t>(p.filters.max_points));
  ec.setSearchMethod(tree);
  ec.setInputCloud(above);
  std::vector<pcl::PointIndices> clusters;
  ec.extract(clusters);
  std::size_t obstacles = 0;
  for (const auto& c : clusters) {
    Eigen::Vector4f lo, hi;
    pcl::getMinMax3D(*above, c.indices, lo, hi);
    const Eigen::Vector4f size = hi - lo;
    const double v = static_cast<double>(size[0] * size[1] * size[2]);
    if (v >= p.filters.min_volume_m3 && v <= p.filters.max_volume_m3) ++obstacles;
  }
  return obstacles;
}

// The frames: simulator scene, rate, the rotation taken, the rotations of the scene (pedestrian: one crossing
// per two rotations, the second crossing at 10 m).
struct FrameSpec {
  const char* name;
  const char* scene;
  double hz;
  std::uint64_t rotation;
  int scene_rotations;
};
constexpr FrameSpec kFrames[] = {
    {"shed 10Hz", "shed", 10.0, 1, 3},
    {"shed 5Hz", "shed", 5.0, 1, 3},
    {"field 10Hz", "pedestrian", 10.0, 3, 12},
    {"field 5Hz", "pedestrian", 5.0, 3, 12},
};
constexpr int kFrameCount = 4;

Frame make_frame(const FrameSpec& spec) {
  Frame f;
  f.name = spec.name;
  bench::SimRotation r = bench::simulate_rotation(spec.scene, spec.hz, spec.rotation, spec.scene_rotations);
  f.packets = std::move(r.packets);
  f.points = std::move(r.points);
  for (const auto& p : f.points) f.pcl_points->push_back(pcl::PointXYZ(p.x, p.y, p.z));
  const PipelineParams& p = published();
  crop_box(f.points, p.roi, p.body, f.cropped);
  VoxelGrid grid(p.voxel);
  grid.filter(f.cropped, f.voxels);
  RansacGround ransac(p.ground.ransac, p.ground.zones.sensor_height_m);
  GroundLabels labels;
  ransac.segment(f.voxels, labels);
  for (std::size_t i = 0; i < f.voxels.size(); ++i) {
    if (labels.ground[i] == 0U) f.above.push_back(f.voxels.x[i], f.voxels.y[i], f.voxels.z[i]);
  }
  pcl_crop(f.pcl_points, *f.pcl_cropped, p);
  pcl_voxel(f.pcl_cropped, *f.pcl_voxels, p.voxel.leaf_m);
  pcl::PointIndices ground;
  pcl_ground(f.pcl_voxels, ground, p.ground.ransac.iterations, p.ground.ransac.distance_m);
  std::vector<char> is_ground(f.pcl_voxels->size(), 0);
  for (const int i : ground.indices) is_ground[static_cast<std::size_t>(i)] = 1;
  for (std::size_t i = 0; i < f.pcl_voxels->size(); ++i) {
    if (is_ground[i] == 0) f.pcl_above->push_back((*f.pcl_voxels)[i]);
  }
  return f;
}

Frame& frame(int which) {
  static std::vector<Frame> frames = [] {
    std::vector<Frame> v;
    for (const FrameSpec& spec : kFrames) v.push_back(make_frame(spec));
    return v;
  }();
  return frames.at(static_cast<std::size_t>(which));
}

// ---- paired timing ----

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Row {
  std::string stage, frame;
  std::size_t points_in = 0;
  // Medians of the thread's CPU time (us): warm = runs that follow a run of the same side, cold = the first
  // run after the other side's; and of the wall time of the warm runs.
  double ours_cpu = 0, pcl_cpu = 0, ours_cold = 0, pcl_cold = 0, ours_wall = 0, pcl_wall = 0;
};
std::vector<Row>& rows() {
  static std::vector<Row> r;
  return r;
}

// Every iteration runs ours kRuns times, then PCL's kRuns times, on the same input. The first run of each
// side follows the other side's runs (its caches and branch history are the other's: cold); the rest follow
// their own (warm). `pcl` may be empty (no stock-PCL counterpart).
constexpr int kRuns = 3;
void paired(benchmark::State& state, const std::string& stage, int which, std::size_t points_in,
            const std::function<void()>& ours, const std::function<void()>& pcl,
            const std::string* frame_name = nullptr) {
  std::vector<double> o_cpu, p_cpu, o_cold, p_cold, o_wall, p_wall;
  using clock = std::chrono::steady_clock;
  const auto timed = [](const std::function<void()>& f, double& cpu_us, double& wall_us) {
    const auto t0 = clock::now();
    const double c0 = cpu_seconds();
    f();
    cpu_us = (cpu_seconds() - c0) * 1e6;
    wall_us = std::chrono::duration<double>(clock::now() - t0).count() * 1e6;
  };
  for (auto _ : state) {
    double manual = 0.0;
    for (int r = 0; r < kRuns; ++r) {
      double cpu = 0, wall = 0;
      timed(ours, cpu, wall);
      manual += wall * 1e-6;
      (r == 0 ? o_cold : o_cpu).push_back(cpu);
      if (r > 0) o_wall.push_back(wall);
    }
    state.SetIterationTime(manual / kRuns);
    if (!pcl) continue;
    for (int r = 0; r < kRuns; ++r) {
      double cpu = 0, wall = 0;
      timed(pcl, cpu, wall);
      (r == 0 ? p_cold : p_cpu).push_back(cpu);
      if (r > 0) p_wall.push_back(wall);
    }
  }
  const std::string& name = frame_name != nullptr ? *frame_name : frame(which).name;
  Row row{stage,          name,           points_in,      median(o_cpu), median(p_cpu),
          median(o_cold), median(p_cold), median(o_wall), median(p_wall)};
  state.counters["points_in"] = static_cast<double>(points_in);
  state.counters["ours_us"] = row.ours_cpu;
  state.counters["ours_cold_us"] = row.ours_cold;
  if (pcl) {
    state.counters["pcl_us"] = row.pcl_cpu;
    state.counters["pcl_cold_us"] = row.pcl_cold;
    state.counters["x_faster_than_pcl"] = row.ours_cpu > 0 ? row.pcl_cpu / row.ours_cpu : 0.0;
    state.counters["x_faster_cold"] = row.ours_cold > 0 ? row.pcl_cold / row.ours_cold : 0.0;
  }
  // Google Benchmark calls a benchmark several times while it sizes the run: keep the last, the real one.
  auto& all = rows();
  const auto same = [&row](const Row& x) { return x.stage == row.stage && x.frame == row.frame; };
  const auto it = std::find_if(all.begin(), all.end(), same);
  if (it != all.end()) {
    *it = row;
  } else {
    all.push_back(row);
  }
}

// ---- the benchmarks ----

void BM_Crop(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  const PipelineParams& p = published();
  Cloud out;
  PclCloud pout;
  paired(
      state, "crop (ROI + body)", static_cast<int>(state.range(0)), f.points.size(),
      [&] {
        crop_box(f.points, p.roi, p.body, out);
        benchmark::DoNotOptimize(out.x.data());
      },
      [&] { pcl_crop(f.pcl_points, pout, p); });
}

// The crop as the fieldguard.yaml pipeline calls it (BM_Crop times the published call): its ROI with the ground's
// context band beyond the far end, the 2D LiDAR's points set aside, the points within the ROI's far end counted.
// No PCL side: CropBox has no context band or 2D split (BM_Crop holds ours against it).
void BM_CropPipeline(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  const PipelineParams& p = fieldguard_params();
  Box3 roi = p.roi;
  roi.max[0] += p.ground.context_m;
  const auto far = static_cast<float>(p.roi.max[0]);
  Cloud out;
  std::vector<LidarPoint> scan2d;
  std::uint32_t in_roi = 0;
  paired(state, "crop: fieldguard.yaml, pipeline call", static_cast<int>(state.range(0)), f.points.size(),
         [&] {
           in_roi = crop_box(f.points, roi, p.body, out, scan2d, far);
           benchmark::DoNotOptimize(out.x.data());
         },
         {});
  state.counters["kept"] = static_cast<double>(out.size());
  state.counters["in_roi"] = static_cast<double>(in_roi);
}

void BM_Voxel(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  VoxelGrid grid(published().voxel);
  Cloud out;
  PclCloud pout;
  paired(
      state, "voxel grid 0.15 m", static_cast<int>(state.range(0)), f.cropped.size(),
      [&] {
        grid.filter(f.cropped, out);
        benchmark::DoNotOptimize(out.x.data());
      },
      [&] { pcl_voxel(f.pcl_cropped, pout, 0.15); });
}

// The voxel grid on one frame, each run after runs on the three other frames. Run after run on one frame (or
// on two), the branch predictor learns much of the frames' branches (the grid's "shed 10Hz" took 125 us that
// way, 350 us after the other frames; "shed 5Hz" is too long to learn), which no live rotation repeats.
// Medians of thread CPU time of the frame's runs only (ours_us).
void BM_VoxelAlternated(benchmark::State& state) {
  const int which = static_cast<int>(state.range(0));
  const Frame& f = frame(which);
  VoxelGrid grid(published().voxel);
  Cloud out;
  std::vector<double> cpu;
  for (auto _ : state) {
    for (int k = 1; k < kFrameCount; ++k) {
      grid.filter(frame((which + k) % kFrameCount).cropped, out);
      benchmark::DoNotOptimize(out.x.data());
    }
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_seconds();
    grid.filter(f.cropped, out);
    benchmark::DoNotOptimize(out.x.data());
    cpu.push_back((cpu_seconds() - c0) * 1e6);
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  state.counters["points_in"] = static_cast<double>(f.cropped.size());
  state.counters["ours_us"] = median(cpu);
}

void BM_GroundRansac(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  const PipelineParams& p = published();
  RansacGround ransac(p.ground.ransac, 0.95);
  GroundLabels labels;
  pcl::PointIndices inliers;
  paired(
      state, "ground: RANSAC plane", static_cast<int>(state.range(0)), f.voxels.size(),
      [&] {
        ransac.segment(f.voxels, labels);
        benchmark::DoNotOptimize(labels.ground.data());
      },
      [&] { pcl_ground(f.pcl_voxels, inliers, p.ground.ransac.iterations, p.ground.ransac.distance_m); });
}

void BM_GroundZones(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  const PipelineParams& p = published();
  ZoneGround zones(fieldguard_params().ground.zones);
  GroundLabels labels;
  pcl::PointIndices inliers;
  paired(
      state, "ground: zones (vs PCL RANSAC)", static_cast<int>(state.range(0)), f.voxels.size(),
      [&] {
        zones.segment(f.voxels, labels);
        benchmark::DoNotOptimize(labels.ground.data());
      },
      [&] { pcl_ground(f.pcl_voxels, inliers, p.ground.ransac.iterations, p.ground.ransac.distance_m); });
}

void cluster_bench(benchmark::State& state, const char* stage, ClusterMethod m, ClusterStructure s) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  ClusterParams cp = fieldguard_params().cluster;
  cp.method = m;
  cp.structure = s;
  cp.tolerance_m = 0.6;
  EuclideanClusterer clusterer(cp);
  Clusters out;
  paired(
      state, stage, static_cast<int>(state.range(0)), f.above.size(),
      [&] {
        clusterer.extract(f.above, out);
        benchmark::DoNotOptimize(out.indices.data());
      },
      [&] { pcl_clusters(f.pcl_above, 0.6, 1, 1000000); });
}
void BM_ClusterFixedKdTree(benchmark::State& state) {
  cluster_bench(state, "cluster: fixed 0.6, k-d tree", ClusterMethod::Fixed, ClusterStructure::KdTree);
}
void BM_ClusterFixedGrid(benchmark::State& state) {
  cluster_bench(state, "cluster: fixed 0.6, grid", ClusterMethod::Fixed, ClusterStructure::Grid);
}
void BM_ClusterAdaptiveGrid(benchmark::State& state) {
  cluster_bench(state, "cluster: adaptive, grid", ClusterMethod::Adaptive, ClusterStructure::Grid);
}
// fieldguard.yaml's clustering as configured (anisotropic radii from its tolerance_m), then its small-cluster
// absorption (cluster_absorb.hpp; no PCL counterpart) on those clusters.
void BM_ClusterAnisotropicGrid(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  ClusterParams cp = fieldguard_params().cluster;
  cp.method = ClusterMethod::Anisotropic;
  cp.structure = ClusterStructure::Grid;
  EuclideanClusterer clusterer(cp);
  Clusters out;
  paired(
      state, "cluster: anisotropic, grid", static_cast<int>(state.range(0)), f.above.size(),
      [&] {
        clusterer.extract(f.above, out);
        benchmark::DoNotOptimize(out.indices.data());
      },
      [&] { pcl_clusters(f.pcl_above, 0.6, 1, 1000000); });
}
// fieldguard.yaml's clustering on the points the fieldguard.yaml pipeline clusters (its crop with the ground
// context, voxel grid and ground zones; not ground, not beyond the ROI): the input BM_PacketsToObstacles times.
void BM_ClusterPipelineInput(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  const PipelineParams& p = fieldguard_params();
  Box3 roi = p.roi;
  roi.max[0] += p.ground.context_m;
  Cloud cropped, voxels, above;
  crop_box(f.points, roi, p.body, cropped);
  VoxelGrid(p.voxel).filter(cropped, voxels);
  GroundLabels labels;
  ZoneGround(p.ground.zones).segment(voxels, labels);
  const auto far = static_cast<float>(p.roi.max[0]);
  for (std::size_t i = 0; i < voxels.size(); ++i) {
    if (labels.ground[i] == 0U && !(voxels.x[i] > far)) above.push_back(voxels.x[i], voxels.y[i], voxels.z[i]);
  }
  EuclideanClusterer clusterer(p.cluster);
  Clusters out;
  paired(state, "cluster: fieldguard.yaml, pipeline input", static_cast<int>(state.range(0)), above.size(),
         [&] {
           clusterer.extract(above, out);
           benchmark::DoNotOptimize(out.indices.data());
         },
         {});
  state.counters["clusters"] = static_cast<double>(out.size());
}
void BM_ClusterAbsorb(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  const ClusterParams cp = fieldguard_params().cluster;
  EuclideanClusterer clusterer(cp);
  Clusters clustered, work;
  clusterer.extract(f.above, clustered);
  ClusterAbsorber absorber(cp.absorb_max_points > 0 ? cp.absorb_max_points : 10, cp.absorb_margin_m);
  std::uint32_t moved = 0;
  paired(state, "cluster absorb", static_cast<int>(state.range(0)), f.above.size(),
         [&] {
           work = clustered;  // the stage rewrites its input: timed with this copy
           moved = absorber.absorb(f.above, work);
           benchmark::DoNotOptimize(work.indices.data());
         },
         {});
  state.counters["clusters_in"] = static_cast<double>(clustered.size());
  state.counters["absorbed"] = static_cast<double>(moved);
}

void pipeline_bench(benchmark::State& state, const char* stage, const PipelineParams& params) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  Pipeline pipe(params);
  paired(
      state, stage, static_cast<int>(state.range(0)), f.points.size(),
      [&] {
        const auto r = pipe.process(f.points);
        benchmark::DoNotOptimize(r.obstacles.data());
      },
      [&] { benchmark::DoNotOptimize(pcl_pipeline(f.pcl_points)); });
}
void BM_PipelinePublished(benchmark::State& state) { pipeline_bench(state, "PIPELINE published.yaml", published()); }
void BM_PipelineFieldguard(benchmark::State& state) {
  pipeline_bench(state, "PIPELINE fieldguard.yaml", fieldguard_params());
}

// fieldguard.yaml's clusters of a frame's above-ground points after absorption, and the points' heights above a
// level ground at the sensor's mounting height: the input of the stages after absorption.
struct AbsorbedClusters {
  Clusters clusters;
  std::vector<float> height;
};
AbsorbedClusters absorbed_clusters(const Frame& f) {
  const ClusterParams& cp = fieldguard_params().cluster;
  EuclideanClusterer clusterer(cp);
  ClusterAbsorber absorber(cp.absorb_max_points, cp.absorb_margin_m);
  AbsorbedClusters out;
  clusterer.extract(f.above, out.clusters);
  absorber.absorb(f.above, out.clusters);
  const auto sensor_h = static_cast<float>(fieldguard_params().ground.zones.sensor_height_m);
  out.height.assign(f.above.z.begin(), f.above.z.end());
  for (float& h : out.height) h += sensor_h;
  return out;
}

// The floating-cluster joins (cluster_join.hpp; no PCL counterpart) with fieldguard.yaml's keys, on its clusters
// after absorption. Heights above a level ground at the sensor's mounting height: the stage's cost is its pairs of
// clusters, whatever the heights make of them.
void BM_ClusterJoin(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  const ClusterParams& cp = fieldguard_params().cluster;
  const AbsorbedClusters in = absorbed_clusters(f);
  const Clusters& clustered = in.clusters;
  const std::vector<float>& height = in.height;
  Clusters work;
  ClusterJoiner joiner(ClusterJoinParams::from(cp));
  std::uint32_t joined = 0;
  paired(state, "cluster join (floating)", static_cast<int>(state.range(0)), f.above.size(),
         [&] {
           work = clustered;  // the stage rewrites its input: timed with this copy
           joined = joiner.join(f.above, height, fieldguard_params().filters, work);
           benchmark::DoNotOptimize(work.indices.data());
         },
         {});
  state.counters["clusters_in"] = static_cast<double>(clustered.size());
  state.counters["joins"] = static_cast<double>(joined);
}

// The split of clusters holding two crowns (cluster_split.hpp; no PCL counterpart), on fieldguard.yaml's clusters
// after absorption and joins: the stage's cost is the clusters long enough to be looked at (the shed's walls).
void BM_ClusterSplit(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  const ClusterParams& cp = fieldguard_params().cluster;
  AbsorbedClusters in = absorbed_clusters(f);
  Clusters& clustered = in.clusters;
  ClusterJoiner(ClusterJoinParams::from(cp)).join(f.above, in.height, fieldguard_params().filters, clustered);
  EuclideanClusterer clusterer(cp);  // the split measures gaps against its horizontal radius
  Clusters work;
  ClusterSplitter splitter(ClusterSplitParams::from(cp));
  std::uint32_t cuts = 0;
  paired(state, "cluster split (two crowns)", static_cast<int>(state.range(0)), f.above.size(),
         [&] {
           work = clustered;  // the stage rewrites its input: timed with this copy
           cuts = splitter.split(f.above, clusterer, work);
           benchmark::DoNotOptimize(work.indices.data());
         },
         {});
  state.counters["clusters_in"] = static_cast<double>(clustered.size());
  state.counters["cuts"] = static_cast<double>(cuts);
}

// The joins' worst case: a frame of scattered single returns (rain, dust, a thin hedge far out), each its own
// cluster, half of them floating. The joins compare clusters by their x-y boxes; this measures how that grows
// with the count (range(0) clusters, over x 0..50 m, y -10..10 m).
void BM_ClusterJoinScattered(benchmark::State& state) {
  const auto count = static_cast<std::size_t>(state.range(0));
  Cloud c;
  std::vector<float> height;
  sim::Rng rng(12345);  // the simulator's generator: the same cloud on every machine
  const auto next = [&rng] { return static_cast<float>(rng.uniform()); };
  for (std::size_t i = 0; i < count; ++i) {
    const float h = 3.F * next();
    c.push_back(50.F * next(), 20.F * next() - 10.F, h - 0.95F);
    height.push_back(h);
  }
  Clusters clustered;
  clustered.offsets.push_back(0);
  for (std::uint32_t i = 0; i < count; ++i) {
    clustered.indices.push_back(i);
    clustered.offsets.push_back(i + 1);
  }
  ClusterJoiner joiner(ClusterJoinParams::from(fieldguard_params().cluster));
  Clusters work;
  std::uint32_t joined = 0;
  for (auto _ : state) {
    work = clustered;
    joined = joiner.join(c, height, fieldguard_params().filters, work);
    benchmark::DoNotOptimize(work.indices.data());
  }
  state.counters["joins"] = static_cast<double>(joined);
  state.counters["clusters_out"] = static_cast<double>(work.size());
}

// fieldguard.yaml's pipeline without the crop-canopy rule (canopy.hpp) and the radial ground blend
// (ZoneParams::blend_radial): their cost is BM_PipelineFieldguard's time minus this one's.
void BM_PipelineFieldguardNoCanopy(benchmark::State& state) {
  static const PipelineParams p = [] {
    PipelineParams q = fieldguard_params();
    q.filters.canopy_max_height_m = 0.0;
    q.ground.zones.blend_radial = false;
    return q;
  }();
  pipeline_bench(state, "PIPELINE fieldguard.yaml without canopy rule, ground blend", p);
}

// fieldguard.yaml's pipeline without the canopy rule's look at a low cluster's surroundings
// (FilterParams::canopy_surroundings_m): its cost is BM_PipelineFieldguard's time minus this one's.
void BM_PipelineFieldguardNoSurroundings(benchmark::State& state) {
  static const PipelineParams p = [] {
    PipelineParams q = fieldguard_params();
    q.filters.canopy_surroundings_m = 0.0;
    return q;
  }();
  pipeline_bench(state, "PIPELINE fieldguard.yaml without canopy surroundings", p);
}

// Packets to obstacles: the UDP payloads of the rotation into velodyne::Stream, the rotation it emits through
// the fieldguard.yaml pipeline and its hold (which the daemon runs on its io thread, after the worker). The stream and
// the pipeline live across runs as in the daemon: each run pushes the rotation's packets, and the first packet (azimuth
// 0) completes the rotation pushed by the run before, which is then processed; frame buffers go back to the stream. One
// rotation decoded and detected per run.
void BM_PacketsToObstacles(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  velodyne::Stream stream(bench::sim_stream_options());
  Pipeline pipe(fieldguard_params());
  ObstacleHold hold(fieldguard_params().hold);
  std::vector<LidarFrame> done;
  std::vector<StageTimes> times;  // the pipeline's own stage times of every rotation processed
  std::size_t processed = 0, obstacles = 0;
  const auto run = [&] {
    for (auto& d : done) stream.recycle(std::move(d));
    done.clear();
    for (const auto& p : f.packets) stream.push(ByteSpan(p.bytes.data(), p.bytes.size()), Stamp{p.pcap_time_ns}, done);
    for (const auto& d : done) {
      auto r = pipe.process(d.points);
      (void)hold.apply(d.host_stamp.ns, r);
      obstacles = r.obstacles.size();
      times.push_back(r.times);
      ++processed;
      benchmark::DoNotOptimize(r.obstacles.data());
    }
  };
  run();  // the first push only starts a rotation
  times.clear();
  paired(state, "PACKETS -> obstacles", static_cast<int>(state.range(0)), f.points.size(), run, {});
  state.counters["obstacles"] = static_cast<double>(obstacles);
  if (processed == 0) state.SkipWithError("velodyne::Stream emitted no rotation");
  // Each stage as it ran here, after decoding and after the last rotation (medians, steady clock): what the
  // stage benches above time on one frame repeated, warm.
  const auto stage = [&](const char* name, float StageTimes::*field) {
    std::vector<double> v;
    v.reserve(times.size());
    for (const StageTimes& t : times) v.push_back(static_cast<double>(t.*field));
    state.counters[name] = median(v);
  };
  stage("in_crop_us", &StageTimes::crop_us);
  stage("in_voxel_us", &StageTimes::voxel_us);
  stage("in_ground_us", &StageTimes::ground_us);
  stage("in_cluster_us", &StageTimes::cluster_us);
  stage("in_merge_us", &StageTimes::merge_us);
  stage("in_boxes_us", &StageTimes::boxes_us);
  stage("in_pipeline_us", &StageTimes::total_us);
}

// Decoding alone: the same packets into velodyne::Stream.
void BM_Decode(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  velodyne::Stream stream(bench::sim_stream_options());
  std::vector<LidarFrame> done;
  const auto run = [&] {
    for (auto& d : done) stream.recycle(std::move(d));
    done.clear();
    for (const auto& p : f.packets) stream.push(ByteSpan(p.bytes.data(), p.bytes.size()), Stamp{p.pcap_time_ns}, done);
    benchmark::DoNotOptimize(done.data());
  };
  run();
  paired(state, "decode (velodyne::Stream)", static_cast<int>(state.range(0)), f.points.size(), run, {});
}

// A 1081-step scan of a bumper 2D LiDAR 0.3 m above flat ground (z = -0.95 in the 3D LiDAR's frame), the nose
// pitched 1.5 deg down: its plane meets the ground 11.5 m ahead, so the forward rays are points in the zone for
// the ground lookup (the stage's worst case); three crates cut it (two obstacles in the zone, one beyond), a
// hedge 25 m out returns the rest of the forward rays and the tractor itself the rays behind: 1081 points.
std::vector<LidarPoint> bumper_scan() {
  struct Crate {
    double x0, x1, y0, y1;
  };
  constexpr Crate kCrates[] = {{2.0, 2.6, -0.5, 0.1}, {5.0, 5.8, 1.5, 2.5}, {14.0, 15.0, -2.0, 2.0}};
  constexpr double kOz = -0.65, kGround = -0.95, kDip = 1.5 * std::numbers::pi / 180.0, kMaxRange = 30.0;
  constexpr double kHedge = 25.0, kTractor = 0.8;
  std::vector<LidarPoint> out;
  for (int step = 0; step <= 1080; ++step) {
    const double a = static_cast<double>(step - 540) * 0.25 * std::numbers::pi / 180.0;
    const double dx = std::cos(a) * std::cos(kDip), dy = std::sin(a), dz = -std::cos(a) * std::sin(kDip);
    double t = dz < 0.0 ? std::min(kMaxRange, (kGround - kOz) / dz) : kMaxRange;
    for (const Crate& c : kCrates) {
      if (std::fabs(dx) < 1e-9) continue;
      const double tc = (c.x0 - 0.3) / dx;  // the crate's near face, from the bumper at x = 0.3
      const double yc = tc * dy;
      if (tc > 0.0 && tc < t && yc >= c.y0 && yc <= c.y1) t = tc;
    }
    if (t >= kMaxRange) t = dx >= 0.0 ? kHedge : kTractor;
    LidarPoint p;
    p.x = static_cast<float>(0.3 + t * dx);
    p.y = static_cast<float>(t * dy);
    p.z = static_cast<float>(kOz + t * dz);
    p.range_m = static_cast<float>(t);
    p.ring = static_cast<std::uint16_t>(step);
    p.source = static_cast<std::uint8_t>(PointSource::Lidar2d);
    out.push_back(p);
  }
  return out;
}

// The hold (obstacle_hold.hpp; no PCL counterpart) with fieldguard.yaml's keys, on a frame's own fragments: every
// obstacle of the frame remembered, then each run the same frame with every second obstacle gone, so that half
// of them are looked for among the fragments. Frame 4 is an orchard rotation (10 Hz: crowns seen through the
// gaps of nearer rows, the most fragments). A run includes putting the frame's obstacles back (a copy of a few
// dozen).
void hold_bench(benchmark::State& state, const char* stage, bool posed) {
  static Frame orchard = make_frame(FrameSpec{"orchard 10Hz", "orchard", 10.0, 3, 12});
  const int which = static_cast<int>(state.range(0));
  Frame& f = which < kFrameCount ? frame(which) : orchard;
  Pipeline pipe(fieldguard_params());
  const FrameResult full = pipe.process(f.points);
  std::vector<Obstacle> half;
  for (std::size_t i = 0; i < full.obstacles.size(); i += 2) half.push_back(full.obstacles[i]);
  ObstacleHold hold(fieldguard_params().hold);
  // A fused frame's pose in a Gauss-Krueger zone, the same every run (the tractor standing, so that the same
  // fragments are held): every remembered box is still moved through it.
  const std::optional<FramePose> pose =
      posed ? std::optional<FramePose>(FramePose{3'512'345.0, 5'401'234.0, 312.0, 0.52, 3}) : std::nullopt;
  FrameResult work = full;
  std::int64_t stamp = 0;
  (void)hold.apply(stamp, work, std::nullopt, pose);
  std::size_t held = 0;
  paired(
      state, stage, which < kFrameCount ? which : 0, full.fragments.size(),
      [&] {
        work.obstacles.assign(half.begin(), half.end());
        held = hold.apply(++stamp, work, std::nullopt, pose);  // 1 ns later: nothing ages out
      },
      {}, &f.name);
  state.counters["obstacles"] = static_cast<double>(full.obstacles.size());
  state.counters["fragments"] = static_cast<double>(full.fragments.size());
  state.counters["held"] = static_cast<double>(held);
}

void BM_ObstacleHold(benchmark::State& state) { hold_bench(state, "hold (half the obstacles gone)", false); }

// The same with the frames' poses (a fused daemon's): every remembered box moved into the frame first.
void BM_ObstacleHoldPosed(benchmark::State& state) { hold_bench(state, "hold, posed frames", true); }

void BM_NearField(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  Pipeline pipe(fieldguard_params());
  (void)pipe.process(f.points);  // the frame's ground
  const std::vector<LidarPoint> scan = bumper_scan();
  NearField near(fieldguard_params().near_field);
  std::vector<Obstacle> out;
  const NearField::GroundFn ground = [&pipe](float x, float y) { return pipe.ground_z(x, y); };
  paired(state, "near field (2D scan)", static_cast<int>(state.range(0)), scan.size(),
         [&] {
           out.clear();
           benchmark::DoNotOptimize(near.detect(scan, ground, out));
         },
         {});
  state.counters["near_obstacles"] = static_cast<double>(out.size());
}

// The whole fieldguard.yaml pipeline on the frame with the scan merged in (appended, as geo's compensator
// does) and without, alternated within each iteration; counters: medians of the thread's CPU time.
void BM_PipelineWithScan(benchmark::State& state) {
  Frame& f = frame(static_cast<int>(state.range(0)));
  Pipeline pipe(fieldguard_params());
  std::vector<LidarPoint> merged = f.points;
  const std::vector<LidarPoint> scan = bumper_scan();
  merged.insert(merged.end(), scan.begin(), scan.end());
  std::vector<double> with_us, without_us;
  std::size_t obstacles_with = 0, obstacles_without = 0;
  const auto cpu_us = [&](std::span<const LidarPoint> pts, std::size_t& obstacles) {
    const double c0 = cpu_seconds();
    const auto r = pipe.process(pts);
    const double us = (cpu_seconds() - c0) * 1e6;
    obstacles = r.obstacles.size();
    benchmark::DoNotOptimize(r.obstacles.data());
    return us;
  };
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    for (int r = 0; r < kRuns; ++r) without_us.push_back(cpu_us(f.points, obstacles_without));
    for (int r = 0; r < kRuns; ++r) with_us.push_back(cpu_us(merged, obstacles_with));
    state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / (2 * kRuns));
  }
  const double w = median(with_us), wo = median(without_us);
  state.counters["points_in"] = static_cast<double>(merged.size());
  state.counters["with_scan_us"] = w;
  state.counters["without_us"] = wo;
  state.counters["added_us"] = w - wo;
  state.counters["obstacles_with"] = static_cast<double>(obstacles_with);
  state.counters["obstacles_without"] = static_cast<double>(obstacles_without);
}

// Iterations per benchmark, each three runs of ours and three of PCL's: 60 timed runs a side, enough for
// steady medians, and a whole run stays within minutes on a loaded 2-core machine (the stock-PCL pipeline
// takes ~40 ms on the shed).
constexpr int kIterations = 20;
#define FG_BENCH(fn) \
  BENCHMARK(fn)->DenseRange(0, kFrameCount - 1)->UseManualTime()->Iterations(kIterations)->Unit(benchmark::kMicrosecond)
FG_BENCH(BM_Crop);
FG_BENCH(BM_CropPipeline);
FG_BENCH(BM_Voxel);
FG_BENCH(BM_VoxelAlternated);
FG_BENCH(BM_GroundRansac);
FG_BENCH(BM_GroundZones);
FG_BENCH(BM_ClusterFixedKdTree);
FG_BENCH(BM_ClusterFixedGrid);
FG_BENCH(BM_ClusterAdaptiveGrid);
FG_BENCH(BM_ClusterAnisotropicGrid);
FG_BENCH(BM_ClusterPipelineInput);
FG_BENCH(BM_ClusterAbsorb);
FG_BENCH(BM_ClusterJoin);
FG_BENCH(BM_ClusterSplit);
BENCHMARK(BM_ClusterJoinScattered)->Arg(1000)->Arg(4000)->Arg(16000)->Unit(benchmark::kMicrosecond);
FG_BENCH(BM_PipelinePublished);
FG_BENCH(BM_PipelineFieldguard);
FG_BENCH(BM_PipelineFieldguardNoCanopy);
FG_BENCH(BM_PipelineFieldguardNoSurroundings);
FG_BENCH(BM_Decode);
FG_BENCH(BM_PacketsToObstacles);
FG_BENCH(BM_NearField);
BENCHMARK(BM_ObstacleHold)
    ->DenseRange(0, kFrameCount)
    ->UseManualTime()
    ->Iterations(kIterations)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ObstacleHoldPosed)
    ->DenseRange(0, kFrameCount)
    ->UseManualTime()
    ->Iterations(kIterations)
    ->Unit(benchmark::kMicrosecond);
FG_BENCH(BM_PipelineWithScan);

void print_summary() {
  if (rows().empty()) return;
  std::printf("\nFrames (fieldguard-sim scenes, seed 1, decoded by velodyne::Stream):");
  for (int i = 0; i < kFrameCount; ++i) {
    std::printf(" %s = %s rotation %llu, %zu points%s", kFrames[i].name, kFrames[i].scene,
                static_cast<unsigned long long>(kFrames[i].rotation), frame(i).points.size(),
                i + 1 < kFrameCount ? ";" : ".\n");
  }
  std::printf(
      "Medians of thread CPU time in us. warm: runs after a run of the same side; cold: the first run\n"
      "after the other side's (caches and branch history theirs). PCL: the stock classes, same input.\n");
  std::printf("%-30s %-10s %7s | %8s %8s %6s | %8s %8s %6s | %8s %8s\n", "stage", "frame", "pts in", "ours", "pcl",
              "x warm", "ours", "pcl", "x cold", "ours wall", "pcl wall");
  for (const Row& r : rows()) {
    if (r.pcl_cpu > 0.0) {
      std::printf("%-30s %-10s %7zu | %8.1f %8.1f %6.2f | %8.1f %8.1f %6.2f | %8.1f %8.1f\n", r.stage.c_str(),
                  r.frame.c_str(), r.points_in, r.ours_cpu, r.pcl_cpu, r.pcl_cpu / r.ours_cpu, r.ours_cold, r.pcl_cold,
                  r.pcl_cold / r.ours_cold, r.ours_wall, r.pcl_wall);
    } else {
      std::printf("%-30s %-10s %7zu | %8.1f %8s %6s | %8.1f %8s %6s | %8.1f %8s\n", r.stage.c_str(), r.frame.c_str(),
                  r.points_in, r.ours_cpu, "-", "-", r.ours_cold, "-", "-", r.ours_wall, "-");
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  print_summary();
  return 0;
}
