#include "fieldguard/perception/pipeline.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "fieldguard/perception/cluster_absorb.hpp"
#include "fieldguard/perception/cluster_filter.hpp"
#include "fieldguard/perception/cluster_join.hpp"
#include "fieldguard/perception/cluster_split.hpp"
#include "fieldguard/perception/crop.hpp"
#include "fieldguard/perception/euclidean_cluster.hpp"
#include "fieldguard/perception/near_field.hpp"
#include "fieldguard/perception/obstacle_box.hpp"
#include "fieldguard/perception/ransac_ground.hpp"
#include "fieldguard/perception/voxel_grid.hpp"
#include "fieldguard/perception/zone_ground.hpp"
#include "perception/indices.hpp"
#include "perception/simd.hpp"

namespace fieldguard::perception {
namespace {

// Lane k all ones where bit k of the index is set.
alignas(16) constexpr std::array<std::array<std::int32_t, 4>, 16> kLanes = [] {
  std::array<std::array<std::int32_t, 4>, 16> t{};
  for (std::size_t b = 0; b < 16; ++b) {
    for (std::size_t k = 0; k < 4; ++k) t[b][k] = ((b >> k) & 1U) != 0U ? -1 : 0;
  }
  return t;
}();
simd::i32x4 lanes(unsigned bits) {
  simd::i32x4 v;
  std::memcpy(&v, kLanes[bits].data(), sizeof v);
  return v;
}

// The x-y points of a cluster's members into `out` (members.size() of them). A run of four members (most of a
// cluster's) is two loads and two interleaves: one by one this took eight instructions a point.
void footprint_of(const Cloud& cloud, std::span<const std::uint32_t> members, std::array<float, 2>* out) {
  const float* const px = cloud.x.data();
  const float* const py = cloud.y.data();
  const std::size_t m = members.size();
  const bool run_safe = cloud.size() < kRunSafe;  // every member is a point of `cloud`
  std::size_t k = 0;
  for (; k + 4 <= m; k += 4) {
    if (run_safe && run_of_four(members.data() + k)) {
      const simd::f32x4 x = simd::load(px + members[k]), y = simd::load(py + members[k]);
      const simd::f32x4 first = __builtin_shufflevector(x, y, 0, 4, 1, 5),
                        second = __builtin_shufflevector(x, y, 2, 6, 3, 7);
      std::memcpy(out + k, &first, sizeof first);
      std::memcpy(out + k + 2, &second, sizeof second);
    } else {
      const std::uint32_t i0 = members[k], i1 = members[k + 1], i2 = members[k + 2], i3 = members[k + 3];
      out[k] = {px[i0], py[i0]};
      out[k + 1] = {px[i1], py[i1]};
      out[k + 2] = {px[i2], py[i2]};
      out[k + 3] = {px[i3], py[i3]};
    }
  }
  for (; k < m; ++k) out[k] = {px[members[k]], py[members[k]]};
}

// Microseconds from `from` to now, and `from` moved to now.
float lap_us(std::chrono::steady_clock::time_point& from) {
  const auto now = std::chrono::steady_clock::now();
  const float us = std::chrono::duration<float, std::micro>(now - from).count();
  from = now;
  return us;
}

// A cluster the filters found TooFewPoints (check_cluster's first test) is ObstacleHold's evidence when it stands
// as high above its measured ground as an obstacle must (fragments, obstacle.hpp).
void add_fragment(const FilterParams& f, const ClusterSummary& s, std::vector<Fragment>& out) {
  if (s.ground_guessed || static_cast<double>(s.height_above_ground_m) < min_height_at(f, s.distance_m)) return;
  out.push_back(Fragment{s.min, s.max, s.points, s.distance_m, s.height_above_ground_m});
}

}  // namespace

struct Pipeline::Impl {
  explicit Impl(const PipelineParams& p)
      : params(p),
        voxel(p.voxel),
        clusterer(p.cluster),
        absorber(p.cluster.absorb_max_points, p.cluster.absorb_margin_m),
        joiner(ClusterJoinParams::from(p.cluster)),
        splitter(ClusterSplitParams::from(p.cluster)),
        near(p.near_field),
        jitter(BeamGeometry{}.min_spacing_deg(), p.filters.canopy_max_gap_m) {
    if (p.cluster.beam_spacing_deg > 0.0) beams = BeamGeometry::uniform(p.cluster.beam_spacing_deg);
    jitter.set_beams(beams);
    if (p.roi.min[0] >= p.roi.max[0] || p.roi.min[1] >= p.roi.max[1] || p.roi.min[2] >= p.roi.max[2]) {
      throw std::invalid_argument("Pipeline: the ROI box needs min < max on every axis");
    }
    if (p.ground.method == GroundMethod::Ransac) {
      ransac.emplace(p.ground.ransac, p.ground.zones.sensor_height_m);
    } else {
      zones.emplace(p.ground.zones);
    }
  }

