// The `pipeline:` section: the worker pool between the io thread and perception.

#include "config/section_readers.hpp"

namespace fieldguard::app {

void read_pipeline(YamlReader& r, const YAML::Node& n, PipelineConfig& c) {
  const std::string path = "pipeline";
  if (!r.section(n, path, {"workers", "queue_capacity", "drop"})) return;
  // The limits are sync::PoolParams' own: a value the loader accepts never makes the pool throw.
  r.integer(n, path, "workers", c.workers, 1, 64);
  r.integer(n, path, "queue_capacity", c.queue_capacity, 1, 4096);
  if (auto d = r.choice(n, path, "drop", {"oldest", "newest"})) c.drop = *d == 0 ? PipelineDrop::Oldest : PipelineDrop::Newest;
}

}  // namespace fieldguard::app
