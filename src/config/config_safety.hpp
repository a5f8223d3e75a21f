#pragma once
// Reader of the `safety:` section (the stop decision). Private to the app.

#include <yaml-cpp/yaml.h>

#include "config/yaml_reader.hpp"
#include "fieldguard/config/config.hpp"

namespace fieldguard::app {

// Reads `n` into c.safety and checks it against the sensor sections already read into `c` (a required
// sensor must be enabled). Call after the sensor sections.
void read_safety(YamlReader& r, const YAML::Node& n, Config& c);

}  // namespace fieldguard::app
