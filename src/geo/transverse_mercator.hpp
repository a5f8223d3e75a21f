#pragma once
// Private: the transverse Mercator of any ellipsoid and central scale, the one code path GaussKrueger
// projects with (GeographicLib's 6th-order Krueger series). Exposed to the tests so they can hold it to
// GeographicLib's own published test points, which use other ellipsoids and scales than ours.

#include <memory>

namespace fieldguard::geo::detail {

struct TmXY {
  double x_m = 0.0;  // easting from the central meridian, no false easting
  double y_m = 0.0;  // northing from the equator
  double convergence_deg = 0.0;
  double scale = 1.0;
};

struct TmLatLon {
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  double convergence_deg = 0.0;
  double scale = 1.0;
};

class TransverseMercator {
 public:
  TransverseMercator(double a_m, double f, double k0);  // throws GeographicLib's exception on a bad shape
  ~TransverseMercator();
  TransverseMercator(TransverseMercator&& other) noexcept;
  TransverseMercator& operator=(TransverseMercator&& other) noexcept;

  [[nodiscard]] TmXY forward(double lon0_deg, double lat_deg, double lon_deg) const;
  [[nodiscard]] TmLatLon reverse(double lon0_deg, double x_m, double y_m) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldguard::geo::detail
