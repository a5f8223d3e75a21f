#pragma once
// Readers of the sensor sections other than the 3D LiDAR's (scan2d, gnss, ahrs). Private to the app.

#include <yaml-cpp/yaml.h>

#include "config/yaml_reader.hpp"
#include "fieldguard/config/config.hpp"

namespace fieldguard::app {

void read_mounting(YamlReader& r, const YAML::Node& n, const std::string& path, Mounting& m);
void read_scan2d(YamlReader& r, const YAML::Node& n, Scan2dConfig& c);
void read_gnss(YamlReader& r, const YAML::Node& n, GnssConfig& c);
void read_ahrs(YamlReader& r, const YAML::Node& n, AhrsConfig& c);

}  // namespace fieldguard::app
