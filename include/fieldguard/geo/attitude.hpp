#pragma once
// Attitude: rotations from roll, pitch, yaw; the AHRS-to-vehicle mounting; the AHRS's heading reference
// turned into the plane (grid) frame; the antenna lever arm.
//
// Frames (all right-handed):
//   vehicle  x forward, y left, z up; origin on the ground below the rear axle centre (core/mounting.hpp)
//   plane    x east (grid), y north (grid), z up: Gauss-Krueger easting, northing, height (projection.hpp)
//   level    the vehicle frame turned so z is vertical: origin at the vehicle reference point at a chosen
//            time, x the vehicle's heading projected on the horizontal, z up (deskew.hpp)
//
// Rotation convention: R = Rz(yaw) Ry(pitch) Rx(roll) takes a vector from the rotated frame to the
// reference frame (the aerospace Z-Y'-X'' sequence Xsens outputs). In the vehicle frame: positive roll
// lowers the right (-y) side, positive pitch lowers the nose, positive yaw turns left.
//
// Yaw reference. In the plane frame yaw is measured from grid east, counter-clockwise seen from above
// (Xsens' default ENU output: yaw 90 deg when the sensor's x axis points north, MTi User Manual
// MT0605P, "Interpretation of yaw as heading"). A compass heading (clockwise from north, NMEA HDT) is
// yaw = 90 deg - heading. Xsens' NED output (data id | 0x4) is converted by enu_from_ned(). An AHRS
// without GNSS (MTi-300) references magnetic north: the declination (east positive) turns it to true
// north, the meridian convergence (projection.hpp) to grid north.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "fieldguard/core/mounting.hpp"

namespace fieldguard::geo {

struct EulerDeg {
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double yaw_deg = 0.0;
};

[[nodiscard]] Eigen::Matrix3d rotation_rpy(double roll_rad, double pitch_rad, double yaw_rad);
[[nodiscard]] Eigen::Quaterniond quaternion_of(const EulerDeg& e);
// Inverse of quaternion_of away from pitch +-90 deg; yaw in (-180, 180].
[[nodiscard]] EulerDeg euler_of(const Eigen::Quaterniond& q);

// A sensor's mounting as a transform sensor frame -> vehicle frame: p_vehicle = R p_sensor + t.
[[nodiscard]] Eigen::Isometry3d transform_of(const Mounting& m);

// Xsens NED output (local frame north-east-down, sensor frame x forward, y right, z down) to the ENU
// convention above (x forward, y left, z up): roll stays, pitch and yaw change sign, yaw turns by 90 deg.
[[nodiscard]] EulerDeg enu_from_ned(const EulerDeg& ned);
// Compass heading (clockwise from north, deg) -> ENU yaw (counter-clockwise from east, deg).
[[nodiscard]] double yaw_from_heading_deg(double heading_deg);

enum class AhrsFrame : std::uint8_t { Enu = 0, Ned = 1 };

struct AhrsParams {
  AhrsFrame frame = AhrsFrame::Enu;  // what the AHRS was configured to output
  // The AHRS's orientation on the vehicle (only roll/pitch/yaw are used; position does not matter for a
  // rotation). Identity = its x forward, y left, z up.
  Mounting mounting;
  // Magnetic declination, deg, east positive: true heading = magnetic heading + declination. 0 when the
  // AHRS already references true north (GNSS-aided) or the field is small and a constant offset is fine.
  double declination_deg = 0.0;

  [[nodiscard]] std::vector<std::string> validate() const;
};

// The vehicle's attitude (vehicle frame -> plane frame) from one AHRS Euler sample as the AHRS outputs
// it, with the meridian convergence of the place (PlaneCoord::convergence_deg; 0 if unknown).
// Thread-compatible: holds precomputed rotations.
class AttitudeModel {
 public:
  explicit AttitudeModel(const AhrsParams& params);  // throws std::invalid_argument when invalid
  [[nodiscard]] Eigen::Quaterniond vehicle_in_plane(const EulerDeg& ahrs, double convergence_deg) const;
  [[nodiscard]] const AhrsParams& params() const { return params_; }

 private:
  AhrsParams params_;
  Eigen::Quaterniond vehicle_from_ahrs_inv_;  // R_ahrs<-vehicle
};

// The antenna's lever arm: the reference point (vehicle origin) in the plane frame from the antenna's
// position there, the vehicle attitude and the antenna's position in the vehicle frame:
// reference = antenna - R * lever_arm.
[[nodiscard]] Eigen::Vector3d reference_from_antenna(const Eigen::Vector3d& antenna_plane,
                                                     const Eigen::Quaterniond& vehicle_in_plane,
                                                     const Eigen::Vector3d& lever_arm_vehicle);

// Heading of the vehicle's x axis projected on the horizontal, rad, counter-clockwise from plane x.
[[nodiscard]] double horizontal_yaw_rad(const Eigen::Quaterniond& vehicle_in_plane);

}  // namespace fieldguard::geo
