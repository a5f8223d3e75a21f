#include "fieldguard/writers/pcd_writer.hpp"

#define PCL_NO_PRECOMPILE
#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

namespace fieldguard::app {

// A plain record (PCL's PCL_ADD_POINT4D relies on anonymous structs, a GNU extension); the PCD writer only
// needs the registered fields.
struct PcdPoint {
  float x;
  float y;
  float z;
  float intensity;
  std::uint16_t ring;
  float time;  // seconds after the frame's sensor stamp
};

}  // namespace fieldguard::app

POINT_CLOUD_REGISTER_POINT_STRUCT(fieldguard::app::PcdPoint,
                                  (float, x, x)(float, y, y)(float, z, z)(float, intensity,
                                                                          intensity)(std::uint16_t, ring,
                                                                                     ring)(float, time, time))

namespace fieldguard::app {

std::string write_pcd(const std::string& path, const LidarFrame& frame) {
  pcl::PointCloud<PcdPoint> cloud;
  cloud.reserve(frame.points.size());
  for (const auto& p : frame.points) {
    PcdPoint q{};
    q.x = p.x;
    q.y = p.y;
    q.z = p.z;
    q.intensity = p.intensity;
    q.ring = p.ring;
    q.time = p.time_s;
    cloud.push_back(q);
  }
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
  pcl::PCDWriter writer;
  try {
    if (writer.writeBinary(path, cloud) != 0) return "cannot write " + path;
  } catch (const pcl::IOException& e) {
    return "cannot write " + path + ": " + e.detailedMessage();
  }
  return {};
}

}  // namespace fieldguard::app
