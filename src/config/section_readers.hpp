#pragma once
// Readers of the `sync:`, `geo:`, `pipeline:` and `can:` sections. Private to the app.

#include <yaml-cpp/yaml.h>

#include <string>

#include "config/yaml_reader.hpp"
#include "fieldguard/config/config.hpp"

namespace fieldguard::app {

void read_sync(YamlReader& r, const YAML::Node& n, SyncConfig& c);
void read_geo(YamlReader& r, const YAML::Node& n, GeoConfig& c);
void read_pipeline(YamlReader& r, const YAML::Node& n, PipelineConfig& c);
void read_realtime(YamlReader& r, const YAML::Node& n, RealtimeConfig& c);
// `config_dir`: the config file's folder, against which a relative log path is taken ("" for text).
void read_can(YamlReader& r, const YAML::Node& n, const std::string& config_dir, CanConfig& c);
void read_view(YamlReader& r, const YAML::Node& n, const std::string& config_dir, ViewConfig& c);

}  // namespace fieldguard::app
