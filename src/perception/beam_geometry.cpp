#include "fieldguard/perception/beam_geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

namespace fieldguard::perception {

namespace {
constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr double kHdl32eSpacingDeg = 1.33;
constexpr double kEvenWithinDeg = 0.05;
}  // namespace

BeamGeometry::BeamGeometry() : min_deg_(kHdl32eSpacingDeg), max_deg_(kHdl32eSpacingDeg) { tabulate(); }

BeamGeometry BeamGeometry::uniform(double spacing_deg) {
  if (!(spacing_deg > 0.0 && spacing_deg < 45.0)) {
    throw std::invalid_argument("BeamGeometry: a ring spacing must be above 0 and below 45 degrees");
  }
  BeamGeometry g;
  g.min_deg_ = g.max_deg_ = spacing_deg;
  g.tabulate();
  return g;
}

BeamGeometry::BeamGeometry(std::span<const double> ring_elevations_deg)
    : rings_(ring_elevations_deg.begin(), ring_elevations_deg.end()) {
  std::sort(rings_.begin(), rings_.end());
  rings_.erase(std::unique(rings_.begin(), rings_.end()), rings_.end());
  if (rings_.size() < 2 ||
      !std::all_of(rings_.begin(), rings_.end(), [](double e) { return std::isfinite(e) && std::abs(e) <= 90.0; })) {
    throw std::invalid_argument("BeamGeometry: needs at least two distinct ring elevations within +-90 degrees");
  }
  std::vector<double> gaps;
  for (std::size_t i = 1; i < rings_.size(); ++i) gaps.push_back(rings_[i] - rings_[i - 1]);
  std::sort(gaps.begin(), gaps.end());
  min_deg_ = gaps.front();
  max_deg_ = gaps.back();
  // Even rings up to a table's rounding (the HDL-32E's nominal gaps are 1.33 and 1.34 degrees): one spacing, the
  // median gap, as for a configured one.
  if (max_deg_ - min_deg_ <= kEvenWithinDeg) min_deg_ = max_deg_ = gaps[gaps.size() / 2];
  tabulate();
}

double BeamGeometry::spacing_deg(double elevation_deg) const {
  if (is_uniform()) return min_deg_;
  // The ring nearest the elevation, then the larger gap beside it.
  const auto above = std::lower_bound(rings_.begin(), rings_.end(), elevation_deg);
  std::size_t k = static_cast<std::size_t>(above - rings_.begin());
  if (k == rings_.size() || (k > 0 && elevation_deg - rings_[k - 1] < rings_[k] - elevation_deg)) --k;
  const double below_gap = k > 0 ? rings_[k] - rings_[k - 1] : rings_[1] - rings_[0];
  const double above_gap = k + 1 < rings_.size() ? rings_[k + 1] - rings_[k] : below_gap;
  return std::max(below_gap, above_gap);
}

void BeamGeometry::tabulate() {
  tan_by_sin_.resize(kBins);
  rad_by_sin_.resize(kBins);
  for (unsigned b = 0; b < kBins; ++b) {
    const double s = std::clamp((b + 0.5) / static_cast<double>(kHalfBins) - 1.0, -1.0, 1.0);
    const double spacing_rad = spacing_deg(std::asin(s) / kRadPerDeg) * kRadPerDeg;
    tan_by_sin_[b] = static_cast<float>(std::tan(spacing_rad));
    rad_by_sin_[b] = static_cast<float>(spacing_rad);
  }
}

std::string BeamGeometry::describe() const {
  std::array<char, 160> buf{};
  if (rings_.empty()) {
    std::snprintf(buf.data(), buf.size(), "%.2f deg apart everywhere", min_deg_);
  } else if (is_uniform()) {
    std::snprintf(buf.data(), buf.size(), "%zu rings from %.2f to %.2f deg, %.2f deg apart", rings_.size(),
                  rings_.front(), rings_.back(), min_deg_);
  } else {
    std::snprintf(buf.data(), buf.size(), "%zu rings from %.2f to %.2f deg, %.2f to %.2f deg apart", rings_.size(),
                  rings_.front(), rings_.back(), min_deg_, max_deg_);
  }
  return buf.data();
}

}  // namespace fieldguard::perception
