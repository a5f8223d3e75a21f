#pragma once
// Where the simulated field lies on the earth: the world frame (x along the tractor's path, y left, z up)
// is a local tangent plane at a geodetic origin, turned so that world x points at a compass heading. Exact
// WGS84 conversions (through ECEF), so the GNSS stream and the truth agree to well below a millimetre.

#include "sim/geometry.hpp"

namespace fieldguard::sim {

struct Geodetic {
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  double h_m = 0.0;  // above the WGS84 ellipsoid
};

class FieldPlacement {
 public:
  // `heading_deg`: compass heading (clockwise from true north) of world +x.
  FieldPlacement(Geodetic origin, double heading_deg);

  [[nodiscard]] Geodetic to_geodetic(Vec3 world) const;
  // East-north-up components of a world vector (a rotation about z).
  [[nodiscard]] Vec3 enu_of(Vec3 world) const;
  [[nodiscard]] double heading_deg() const { return heading_deg_; }
  // The ENU yaw (counter-clockwise from east, deg, as Xsens outputs it) of world +x.
  [[nodiscard]] double enu_yaw_deg() const { return 90.0 - heading_deg_; }
  [[nodiscard]] const Geodetic& origin() const { return origin_; }

 private:
  Geodetic origin_;
  double heading_deg_ = 0.0;
  Vec3 origin_ecef_;
  Mat3 enu_to_ecef_;
};

}  // namespace fieldguard::sim
