#include "fieldguard/perception/near_field.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace fieldguard::perception {
namespace {

[[nodiscard]] bool inside(const Box3& b, float x, float y, float z) {
  // Comparisons with NaN are false: a non-finite coordinate is never inside (the zone itself is finite).
  return static_cast<double>(x) >= b.min[0] && static_cast<double>(x) <= b.max[0] &&
         static_cast<double>(y) >= b.min[1] && static_cast<double>(y) <= b.max[1] &&
         static_cast<double>(z) >= b.min[2] && static_cast<double>(z) <= b.max[2];
}

[[nodiscard]] float bearing_deg(const Obstacle& o) {
  const double cx = 0.5 * (static_cast<double>(o.min[0]) + static_cast<double>(o.max[0]));
  const double cy = 0.5 * (static_cast<double>(o.min[1]) + static_cast<double>(o.max[1]));
  return static_cast<float>(std::atan2(cy, cx) * 180.0 / std::numbers::pi);
}

void set_rect(Obstacle& o, const OrientedRect& r) {
  o.obb_center = r.center;
  o.obb_length_m = r.length_m;
  o.obb_width_m = r.width_m;
  o.obb_yaw_rad = r.yaw_rad;
  o.size_class = size_class(r.length_m, r.width_m, o.max[2] - o.min[2]);
}

void add_corners(const Obstacle& o, std::vector<std::array<float, 2>>& pts) {
  const float c = std::cos(o.obb_yaw_rad), s = std::sin(o.obb_yaw_rad);
  const float hl = 0.5F * o.obb_length_m, hw = 0.5F * o.obb_width_m;
  for (const float a : {-hl, hl}) {
    for (const float b : {-hw, hw}) {
      pts.push_back({o.obb_center[0] + a * c - b * s, o.obb_center[1] + a * s + b * c});
    }
  }
}

// Euclidean distance between two axis-aligned footprints (0 when they overlap).
[[nodiscard]] float footprint_gap(const Obstacle& a, const Obstacle& b) {
  const float gx = std::max({0.F, a.min[0] - b.max[0], b.min[0] - a.max[0]});
  const float gy = std::max({0.F, a.min[1] - b.max[1], b.min[1] - a.max[1]});
  return std::hypot(gx, gy);
}

}  // namespace

NearField::NearField(const NearFieldParams& params) : params_(params) {
  for (std::size_t i = 0; i < 3; ++i) {
    if (!(params.zone.min[i] < params.zone.max[i]) || !std::isfinite(params.zone.min[i]) ||
        !std::isfinite(params.zone.max[i])) {
      throw std::invalid_argument("NearField: the zone needs finite min < max on every axis");
    }
  }
  if (!(params.max_gap_m > 0.0) || params.min_points < 1 || !(params.min_height_m >= 0.0)) {
    throw std::invalid_argument("NearField: max_gap_m and min_points must be positive, min_height_m not negative");
  }
}

NearField::Counts NearField::detect(std::span<const LidarPoint> scan, const GroundFn& ground_z,
                                    std::vector<Obstacle>& out) {
  Counts counts;
  const std::size_t before = out.size();
  const float gap2 = static_cast<float>(params_.max_gap_m * params_.max_gap_m);
  const float min_h = static_cast<float>(params_.min_height_m);
  segment_.clear();
  std::uint16_t last_step = 0;
  for (const LidarPoint& p : scan) {
    if (!inside(params_.zone, p.x, p.y, p.z)) continue;
    ++counts.in_zone;
    const float g = ground_z(p.x, p.y);
    if (!(p.z - g >= min_h)) continue;  // ground (or a ground estimate that is not a number)
    if (!segment_.empty()) {
      const Point& q = segment_.back();
      const float dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z;
      if (p.ring <= last_step || dx * dx + dy * dy + dz * dz >= gap2) emit(out);
    }
    segment_.push_back({p.x, p.y, p.z, g});
    last_step = p.ring;
  }
  emit(out);
  counts.obstacles = static_cast<std::uint32_t>(out.size() - before);
  return counts;
}

void NearField::emit(std::vector<Obstacle>& out) {
  if (segment_.size() < static_cast<std::size_t>(params_.min_points)) {
    segment_.clear();
    return;
  }
  constexpr float inf = std::numeric_limits<float>::infinity();
  Obstacle o;
  o.min = {inf, inf, inf};
  o.max = {-inf, -inf, -inf};
  float nearest2 = inf;
  footprint_.clear();
  for (const Point& p : segment_) {
    o.min[0] = std::min(o.min[0], p.x);
    o.min[1] = std::min(o.min[1], p.y);
    o.max[0] = std::max(o.max[0], p.x);
    o.max[1] = std::max(o.max[1], p.y);
    o.min[2] = std::min(o.min[2], p.ground);  // the box stands on the ground, not on the scan line
    o.max[2] = std::max(o.max[2], p.z);
    o.height_above_ground_m = std::max(o.height_above_ground_m, p.z - p.ground);
    nearest2 = std::min(nearest2, p.x * p.x + p.y * p.y);
    footprint_.push_back({p.x, p.y});
  }
  o.points = static_cast<std::uint32_t>(segment_.size());
  o.distance_m = std::sqrt(nearest2);
  o.bearing_deg = bearing_deg(o);
  o.sources = kSeenBy2d;
  set_rect(o, min_area_rect(footprint_, hull_, hull_scratch_));
  out.push_back(o);
  segment_.clear();
}

std::uint32_t NearField::fuse(std::vector<Obstacle>& out, std::size_t first_near, float tolerance_m) {
  first_near = std::min(first_near, out.size());
  std::uint32_t merged = 0;
  std::size_t keep = first_near;
  for (std::size_t k = first_near; k < out.size(); ++k) {
    const Obstacle n = out[k];
    std::size_t best = first_near;
    float best_gap = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < first_near; ++i) {
      const float gap = footprint_gap(out[i], n);
      if (gap < tolerance_m && gap < best_gap) {
        best = i;
        best_gap = gap;
      }
    }
    if (best == first_near) {
      out[keep++] = n;
      continue;
    }
    Obstacle& o = out[best];
    footprint_.clear();
    add_corners(o, footprint_);
    add_corners(n, footprint_);
    for (std::size_t a = 0; a < 3; ++a) {
      o.min[a] = std::min(o.min[a], n.min[a]);
      o.max[a] = std::max(o.max[a], n.max[a]);
    }
    o.points += n.points;
    o.distance_m = std::min(o.distance_m, n.distance_m);
    o.height_above_ground_m = std::max(o.height_above_ground_m, n.height_above_ground_m);
    o.bearing_deg = bearing_deg(o);
    o.sources = static_cast<std::uint8_t>(o.sources | n.sources);
    set_rect(o, min_area_rect(footprint_, hull_, hull_scratch_));
    ++merged;
  }
  out.resize(keep);
  return merged;
}

}  // namespace fieldguard::perception
