#include "fieldguard/geo/projection.hpp"

#include <GeographicLib/Math.hpp>
#include <cmath>
#include <stdexcept>

#include "geo/transverse_mercator.hpp"

namespace fieldguard::geo {

namespace {

constexpr double kFalseEasting = 500000.0;
constexpr double kPrefixUnit = 1e6;

// Longitudes west of Greenwich counted east, 0 <= lon < 360, so zone numbers stay positive.
double east_longitude(double lon_deg) {
  double lon = std::fmod(lon_deg, 360.0);
  if (lon < 0.0) lon += 360.0;
  return lon;
}

int max_zone(ZoneWidth width) { return width == ZoneWidth::Three ? 120 : 60; }

}  // namespace

EllipsoidShape shape_of(Ellipsoid e) {
  switch (e) {
    case Ellipsoid::Wgs84: return {6378137.0, 1.0 / 298.257223563};
    case Ellipsoid::Cgcs2000: return {6378137.0, 1.0 / 298.257222101};
    case Ellipsoid::Krasovsky1940: return {6378245.0, 1.0 / 298.3};
  }
  return {};
}

const char* to_string(Ellipsoid e) {
  switch (e) {
    case Ellipsoid::Wgs84: return "WGS84";
    case Ellipsoid::Cgcs2000: return "CGCS2000";
    case Ellipsoid::Krasovsky1940: return "Krasovsky1940";
  }
  return "?";
}

const char* to_string(ProjectionError e) {
  switch (e) {
    case ProjectionError::NotFinite: return "not_finite";
    case ProjectionError::BadLatitude: return "bad_latitude";
    case ProjectionError::BadLongitude: return "bad_longitude";
    case ProjectionError::TooFarFromZone: return "too_far_from_zone";
    case ProjectionError::BadZone: return "bad_zone";
  }
  return "?";
}

int zone_of(double lon_deg, ZoneWidth width) {
  const double lon = east_longitude(lon_deg);
  if (width == ZoneWidth::Three) {
    // Zone 0 (CM 0) is numbered 120 so that 0 can mean "from the longitude" in ProjectionParams.
    const int n = static_cast<int>(std::floor((lon + 1.5) / 3.0)) % 120;
    return n == 0 ? 120 : n;
  }
  return static_cast<int>(std::floor(lon / 6.0)) % 60 + 1;
}

double central_meridian_deg(int zone, ZoneWidth width) {
  const double cm = width == ZoneWidth::Three ? 3.0 * zone : 6.0 * zone - 3.0;
  return cm > 180.0 ? cm - 360.0 : cm;
}

std::vector<std::string> ProjectionParams::validate() const {
  std::vector<std::string> problems;
  if (zone_width != ZoneWidth::Three && zone_width != ZoneWidth::Six) {
    problems.emplace_back("zone_width: must be 3 or 6 (degrees)");
  }
  if (ellipsoid != Ellipsoid::Wgs84 && ellipsoid != Ellipsoid::Cgcs2000 && ellipsoid != Ellipsoid::Krasovsky1940) {
    problems.emplace_back("ellipsoid: must be WGS84, CGCS2000 or Krasovsky1940");
  }
  const int top = max_zone(zone_width == ZoneWidth::Six ? ZoneWidth::Six : ZoneWidth::Three);
  if (fixed_zone < 0 || fixed_zone > top) {
    problems.emplace_back("zone: must be 0 (from the longitude) or 1.." + std::to_string(top) + " for this zone width");
  }
  const double half_width = zone_width == ZoneWidth::Six ? 3.0 : 1.5;
  if (!std::isfinite(max_offset_deg) || max_offset_deg < half_width || max_offset_deg > 35.0) {
    problems.emplace_back("max_offset_deg: must be between half the zone width (" + std::to_string(half_width) +
                          ") and 35 degrees");
  }
  return problems;
}

struct GaussKrueger::Impl {
  detail::TransverseMercator tm;
};

GaussKrueger::GaussKrueger(const ProjectionParams& params) : params_(params) {
  const auto problems = params.validate();
  if (!problems.empty()) {
    std::string msg = "invalid Gauss-Krueger parameters:";
    for (const auto& p : problems) msg += "\n  " + p;
    throw std::invalid_argument(msg);
  }
  const EllipsoidShape s = shape_of(params.ellipsoid);
  impl_ = std::make_unique<Impl>(Impl{detail::TransverseMercator(s.a_m, s.f, 1.0)});
}

GaussKrueger::~GaussKrueger() = default;
GaussKrueger::GaussKrueger(GaussKrueger&&) noexcept = default;
GaussKrueger& GaussKrueger::operator=(GaussKrueger&&) noexcept = default;

Expected<PlaneCoord, ProjectionError> GaussKrueger::forward(const Geodetic& g) const {
  if (!std::isfinite(g.lat_deg) || !std::isfinite(g.lon_deg) || !std::isfinite(g.h_m)) {
    return Unexpected{ProjectionError::NotFinite};
  }
  if (g.lat_deg < -90.0 || g.lat_deg > 90.0) return Unexpected{ProjectionError::BadLatitude};
  if (g.lon_deg < -180.0 || g.lon_deg > 360.0) return Unexpected{ProjectionError::BadLongitude};
  const int zone = params_.fixed_zone != 0 ? params_.fixed_zone : zone_of(g.lon_deg, params_.zone_width);
  const double lon0 = central_meridian_deg(zone, params_.zone_width);
  if (std::fabs(GeographicLib::Math::AngDiff(lon0, g.lon_deg)) > params_.max_offset_deg) {
    return Unexpected{ProjectionError::TooFarFromZone};
  }
  const detail::TmXY xy = impl_->tm.forward(lon0, g.lat_deg, g.lon_deg);
  PlaneCoord out;
  out.convergence_deg = xy.convergence_deg;
  out.scale = xy.scale;
  out.northing_m = xy.y_m;
  out.easting_m = xy.x_m + kFalseEasting + (params_.zone_prefix ? kPrefixUnit * zone : 0.0);
  out.up_m = g.h_m;
  out.zone = zone;
  return out;
}

Expected<Geodetic, ProjectionError> GaussKrueger::reverse(const PlaneCoord& p) const {
  if (!std::isfinite(p.northing_m) || !std::isfinite(p.easting_m) || !std::isfinite(p.up_m)) {
    return Unexpected{ProjectionError::NotFinite};
  }
  const int top = max_zone(params_.zone_width);
  int zone = p.zone != 0 ? p.zone : params_.fixed_zone;
  if (params_.zone_prefix) {
    const double prefix = std::floor(p.easting_m / kPrefixUnit);
    if (prefix < 1.0 || prefix > top) return Unexpected{ProjectionError::BadZone};
    const int from_easting = static_cast<int>(prefix);
    if (zone != 0 && zone != from_easting) return Unexpected{ProjectionError::BadZone};
    zone = from_easting;
  }
  if (zone < 1 || zone > top) return Unexpected{ProjectionError::BadZone};
  const double lon0 = central_meridian_deg(zone, params_.zone_width);
  const double x = p.easting_m - kFalseEasting - (params_.zone_prefix ? kPrefixUnit * zone : 0.0);
  // Beyond a quarter meridian north or a few thousand km east there is no point on the ellipsoid a
  // tractor could stand on; GeographicLib would still answer (near the pole), so bound it here.
  if (std::fabs(p.northing_m) > 1.0002e7 || std::fabs(x) > 2.0e6) return Unexpected{ProjectionError::TooFarFromZone};
  const detail::TmLatLon ll = impl_->tm.reverse(lon0, x, p.northing_m);
  Geodetic g;
  g.lat_deg = ll.lat_deg;
  g.lon_deg = ll.lon_deg;
  g.h_m = p.up_m;
  if (std::fabs(GeographicLib::Math::AngDiff(lon0, g.lon_deg)) > params_.max_offset_deg) {
    return Unexpected{ProjectionError::TooFarFromZone};
  }
  return g;
}

}  // namespace fieldguard::geo
