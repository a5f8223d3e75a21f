#include "geo/transverse_mercator.hpp"

#include <GeographicLib/TransverseMercator.hpp>

namespace fieldguard::geo::detail {

struct TransverseMercator::Impl {
  GeographicLib::TransverseMercator tm;
};

TransverseMercator::TransverseMercator(double a_m, double f, double k0)
    : impl_(std::make_unique<Impl>(Impl{GeographicLib::TransverseMercator(a_m, f, k0)})) {}

TransverseMercator::~TransverseMercator() = default;
TransverseMercator::TransverseMercator(TransverseMercator&&) noexcept = default;
TransverseMercator& TransverseMercator::operator=(TransverseMercator&&) noexcept = default;

TmXY TransverseMercator::forward(double lon0_deg, double lat_deg, double lon_deg) const {
  TmXY r;
  impl_->tm.Forward(lon0_deg, lat_deg, lon_deg, r.x_m, r.y_m, r.convergence_deg, r.scale);
  return r;
}

TmLatLon TransverseMercator::reverse(double lon0_deg, double x_m, double y_m) const {
  TmLatLon r;
  impl_->tm.Reverse(lon0_deg, x_m, y_m, r.lat_deg, r.lon_deg, r.convergence_deg, r.scale);
  return r;
}

}  // namespace fieldguard::geo::detail
