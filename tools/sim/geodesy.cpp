#include "sim/geodesy.hpp"

#include <cmath>

namespace fieldguard::sim {

namespace {

constexpr double kA = 6378137.0;            // WGS84 semi-major axis, m
constexpr double kF = 1.0 / 298.257223563;  // flattening
constexpr double kE2 = kF * (2.0 - kF);     // first eccentricity squared

Vec3 ecef_of(const Geodetic& g) {
  const double lat = g.lat_deg * kDegToRad;
  const double lon = g.lon_deg * kDegToRad;
  const double n = kA / std::sqrt(1.0 - kE2 * std::sin(lat) * std::sin(lat));
  return {(n + g.h_m) * std::cos(lat) * std::cos(lon), (n + g.h_m) * std::cos(lat) * std::sin(lon),
          (n * (1.0 - kE2) + g.h_m) * std::sin(lat)};
}

// Iterates the latitude from the ECEF position; converges to far below a micrometre in a few steps
// anywhere near the earth's surface.
Geodetic geodetic_of(Vec3 p) {
  const double lon = std::atan2(p.y, p.x);
  const double r = std::hypot(p.x, p.y);
  double lat = std::atan2(p.z, r * (1.0 - kE2));
  double h = 0.0;
  for (int i = 0; i < 6; ++i) {
    const double s = std::sin(lat);
    const double n = kA / std::sqrt(1.0 - kE2 * s * s);
    h = r / std::cos(lat) - n;
    lat = std::atan2(p.z, r * (1.0 - kE2 * n / (n + h)));
  }
  return {lat / kDegToRad, lon / kDegToRad, h};
}

}  // namespace

FieldPlacement::FieldPlacement(Geodetic origin, double heading_deg)
    : origin_(origin), heading_deg_(heading_deg), origin_ecef_(ecef_of(origin)) {
  const double lat = origin.lat_deg * kDegToRad;
  const double lon = origin.lon_deg * kDegToRad;
  const double sl = std::sin(lat);
  const double cl = std::cos(lat);
  const double so = std::sin(lon);
  const double co = std::cos(lon);
  // Columns: east, north, up in ECEF.
  enu_to_ecef_ = Mat3{{-so, -sl * co, cl * co, co, -sl * so, cl * so, 0.0, cl, sl}};
}

Vec3 FieldPlacement::enu_of(Vec3 w) const {
  const double psi = heading_deg_ * kDegToRad;
  // World x points at heading psi (east = sin, north = cos); world y is 90 deg to its left.
  return {w.x * std::sin(psi) - w.y * std::cos(psi), w.x * std::cos(psi) + w.y * std::sin(psi), w.z};
}

Geodetic FieldPlacement::to_geodetic(Vec3 world) const {
  return geodetic_of(origin_ecef_ + enu_to_ecef_ * enu_of(world));
}

}  // namespace fieldguard::sim