  PipelineParams params;
  BeamGeometry beams;  // in force: the configured spacing, or the sensor's (set_beams), or the HDL-32E's
  VoxelGrid voxel;
  std::optional<RansacGround> ransac;
  std::optional<ZoneGround> zones;
  EuclideanClusterer clusterer;
  ClusterAbsorber absorber;
  ClusterJoiner joiner;
  ClusterSplitter splitter;
  NearField near;
  RingJitterMeter jitter;
  Cloud surroundings;                   // check_canopy's scratch
  Buffer<std::uint8_t> surround_marks;  // ... and its marks, one per voxel, left zero

  Cloud cropped, voxels, above;
  GroundLabels ground;
  Buffer<std::uint32_t> above_index;  // index in `voxels` of each point of `above`
  Buffer<float> above_height;
  Buffer<std::uint8_t> above_guessed;
  Clusters clusters;
  Buffer<ClusterBounds> bounds;  // one per cluster
  std::vector<LabeledPoint> labeled;
  Buffer<std::array<float, 2>> footprint;  // filled by index: growing it leaves the new points unset
  std::vector<std::array<float, 2>> hull;
  HullScratch hull_scratch;
  std::vector<LidarPoint> points2d;  // a merged frame's 2D LiDAR points
};

Pipeline::Pipeline(const PipelineParams& params) : impl_(std::make_unique<Impl>(params)) {}
Pipeline::~Pipeline() = default;
Pipeline::Pipeline(Pipeline&&) noexcept = default;
Pipeline& Pipeline::operator=(Pipeline&&) noexcept = default;

const PipelineParams& Pipeline::params() const { return impl_->params; }

bool Pipeline::set_beams(const BeamGeometry& beams) {
  Impl& m = *impl_;
  if (m.params.cluster.beam_spacing_deg > 0.0) return false;
  if (beams == m.beams) return true;
  m.clusterer.set_beams(beams);
  m.jitter.set_beams(beams);
  m.beams = beams;
  return true;
}

const BeamGeometry& Pipeline::beams() const { return impl_->beams; }

std::span<const LabeledPoint> Pipeline::last_points() const { return impl_->labeled; }

float Pipeline::ground_z(float x, float y) const {
  return impl_->ransac ? impl_->ransac->ground_z(x, y) : impl_->zones->ground_z(x, y);
}

FrameResult Pipeline::process(std::span<const LidarPoint> points) {
  FrameResult result;
  process(points, result);
  return result;
}

void Pipeline::process(std::span<const LidarPoint> points, FrameResult& result) {
  Impl& m = *impl_;
  // Over the last frame's result: its vectors keep their room.
  result.obstacles.clear();
  result.fragments.clear();
  result.counts = StageCounts{};
  result.times = StageTimes{};
  const auto start = std::chrono::steady_clock::now();
  auto lap = start;
  // ROI and body box, then the voxel grid. (One pass doing both measured no faster: the cropped cloud stays
  // in cache between the two.) A merged frame's 2D LiDAR points go to the near-field stage only (its one plane
  // of points would be ground, or too few and too low for the 3D filters): the crop sets them aside.
  // The crop keeps the ground stage's context beyond the ROI's far end too; those points are ground or nothing.
  const float roi_far = static_cast<float>(m.params.roi.max[0]);
  Box3 crop = m.params.roi;
  crop.max[0] += m.params.ground.context_m;
  // The crop counts the points within the ROI's far end as it keeps them (not a second pass over them). Without
  // a context band (context_m <= 0) that is every point it keeps: its x limit is then at most roi_far.
  result.counts.after_roi = crop_box(points, crop, m.params.body, m.cropped, m.points2d, roi_far);
  result.counts.input = static_cast<std::uint32_t>(points.size() - m.points2d.size());
  result.times.crop_us = lap_us(lap);
  m.voxel.filter(m.cropped, m.voxels);
  result.times.voxel_us = lap_us(lap);
  const std::size_t n = m.voxels.size();
  result.counts.after_voxel = static_cast<std::uint32_t>(n);

  if (m.ransac) {
    m.ransac->segment(m.voxels, m.ground);
  } else {
    m.zones->segment(m.voxels, m.ground);
  }

  // Everything that is not ground goes on to clustering. (Sized for every point, then cut to those kept: a
  // push_back per array per point was about half this loop's instructions.)
  m.above.resize_xyz(n);
  m.above_index.resize(n);
  m.above_height.resize(n);
  m.above_guessed.resize(n);
  m.labeled.resize(n);
  std::uint32_t ground_count = 0;
  std::size_t kept = 0;
  {
    // Four voxels a turn: their labelled points written as one 4 x 4 transpose, and a run of four kept points
    // (most of them: a frame is mostly not ground) copied as four-wide stores. Done one by one this loop took
    // seventeen instructions a point.
    static_assert(sizeof(LabeledPoint) == 16 && offsetof(LabeledPoint, label) == 12);
    const simd::f32x4 far = simd::splat(roi_far);
    const simd::i32x4 unclustered = simd::splat(static_cast<std::int32_t>(PointLabel::Unclustered));
    static_assert(static_cast<int>(PointLabel::Ground) == 0);  // a ground lane's label is the mask's zero
    simd::i32x4 minus_ground = simd::splat(std::int32_t{0});   // a ground lane is -1
    const simd::i32x4 step = simd::splat(std::int32_t{4});
    simd::i32x4 index{0, 1, 2, 3};
    for (std::size_t i = 0; i + 4 <= n; i += 4, index += step) {
      simd::f32x4 x = simd::load(m.voxels.x.data() + i), y = simd::load(m.voxels.y.data() + i),
                  z = simd::load(m.voxels.z.data() + i);
      // The four ground flags as four bits: a byte's top bit set where it is nonzero, the four top bits gathered
      // by one multiplication (their copies land on distinct bits, so nothing carries into bits 21 to 24).
      std::uint32_t g4 = 0;
      std::memcpy(&g4, m.ground.ground.data() + i, sizeof g4);
      const std::uint32_t nonzero = (((g4 & 0x7F7F7F7FU) + 0x7F7F7F7FU) | g4) & 0x80808080U;
      const unsigned ground4 = (((nonzero >> 7U) * 0x00204081U) >> 21U) & 0xFU;
      const simd::i32x4 g = lanes(ground4);
      minus_ground += g;
      const unsigned keep =
          ~(ground4 | simd::mask_bits(x > far)) & 0xFU;  // not ground, nor beyond the ROI (NaN is not)
      if (keep == 0xFU) {
        std::memcpy(m.above.x.data() + kept, &x, sizeof x);
        std::memcpy(m.above.y.data() + kept, &y, sizeof y);
        std::memcpy(m.above.z.data() + kept, &z, sizeof z);
        std::memcpy(m.above_index.data() + kept, &index, sizeof index);
        std::memcpy(m.above_height.data() + kept, m.ground.height_m.data() + i, 4 * sizeof(float));
        std::memcpy(m.above_guessed.data() + kept, m.ground.guessed.data() + i, 4);
        kept += 4;
      } else {
        for (unsigned rest = keep; rest != 0U; rest &= rest - 1U) {
          const std::size_t v = i + static_cast<unsigned>(__builtin_ctz(rest));
          m.above.x[kept] = m.voxels.x[v];
          m.above.y[kept] = m.voxels.y[v];
          m.above.z[kept] = m.voxels.z[v];
          m.above_index[kept] = static_cast<std::uint32_t>(v);
          m.above_height[kept] = m.ground.height_m[v];
          m.above_guessed[kept] = m.ground.guessed[v];
          ++kept;
        }
      }
      simd::f32x4 label = std::bit_cast<simd::f32x4>(unclustered & ~g);
      simd::transpose4(x, y, z, label);
      std::memcpy(static_cast<void*>(m.labeled.data() + i), &x, sizeof x);
      std::memcpy(static_cast<void*>(m.labeled.data() + i + 1), &y, sizeof y);
      std::memcpy(static_cast<void*>(m.labeled.data() + i + 2), &z, sizeof z);
      std::memcpy(static_cast<void*>(m.labeled.data() + i + 3), &label, sizeof label);
    }
    for (int k = 0; k < 4; ++k) ground_count += static_cast<std::uint32_t>(-minus_ground[k]);
  }
  for (std::size_t i = n - n % 4; i < n; ++i) {
    const bool g = m.ground.ground[i] != 0U;
    const float x = m.voxels.x[i], y = m.voxels.y[i], z = m.voxels.z[i];
    m.labeled[i] = LabeledPoint{x, y, z, g ? PointLabel::Ground : PointLabel::Unclustered};
    if (g) {
      ++ground_count;
      continue;
    }
    if (x > roi_far) continue;  // ground context only
    m.above.x[kept] = x;
    m.above.y[kept] = y;
    m.above.z[kept] = z;
    m.above_index[kept] = static_cast<std::uint32_t>(i);
    m.above_height[kept] = m.ground.height_m[i];
    m.above_guessed[kept] = m.ground.guessed[i];
    ++kept;
  }
  m.above.resize_xyz(kept);
  m.above_index.resize(kept);
  m.above_height.resize(kept);
  m.above_guessed.resize(kept);
  result.counts.ground = ground_count;
  result.times.ground_us = lap_us(lap);

  m.clusterer.extract(m.above, m.clusters);
  result.times.cluster_us = lap_us(lap);
  // Each cluster's summary figures in one pass, merged along by the absorber and the joiner (a pass over the
  // clusters' points each took about a tenth of the cluster stages); a cut cluster's are found again.
  bound_clusters(m.above, m.above_height, m.above_guessed, m.clusters, m.bounds);
  m.absorber.absorb(m.above, m.clusters, &m.bounds);
  m.joiner.join(m.above, m.above_height, m.params.filters, m.clusters, &m.bounds);
  if (m.splitter.split(m.above, m.clusterer, m.clusters) > 0) {
    bound_clusters(m.above, m.above_height, m.above_guessed, m.clusters, m.bounds);
  }

  result.times.merge_us = lap_us(lap);

  const FilterParams& f = m.params.filters;
  if (f.canopy_surroundings_m > 0.0 && m.surround_marks.size() != n) m.surround_marks.assign(n, 0U);
  const FrameSurroundings around{m.voxels, m.ground.height_m, m.above_index, m.surround_marks};
  const std::uint32_t least_points = least_min_points(f);
  const bool fragments = m.params.hold.enabled;
  for (std::size_t c = 0; c < m.clusters.size(); ++c) {
    const auto members = m.clusters[c];
    // Most clusters are a return or two, too few for any distance: TooFewPoints below whatever their summary.
    if (members.size() < least_points) {
      if (fragments) {
        add_fragment(f, summary_of(m.bounds[c], static_cast<std::uint32_t>(members.size())), result.fragments);
      }
      continue;
    }
    ClusterSummary s = summary_of(m.bounds[c], static_cast<std::uint32_t>(members.size()));
    Rejection why = check_cluster(f, s);
    if (fragments && why == Rejection::TooFewPoints) add_fragment(f, s, result.fragments);
    if (s.ground_guessed && why == Rejection::Kept) {
      // No ground measured under it: its height is what it shows, from the lowest point under its footprint
      // (ground-labelled points under it may be its own feet) to its top. (Only a kept cluster can change:
      // this lowers the height.)
      constexpr float kMargin = 0.25F;  // m around the footprint
      float floor_z = s.min[2];
      for (std::size_t i = 0; i < n; ++i) {
        if (m.ground.ground[i] == 0U) continue;
        const float x = m.voxels.x[i], y = m.voxels.y[i];
        if (x >= s.min[0] - kMargin && x <= s.max[0] + kMargin && y >= s.min[1] - kMargin && y <= s.max[1] + kMargin) {
          floor_z = std::min(floor_z, m.voxels.z[i]);
        }
      }
      limit_height_to_extent(s, floor_z);
      why = check_cluster(f, s);
    }
    if (why == Rejection::Kept) why = check_canopy(f, s, m.above, members, m.jitter, &around, &m.surroundings);
    // Too few points for its distance: not a cluster at all (PCL's minimum cluster size), left unclustered.
    if (why == Rejection::TooFewPoints) continue;
    ++result.counts.clusters;
    const PointLabel label = why == Rejection::Kept ? PointLabel::Obstacle : PointLabel::Rejected;
    for (const std::uint32_t i : members) m.labeled[m.above_index[i]].label = label;
    if (why != Rejection::Kept) continue;

    Obstacle o;
    o.min = s.min;
    o.max = s.max;
    o.points = s.points;
    o.distance_m = s.distance_m;
    o.height_above_ground_m = s.height_above_ground_m;
    const float cx = 0.5F * (s.min[0] + s.max[0]), cy = 0.5F * (s.min[1] + s.max[1]);
    o.bearing_deg =
        static_cast<float>(std::atan2(static_cast<double>(cy), static_cast<double>(cx)) * 180.0 / std::numbers::pi);
    // Sized once and filled by index: push_back's capacity check per point was a tenth of the box work.
    m.footprint.resize(members.size());
    footprint_of(m.above, members, m.footprint.data());
    const OrientedRect r = min_area_rect(m.footprint, m.hull, m.hull_scratch);
    o.obb_center = r.center;
    o.obb_length_m = r.length_m;
    o.obb_width_m = r.width_m;
    o.obb_yaw_rad = r.yaw_rad;
    o.size_class = size_class(r.length_m, r.width_m, s.max[2] - s.min[2]);
    result.obstacles.push_back(o);
  }
  result.counts.obstacles = static_cast<std::uint32_t>(result.obstacles.size());
  result.counts.fragments = static_cast<std::uint32_t>(result.fragments.size());
  result.times.boxes_us = lap_us(lap);

  result.counts.near_input = static_cast<std::uint32_t>(m.points2d.size());
  if (m.params.near_field.enabled && !m.points2d.empty()) {
    // Against the ground this frame's 3D points just gave.
    const NearField::Counts nc = m.near.detect(
        m.points2d, [this](float x, float y) { return ground_z(x, y); }, result.obstacles);
    result.counts.near_in_zone = nc.in_zone;
    result.counts.near_obstacles = nc.obstacles;
    result.counts.near_merged =
        m.near.fuse(result.obstacles, result.counts.obstacles, static_cast<float>(m.params.cluster.tolerance_m));
  }

  sort_obstacles(result.obstacles);
  result.times.near_us = lap_us(lap);
  result.times.total_us = std::chrono::duration<float, std::micro>(lap - start).count();
}

}  // namespace fieldguard::perception
