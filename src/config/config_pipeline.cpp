// The `pipeline:` section: the worker pool between the io thread and perception; the `realtime:` section: how
// the io thread and the workers are scheduled.

#include "config/section_readers.hpp"

namespace fieldguard::app {

void read_pipeline(YamlReader& r, const YAML::Node& n, PipelineConfig& c) {
  const std::string path = "pipeline";
  if (!r.section(n, path, {"workers", "queue_capacity", "drop"})) return;
  // The limits are sync::PoolParams' own: a value the loader accepts never makes the pool throw.
  r.integer(n, path, "workers", c.workers, 1, 64);
  r.integer(n, path, "queue_capacity", c.queue_capacity, 1, 4096);
  if (auto d = r.choice(n, path, "drop", {"oldest", "newest"}))
    c.drop = *d == 0 ? PipelineDrop::Oldest : PipelineDrop::Newest;
}

namespace {

// A list of CPU numbers ([0, 1]); absent leaves `out` empty (any CPU).
void read_cpus(YamlReader& r, const YAML::Node& n, const std::string& path, const char* key, std::vector<int>& out) {
  if (!n || !n.IsMap() || !n[key]) return;
  const YAML::Node v = n[key];
  const std::string at = join_path(path, key);
  if (!v.IsSequence()) {
    r.issue(v, at, "expected a list of CPU numbers, like [1] or [0, 1]; [] for any CPU");
    return;
  }
  for (const auto& c : v) {
    int cpu = -1;
    if (!c.IsScalar() || !YAML::convert<int>::decode(c, cpu) || cpu < 0 || cpu > 1023) {
      r.issue(c, at, "'" + (c.IsScalar() ? c.Scalar() : std::string("?")) + "' is not a CPU number (0..1023)");
      continue;
    }
    out.push_back(cpu);
  }
}

}  // namespace

void read_realtime(YamlReader& r, const YAML::Node& n, RealtimeConfig& c) {
  const std::string path = "realtime";
  if (!r.section(
          n, path,
          {"policy", "io_priority", "worker_priority", "io_cpus", "worker_cpus", "lock_memory", "latency_budget_ms"})) {
    return;
  }
  if (auto p = r.choice(n, path, "policy", {"other", "fifo", "rr"})) {
    using sync::SchedPolicy;
    c.policy = *p == 0 ? SchedPolicy::Other : *p == 1 ? SchedPolicy::Fifo : SchedPolicy::RoundRobin;
  }
  r.integer(n, path, "io_priority", c.io_priority, 1, 99);
  r.integer(n, path, "worker_priority", c.worker_priority, 1, 99);
  read_cpus(r, n, path, "io_cpus", c.io_cpus);
  read_cpus(r, n, path, "worker_cpus", c.worker_cpus);
  if (auto l = r.choice(n, path, "lock_memory", {"false", "true"})) c.lock_memory = *l == 1;
  r.number(n, path, "latency_budget_ms", c.latency_budget_ms, 0.1, 1000.0, "ms");
}

}  // namespace fieldguard::app
