// The `sync:` and `geo:` sections: frame cutting and pose compensation.

#include "config/section_readers.hpp"

namespace fieldguard::app {

void read_sync(YamlReader& r, const YAML::Node& n, SyncConfig& c) {
  const std::string path = "sync";
  if (!r.section(n, path, {"rate_hz", "timeout_s", "max_scan_offset_s", "max_pending", "pose"})) return;
  // The limits are sync::AssemblerParams' own: a value the loader accepts never makes the synchronizer throw.
  r.number(n, path, "rate_hz", c.rate_hz, 0.5, 50.0, "Hz");
  r.number(n, path, "timeout_s", c.timeout_s, 0.01, 10.0, "s");
  r.number(n, path, "max_scan_offset_s", c.max_scan_offset_s, 0.001, 1.0, "s");
  r.integer(n, path, "max_pending", c.max_pending, 1, 64);
  if (auto p = r.choice(n, path, "pose", {"extrapolate", "wait"})) c.extrapolate_pose = *p == 0;
}

void read_geo(YamlReader& r, const YAML::Node& n, GeoConfig& c) {
  const std::string path = "geo";
  if (!r.section(n, path,
                 {"ellipsoid", "zone_width_deg", "fixed_zone", "zone_prefix", "antenna_m", "ahrs_frame",
                  "declination_deg", "min_gnss_quality", "max_attitude_gap_s", "max_position_gap_s"})) {
    return;
  }
  if (auto e = r.choice(n, path, "ellipsoid", {"WGS84", "CGCS2000", "Krasovsky"})) {
    c.projection.ellipsoid = *e == 0   ? geo::Ellipsoid::Wgs84
                             : *e == 1 ? geo::Ellipsoid::Cgcs2000
                                       : geo::Ellipsoid::Krasovsky1940;
  }
  if (auto w = r.choice(n, path, "zone_width_deg", {"3", "6"})) {
    c.projection.zone_width = *w == 0 ? geo::ZoneWidth::Three : geo::ZoneWidth::Six;
  }
  r.integer(n, path, "fixed_zone", c.projection.fixed_zone, 0, 120);
  if (auto p = r.choice(n, path, "zone_prefix", {"false", "true"})) c.projection.zone_prefix = *p == 1;
  r.vec3(n, path, "antenna_m", c.antenna_m, -20.0, 20.0, "m, vehicle frame");
  if (auto f = r.choice(n, path, "ahrs_frame", {"enu", "ned"}))
    c.ahrs_frame = *f == 0 ? geo::AhrsFrame::Enu : geo::AhrsFrame::Ned;
  r.number(n, path, "declination_deg", c.declination_deg, -180.0, 180.0, "degrees");
  r.integer(n, path, "min_gnss_quality", c.min_gnss_quality, 1, 5);
  r.number(n, path, "max_attitude_gap_s", c.max_attitude_gap_s, 0.001, 5.0, "s");
  r.number(n, path, "max_position_gap_s", c.max_position_gap_s, 0.01, 10.0, "s");
  // The zone's upper limit depends on the width: 120 three-degree zones, 60 six-degree ones.
  const int top = c.projection.zone_width == geo::ZoneWidth::Six ? 60 : 120;
  if (c.projection.fixed_zone > top) {
    r.issue(n["fixed_zone"] ? n["fixed_zone"] : n, "geo.fixed_zone",
            "must be 0 (the zone of each fix's longitude) or 1.." + std::to_string(top) + " for " +
                std::to_string(static_cast<int>(c.projection.zone_width)) + "-degree zones");
  }
}

}  // namespace fieldguard::app
