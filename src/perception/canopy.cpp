#include "fieldguard/perception/canopy.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

namespace fieldguard::perception {

RingJitterMeter::RingJitterMeter(double ring_spacing_deg, double max_gap_m)
    : group_gap_rad_(static_cast<float>(0.5 * ring_spacing_deg * std::numbers::pi / 180.0)),
      max_gap_m_(static_cast<float>(max_gap_m)) {
  if (!(ring_spacing_deg > 0.0) || !(max_gap_m > 0.0)) {
    throw std::invalid_argument("RingJitterMeter: ring spacing and neighbour gap must be positive");
  }
}

void RingJitterMeter::set_beams(const BeamGeometry& beams) {
  if (beams.is_uniform()) {
    group_gap_rad_ = static_cast<float>(0.5 * beams.min_spacing_deg() * std::numbers::pi / 180.0);
    beams_.reset();
  } else {
    beams_ = beams;
  }
}

RingJitter RingJitterMeter::measure(const Cloud& cloud, std::span<const std::uint32_t> indices) {
  RingJitter out;
  samples_.clear();
  for (const std::uint32_t i : indices) {
    const float x = cloud.x[i], y = cloud.y[i], z = cloud.z[i];
    const float r = std::sqrt(x * x + y * y);
    if (!(r > 0.F)) continue;  // straight above the sensor: no bearing
    samples_.push_back(Sample{std::atan2(z, r), std::atan2(y, x), r});
  }
  if (!samples_.empty()) {
    float r0 = samples_[0].range, r1 = r0, b0 = samples_[0].bearing, b1 = b0;
    double rsum = 0.0;
    for (const Sample& q : samples_) {
      r0 = std::min(r0, q.range);
      r1 = std::max(r1, q.range);
      b0 = std::min(b0, q.bearing);
      b1 = std::max(b1, q.bearing);
      rsum += static_cast<double>(q.range);
    }
    out.depth_m = r1 - r0;
    // (Across the bearing seam behind the sensor the span is nearly a full turn: wide, never a needle.)
    out.width_m = (b1 - b0) * static_cast<float>(rsum / static_cast<double>(samples_.size()));
  }
  std::sort(samples_.begin(), samples_.end(),
            [](const Sample& a, const Sample& b) { return a.elevation < b.elevation; });
  offs_.clear();
  std::size_t g0 = 0;
  while (g0 < samples_.size()) {
    // One ring: elevations without a jump of half the ring spacing.
    std::size_t g1 = g0 + 1;
    const auto gap_at = [&](float elevation) {
      return beams_ ? 0.5F * beams_->spacing_rad(std::sin(elevation)) : group_gap_rad_;
    };
    while (g1 < samples_.size() &&
           samples_[g1].elevation - samples_[g1 - 1].elevation <= gap_at(samples_[g1 - 1].elevation)) {
      ++g1;
    }
    const auto first = samples_.begin() + static_cast<std::ptrdiff_t>(g0);
    const auto last = samples_.begin() + static_cast<std::ptrdiff_t>(g1);
    std::sort(first, last, [](const Sample& a, const Sample& b) { return a.bearing < b.bearing; });
    for (std::size_t k = g0 + 1; k + 1 < g1; ++k) {
      const Sample& a = samples_[k - 1];
      const Sample& m = samples_[k];
      const Sample& b = samples_[k + 1];
      // Neighbours on the ring: near across it (bearing times range), whatever the range does.
      if ((m.bearing - a.bearing) * m.range > max_gap_m_ || (b.bearing - m.bearing) * m.range > max_gap_m_) continue;
      // Off the straight line through the two neighbours, at the middle one's bearing (a face seen obliquely
      // changes range linearly with bearing; the line takes that out).
      const float span = b.bearing - a.bearing;
      const float t = span > 0.F ? (m.bearing - a.bearing) / span : 0.5F;
      offs_.push_back(std::fabs(m.range - (a.range + t * (b.range - a.range))));
    }
    g0 = g1;
  }
  out.triples = static_cast<std::uint32_t>(offs_.size());
  if (offs_.empty()) return out;
  const auto mid = offs_.begin() + static_cast<std::ptrdiff_t>(offs_.size() / 2);
  std::nth_element(offs_.begin(), mid, offs_.end());
  out.median_m = *mid;
  return out;
}

RingJitter RingJitterMeter::measure_all(const Cloud& cloud) {
  all_.resize(cloud.size());
  std::iota(all_.begin(), all_.end(), 0U);
  return measure(cloud, all_);
}

void gather_low_surroundings(const Cloud& cluster_cloud, std::span<const std::uint32_t> members, const Cloud& cloud,
                             std::span<const float> height_m, std::span<const std::uint8_t> skip,
                             const LowSurroundings& around, Cloud& out) {
  if (height_m.size() != cloud.size() || (!skip.empty() && skip.size() != cloud.size())) {
    throw std::invalid_argument("gather_low_surroundings: heights and marks need one value per point");
  }
  out.clear();
  for (const std::uint32_t i : members) out.push_back(cluster_cloud.x[i], cluster_cloud.y[i], cluster_cloud.z[i]);
  const float x0 = around.min[0] - around.radius_m, x1 = around.max[0] + around.radius_m;
  const float y0 = around.min[1] - around.radius_m, y1 = around.max[1] + around.radius_m;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const float x = cloud.x[i], y = cloud.y[i];
    if (x < x0 || x > x1 || y < y0 || y > y1 || !(height_m[i] < around.max_height_m)) continue;
    if (!skip.empty() && skip[i] != 0U) continue;
    out.push_back(x, y, cloud.z[i]);
  }
}

}  // namespace fieldguard::perception
