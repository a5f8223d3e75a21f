#include "fieldguard/geo/scan_lift.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "fieldguard/geo/attitude.hpp"

namespace fieldguard::geo {

namespace {

bool finite(const Mounting& m) {
  return std::isfinite(m.x_m) && std::isfinite(m.y_m) && std::isfinite(m.z_m) && std::isfinite(m.roll_deg) &&
         std::isfinite(m.pitch_deg) && std::isfinite(m.yaw_deg);
}

}  // namespace

std::vector<std::string> ScanLiftParams::validate() const {
  std::vector<std::string> problems;
  if (!finite(scanner)) problems.emplace_back("scan2d mounting: every value must be a finite number");
  if (!finite(lidar)) problems.emplace_back("lidar mounting: every value must be a finite number");
  if (!std::isfinite(turn_period_s) || turn_period_s <= 0.0 || turn_period_s > 1.0) {
    problems.emplace_back("turn_period_s: must be > 0 and <= 1 s (UTM-30LX-EW: 0.025)");
  }
  return problems;
}

ScanLifter::ScanLifter(const ScanLiftParams& params) : params_(params) {
  const auto problems = params.validate();
  if (!problems.empty()) {
    std::string msg = "invalid 2D LiDAR lifting parameters:";
    for (const auto& p : problems) msg += "\n  " + p;
    throw std::invalid_argument(msg);
  }
  // p_lidar = T_lidar^-1 T_scanner p_scanner
  const Eigen::Isometry3d m = transform_of(params.lidar).inverse() * transform_of(params.scanner);
  r_ = m.linear();
  t_ = m.translation();
}

ScanLiftStats ScanLifter::lift(const scip::Scan& scan, const scip::Geometry& geometry, float time_offset_s,
                               std::vector<SourcedPoint>& out) const {
  ScanLiftStats stats;
  stats.values = scan.ranges_mm.size();
  out.reserve(out.size() + scan.ranges_mm.size());
  const double step_time_s = params_.turn_period_s / geometry.steps_per_turn;
  for (std::size_t i = 0; i < scan.ranges_mm.size(); ++i) {
    const std::uint32_t mm = scan.ranges_mm[i];
    if (mm < geometry.dmin_mm || mm > geometry.dmax_mm) {
      ++stats.out_of_range;
      continue;
    }
    const std::uint16_t step = scan.step_of(i);
    const double angle = scip::step_angle_rad(static_cast<double>(step), geometry);
    const double r = static_cast<double>(mm) * 1e-3;
    const double sx = r * std::cos(angle);
    const double sy = r * std::sin(angle);
    SourcedPoint p;
    const Eigen::Vector3d v = r_.col(0) * sx + r_.col(1) * sy + t_;
    p.x = static_cast<float>(v.x());
    p.y = static_cast<float>(v.y());
    p.z = static_cast<float>(v.z());
    p.intensity = i < scan.intensities.size() ? static_cast<float>(scan.intensities[i]) : 0.F;
    p.time_s = time_offset_s + static_cast<float>(static_cast<double>(step - scan.first_step) * step_time_s);
    p.channel = step;
    p.source = PointSource::Lidar2d;
    out.push_back(p);
    ++stats.lifted;
  }
  return stats;
}

}  // namespace fieldguard::geo
