#include "fieldguard/geo/attitude.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace fieldguard::geo {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

bool finite_mounting(const Mounting& m) {
  return std::isfinite(m.x_m) && std::isfinite(m.y_m) && std::isfinite(m.z_m) && std::isfinite(m.roll_deg) &&
         std::isfinite(m.pitch_deg) && std::isfinite(m.yaw_deg);
}

}  // namespace

Eigen::Matrix3d rotation_rpy(double roll_rad, double pitch_rad, double yaw_rad) {
  return (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Quaterniond quaternion_of(const EulerDeg& e) {
  return Eigen::AngleAxisd(e.yaw_deg * kDeg, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(e.pitch_deg * kDeg, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(e.roll_deg * kDeg, Eigen::Vector3d::UnitX());
}

EulerDeg euler_of(const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
  // R = Rz Ry Rx: r20 = -sin(pitch), r21 = cos(pitch) sin(roll), r22 = cos(pitch) cos(roll),
  // r10 = cos(pitch) sin(yaw), r00 = cos(pitch) cos(yaw).
  EulerDeg e;
  e.pitch_deg = std::asin(std::clamp(-r(2, 0), -1.0, 1.0)) / kDeg;
  e.roll_deg = std::atan2(r(2, 1), r(2, 2)) / kDeg;
  e.yaw_deg = std::atan2(r(1, 0), r(0, 0)) / kDeg;
  return e;
}

Eigen::Isometry3d transform_of(const Mounting& m) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = rotation_rpy(m.roll_deg * kDeg, m.pitch_deg * kDeg, m.yaw_deg * kDeg);
  t.translation() = Eigen::Vector3d(m.x_m, m.y_m, m.z_m);
  return t;
}

EulerDeg enu_from_ned(const EulerDeg& ned) {
  // R_enu = T R_ned D with T = Rz(90) D the NED -> ENU axes and D = Rx(180) the FLU -> FRD body axes;
  // D Rz(a) D = Rz(-a), D Ry(b) D = Ry(-b), D Rx(c) D = Rx(c), so R_enu = Rz(90 - yaw) Ry(-pitch) Rx(roll).
  return {ned.roll_deg, -ned.pitch_deg, 90.0 - ned.yaw_deg};
}

double yaw_from_heading_deg(double heading_deg) { return 90.0 - heading_deg; }

std::vector<std::string> AhrsParams::validate() const {
  std::vector<std::string> problems;
  if (frame != AhrsFrame::Enu && frame != AhrsFrame::Ned) problems.emplace_back("frame: must be ENU or NED");
  if (!finite_mounting(mounting)) problems.emplace_back("mounting: every value must be a finite number");
  if (std::fabs(mounting.roll_deg) > 180.0 || std::fabs(mounting.pitch_deg) > 90.0 ||
      std::fabs(mounting.yaw_deg) > 180.0) {
    problems.emplace_back("mounting: roll and yaw must be within +-180 deg, pitch within +-90 deg");
  }
  if (!std::isfinite(declination_deg) || std::fabs(declination_deg) > 180.0) {
    problems.emplace_back("declination_deg: must be within +-180 deg (east positive)");
  }
  return problems;
}

AttitudeModel::AttitudeModel(const AhrsParams& params) : params_(params) {
  const auto problems = params.validate();
  if (!problems.empty()) {
    std::string msg = "invalid AHRS parameters:";
    for (const auto& p : problems) msg += "\n  " + p;
    throw std::invalid_argument(msg);
  }
  const Mounting& m = params.mounting;
  vehicle_from_ahrs_inv_ = quaternion_of({m.roll_deg, m.pitch_deg, m.yaw_deg}).conjugate();
}

Eigen::Quaterniond AttitudeModel::vehicle_in_plane(const EulerDeg& ahrs, double convergence_deg) const {
  EulerDeg enu = params_.frame == AhrsFrame::Ned ? enu_from_ned(ahrs) : ahrs;
  // Magnetic -> true: heading + D, so ENU yaw - D. True -> grid: heading - gamma, so ENU yaw + gamma.
  enu.yaw_deg += convergence_deg - params_.declination_deg;
  // R_plane<-vehicle = R_plane<-ahrs * R_ahrs<-vehicle.
  return (quaternion_of(enu) * vehicle_from_ahrs_inv_).normalized();
}

Eigen::Vector3d reference_from_antenna(const Eigen::Vector3d& antenna_plane, const Eigen::Quaterniond& vehicle_in_plane,
                                       const Eigen::Vector3d& lever_arm_vehicle) {
  return antenna_plane - vehicle_in_plane * lever_arm_vehicle;
}

double horizontal_yaw_rad(const Eigen::Quaterniond& vehicle_in_plane) {
  const Eigen::Vector3d x = vehicle_in_plane * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}

}  // namespace fieldguard::geo
