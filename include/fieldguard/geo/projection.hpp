#pragma once
// GNSS geodetic coordinates -> Gauss-Krueger plane coordinates (transverse Mercator, scale 1 on the central
// meridian, false northing 0, false easting 500 km, optionally the zone number prefixed), and back.
// protocols.md §6. GeographicLib does the projection; no GeographicLib type shows here.
//
// Axes. Geodesy (China, Germany, EPSG axis order north, east) calls the northing X and the easting Y.
// This code never uses bare x/y for plane coordinates: PlaneCoord has northing_m and easting_m, and its
// enu() is (easting, northing, up), the "plane frame" every other geo type uses (ENU: x east, y north,
// z up, right-handed, like Xsens' default local frame).
//
// Grid north is not true north: the meridian convergence (bearing of grid north clockwise from true
// north) is up to ~1 degree at a 3-degree zone's edge in China. A heading measured from true north
// becomes a grid heading by subtracting it (attitude.hpp: grid_yaw_from_true()).
//
// Changing the ellipsoid is not a datum transformation: feed Beijing 1954 latitudes/longitudes to the
// Krasovsky projection, CGCS2000/WGS 84 ones to the others (the lat/lon differ by tens of metres).

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fieldguard/core/expected.hpp"

namespace fieldguard::geo {

enum class Ellipsoid : std::uint8_t { Wgs84 = 0, Cgcs2000 = 1, Krasovsky1940 = 2 };

struct EllipsoidShape {
  double a_m = 0.0;  // semi-major axis
  double f = 0.0;    // flattening itself (1/298.3, not 298.3)
};
[[nodiscard]] EllipsoidShape shape_of(Ellipsoid e);
[[nodiscard]] const char* to_string(Ellipsoid e);

// 3-degree zones: central meridian 3n, n = floor((lon + 1.5) / 3) (0..119 east of Greenwich, China 25..45).
// 6-degree zones: central meridian 6n - 3, n = floor(lon / 6) + 1 (1..60, China 13..23).
// Longitudes west of Greenwich are taken as lon + 360 (zone numbers stay positive, as EPSG's do).
enum class ZoneWidth : std::uint8_t { Three = 3, Six = 6 };
[[nodiscard]] int zone_of(double lon_deg, ZoneWidth width);
[[nodiscard]] double central_meridian_deg(int zone, ZoneWidth width);

struct ProjectionParams {
  Ellipsoid ellipsoid = Ellipsoid::Cgcs2000;
  ZoneWidth zone_width = ZoneWidth::Three;
  // 0: every fix uses the zone its own longitude falls in (a map crossing a zone border then has two
  // zones: PlaneCoord says which). 1..120 (3-degree) or 1..60 (6-degree): always this zone's central
  // meridian, also for fixes outside the zone (a field astride a border stays in one map).
  int fixed_zone = 0;
  // true: easting = zone * 1e6 + 500 000 + offset from the central meridian ("zone n" EPSG variants,
  // e.g. 39 448 688.86 m); false: 500 000 + offset ("CM xxxE" variants).
  bool zone_prefix = false;
  // A fix farther than this from its central meridian is refused (bad fix or wrong fixed zone). The
  // series GeographicLib uses is exact to ~5 nm within 35 degrees; this is a plausibility bound.
  double max_offset_deg = 4.5;

  // Every problem as "key: what is wrong, what to do"; empty when valid.
  [[nodiscard]] std::vector<std::string> validate() const;
};

struct Geodetic {
  double lat_deg = 0.0;  // north positive
  double lon_deg = 0.0;  // east positive
  double h_m = 0.0;      // ellipsoidal height; carried through as "up", not projected
};

struct PlaneCoord {
  double northing_m = 0.0;  // geodesy's X
  double easting_m = 0.0;   // geodesy's Y, with false easting (and zone prefix when configured)
  double up_m = 0.0;        // = Geodetic::h_m
  int zone = 0;
  double convergence_deg = 0.0;  // bearing of grid north clockwise from true north
  double scale = 1.0;            // point scale factor
  // Plane frame: x east, y north, z up.
  [[nodiscard]] Eigen::Vector3d enu() const { return {easting_m, northing_m, up_m}; }
};

enum class ProjectionError : std::uint8_t {
  NotFinite,       // NaN or infinite latitude, longitude or height
  BadLatitude,     // outside -90..90
  BadLongitude,    // outside -180..360
  TooFarFromZone,  // more than max_offset_deg from the central meridian
  BadZone,         // inverse: zone 0 / out of range, or an easting whose prefix contradicts it
};
[[nodiscard]] const char* to_string(ProjectionError e);

// Thread-compatible; const methods may be called from several threads at once.
class GaussKrueger {
 public:
  // Throws std::invalid_argument with validate()'s problems.
  explicit GaussKrueger(const ProjectionParams& params);
  ~GaussKrueger();
  GaussKrueger(GaussKrueger&& other) noexcept;
  GaussKrueger& operator=(GaussKrueger&& other) noexcept;
  GaussKrueger(const GaussKrueger&) = delete;
  GaussKrueger& operator=(const GaussKrueger&) = delete;

  [[nodiscard]] Expected<PlaneCoord, ProjectionError> forward(const Geodetic& g) const;
  // zone: the zone the coordinates belong to. With zone_prefix the easting carries it; pass 0 to take it
  // from there. Convergence and scale are filled as in forward().
  [[nodiscard]] Expected<Geodetic, ProjectionError> reverse(const PlaneCoord& p) const;

  [[nodiscard]] const ProjectionParams& params() const { return params_; }

 private:
  struct Impl;
  ProjectionParams params_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldguard::geo
