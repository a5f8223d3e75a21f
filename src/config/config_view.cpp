// The `view:` section: the MCAP recording and the live server (Foxglove WebSocket and the status page).

#include <filesystem>

#include "config/section_readers.hpp"

namespace fieldguard::app {

void read_view(YamlReader& r, const YAML::Node& n, const std::string& config_dir, ViewConfig& c) {
  const std::string path = "view";
  if (!r.section(n, path, {"mcap", "server", "queue_frames"})) return;
  r.integer(n, path, "queue_frames", c.queue_frames, 1, 64);
  const YAML::Node m = n["mcap"];
  const std::string mp = "view.mcap";
  if (m && r.section(m, mp, {"path", "compression", "max_mb", "max_files"})) {
    r.text(m, mp, "path", c.mcap_path);
    if (!c.mcap_path.empty() && std::filesystem::path(c.mcap_path).is_relative() && !config_dir.empty())
      c.mcap_path = (std::filesystem::path(config_dir) / c.mcap_path).string();
    if (auto k = r.choice(m, mp, "compression", {"zstd", "lz4", "none"}))
      c.mcap_compression = *k == 0 ? "zstd" : *k == 1 ? "lz4" : "none";
    r.integer(m, mp, "max_mb", c.mcap_max_mb, 1, 1 << 20);
    r.integer(m, mp, "max_files", c.mcap_max_files, 1, 100000);
  }
  const YAML::Node s = n["server"];
  const std::string sp = "view.server";
  if (s && r.section(s, sp, {"enabled", "address", "port", "max_clients", "client_queue"})) {
    if (auto e = r.choice(s, sp, "enabled", {"false", "true"})) c.server = *e == 1;
    r.text(s, sp, "address", c.address);
    int port = c.port;
    r.integer(s, sp, "port", port, 0, 65535);  // 0: the kernel chooses (tests)
    c.port = static_cast<std::uint16_t>(port);
    r.integer(s, sp, "max_clients", c.max_clients, 1, 64);
    r.integer(s, sp, "client_queue", c.client_queue, 4, 100000);
  }
}

}  // namespace fieldguard::app
