#include "fieldguard/writers/geojson.hpp"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>

namespace fieldguard::app {
namespace {

void num(std::string& s, double v, int decimals) {
  char b[40];
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  s += b;
}

}  // namespace

std::string describe(const geo::ProjectionParams& p) {
  std::string s = std::string("Gauss-Krueger, ") + geo::to_string(p.ellipsoid) + ", " +
                  (p.zone_width == geo::ZoneWidth::Three ? "3" : "6") + "-degree zones, ";
  s += p.fixed_zone == 0 ? std::string("each fix in its own zone") : "fixed zone " + std::to_string(p.fixed_zone);
  s += p.zone_prefix ? ", zone prefix on the easting" : ", no zone prefix";
  return s;
}

GeoJsonWriter::GeoJsonWriter(const geo::ProjectionParams& projection, const Mounting& lidar)
    : projection_(projection), lidar_(lidar) {}

GeoJsonWriter::~GeoJsonWriter() {
  if (file_ != nullptr) static_cast<void>(close());
}

bool GeoJsonWriter::open(const std::string& path) {
  path_ = path;
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) {
    error_ = "cannot write " + path + ": " + std::strerror(errno);
    return false;
  }
  // RFC 7946: coordinates are WGS84 longitude, latitude; no "crs" member. Where they came from is ours to say.
  const std::string head =
      R"({"type":"FeatureCollection","fieldguard":{"projection":")" + describe(projection_.params()) +
      R"(","coordinates":"WGS84 longitude, latitude (degrees) of each obstacle's oriented box footprint, from the plane by GeographicLib's reverse projection"},"features":[)";
  if (std::fputs(head.c_str(), file_) < 0) error_ = "cannot write " + path + ": " + std::strerror(errno);
  return error_.empty();
}

bool GeoJsonWriter::frame(const LidarFrame& frame, const perception::FrameResult& result, const FusionInfo* fusion) {
  if (file_ == nullptr || !error_.empty()) return false;
  const auto pose = fusion != nullptr ? detection_pose(*fusion, lidar_) : std::nullopt;
  if (!pose) {
    ++counts_.frames_unplaced;
    return true;
  }
  ++counts_.frames_placed;
  const double c = std::cos(pose->yaw_rad);
  const double s = std::sin(pose->yaw_rad);
  for (const perception::Obstacle& o : result.obstacles) {
    // The footprint's corners counter-clockwise (RFC 7946's exterior ring), in the detection frame, then on the
    // plane (detection_pose), then on the ellipsoid.
    const double cy = std::cos(static_cast<double>(o.obb_yaw_rad));
    const double sy = std::sin(static_cast<double>(o.obb_yaw_rad));
    const double hl = 0.5 * static_cast<double>(o.obb_length_m);
    const double hw = 0.5 * static_cast<double>(o.obb_width_m);
    const std::array<std::array<double, 2>, 4> k = {{{hl, hw}, {-hl, hw}, {-hl, -hw}, {hl, -hw}}};
    std::array<geo::Geodetic, 4> g{};
    bool placed = true;
    for (std::size_t i = 0; i < 4 && placed; ++i) {
      const double x = static_cast<double>(o.obb_center[0]) + cy * k[i][0] - sy * k[i][1];
      const double y = static_cast<double>(o.obb_center[1]) + sy * k[i][0] + cy * k[i][1];
      geo::PlaneCoord p;
      p.easting_m = pose->x_m + c * x - s * y;
      p.northing_m = pose->y_m + s * x + c * y;
      p.up_m = pose->z_m + static_cast<double>(o.min[2]);
      p.zone = pose->plane;
      const auto r = projection_.reverse(p);
      placed = r.has_value();
      if (placed) g[i] = *r;
    }
    if (!placed) continue;
    buf_.clear();
    buf_ += counts_.features == 0 ? "\n" : ",\n";
    buf_ += R"({"type":"Feature","geometry":{"type":"Polygon","coordinates":[[)";
    for (std::size_t i = 0; i <= 4; ++i) {
      const geo::Geodetic& q = g[i % 4];
      buf_ += i == 0 ? "[" : ",[";
      num(buf_, q.lon_deg, 8);  // 8 decimals: about a millimetre
      buf_ += ',';
      num(buf_, q.lat_deg, 8);
      buf_ += ']';
    }
    buf_ += R"(]]},"properties":{"frame":)" + std::to_string(frame.index) + R"(,"stamp":)";
    num(buf_, frame.host_stamp.seconds(), 6);
    buf_ += R"(,"distance_m":)";
    num(buf_, static_cast<double>(o.distance_m), 3);
    buf_ += R"(,"height_m":)";
    num(buf_, static_cast<double>(o.height_above_ground_m), 3);
    buf_ += R"(,"ground_up_m":)";
    num(buf_, g[0].h_m, 3);
    buf_ += R"(,"class":")";
    buf_ += perception::to_string(o.size_class);
    buf_ += o.held ? R"(","held":true}})" : R"(","held":false}})";
    if (std::fputs(buf_.c_str(), file_) < 0) {
      error_ = "cannot write " + path_ + ": " + std::strerror(errno);
      return false;
    }
    ++counts_.features;
  }
  return true;
}

bool GeoJsonWriter::close() {
  if (file_ == nullptr) return error_.empty();
  if (std::fputs("\n]}\n", file_) < 0 && error_.empty()) error_ = "cannot write " + path_ + ": " + std::strerror(errno);
  if (std::fclose(file_) != 0 && error_.empty()) error_ = "cannot write " + path_ + ": " + std::strerror(errno);
  file_ = nullptr;
  return error_.empty();
}

}  // namespace fieldguard::app
