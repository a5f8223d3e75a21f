#pragma once
// Per-laser calibration of a Velodyne sensor: built-in defaults, or the files users have
// (the ROS velodyne driver's YAML, VeloView's db.xml). Parsing takes text, not paths: no I/O here.

#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/core/expected.hpp"
#include "fieldguard/drivers/velodyne_types.hpp"

namespace fieldguard::velodyne {

// Corrections of one laser, indexed by its slot in the firing order (laser_id in both file formats).
struct LaserCorrection {
  double vert_deg = 0.0;        // vertical angle, + up
  double rot_deg = 0.0;         // azimuth correction as the files give it: SUBTRACTED from the firing azimuth
                                // (Velodyne manual: "positive factors rotate to the left", seen from the back)
  double dist_m = 0.0;          // distance offset added to every range
  double vert_offset_m = 0.0;   // vertical offset of the laser from the sensor origin
  double horiz_offset_m = 0.0;  // horizontal offset of the laser from the sensor origin
  double dist_x_m = 0.0;        // 2-point distance corrections (db.xml distCorrectionX/Y); kept, unused by HDL-32E
  double dist_y_m = 0.0;
};

struct Calibration {
  Model model = Model::Unknown;
  double distance_resolution_m = 0.002;  // one distance LSB
  std::vector<LaserCorrection> lasers;   // 32 for HDL-32E, 16 for VLP-16
  std::vector<int> ring_of_laser;        // ring index (0 = lowest) of every laser, derived from vert_deg
};

// The manufacturer's nominal tables (protocols.md §1.5, §1.10). Throws std::invalid_argument for Unknown.
[[nodiscard]] Calibration default_calibration(Model model);

// ROS velodyne_pointcloud YAML (lasers: [{laser_id, rot_correction (rad), vert_correction (rad),
// dist_correction (m), vert_offset_correction, horiz_offset_correction, ...}], distance_resolution).
[[nodiscard]] Expected<Calibration, std::string> parse_ros_calibration(std::string_view yaml_text);

// VeloView / Velodyne db.xml (boost serialization: DB/points_/item/px/{id_, rotCorrection_, vertCorrection_,
// distCorrection_ (cm), vertOffsetCorrection_ (cm), horizOffsetCorrection_ (cm), ...}, distLSB_ (cm)).
[[nodiscard]] Expected<Calibration, std::string> parse_veloview_calibration(std::string_view xml_text);

// Fills ring_of_laser from the vertical angles (rank of the angle, ties by laser index).
void assign_rings(Calibration& cal);

}  // namespace fieldguard::velodyne
