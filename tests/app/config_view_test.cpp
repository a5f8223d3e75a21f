// The `view:` section: the MCAP recording and the live server, off unless asked for.

#include <gtest/gtest.h>

#include <string>

#include "app/config_issues.hpp"
#include "fieldguard/config/config.hpp"

namespace fieldguard::app {
namespace {

using testing::dump;
using testing::has_issue;

TEST(ConfigView, OffWithoutTheSection) {
  const auto r = load_config_text("lidar: {model: auto}\n", "d.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_TRUE(r.config.view.mcap_path.empty());
  EXPECT_FALSE(r.config.view.server);
  EXPECT_EQ(r.config.view.address, "127.0.0.1");  // localhost unless opened on purpose
  EXPECT_EQ(r.config.view.port, 8765);
}

TEST(ConfigView, ReadsEveryKey) {
  const auto r = load_config_text(R"(
view:
  queue_frames: 4
  mcap: {path: /var/lib/fieldguard/run.mcap, compression: lz4, max_mb: 200, max_files: 3}
  server: {enabled: true, address: 0.0.0.0, port: 9000, max_clients: 2, client_queue: 16}
)",
                                  "v.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const ViewConfig& v = r.config.view;
  EXPECT_EQ(v.queue_frames, 4);
  EXPECT_EQ(v.mcap_path, "/var/lib/fieldguard/run.mcap");
  EXPECT_EQ(v.mcap_compression, "lz4");
  EXPECT_EQ(v.mcap_max_mb, 200);
  EXPECT_EQ(v.mcap_max_files, 3);
  EXPECT_TRUE(v.server);
  EXPECT_EQ(v.address, "0.0.0.0");
  EXPECT_EQ(v.port, 9000);
  EXPECT_EQ(v.max_clients, 2);
  EXPECT_EQ(v.client_queue, 16);
}

TEST(ConfigView, ReportsEveryProblem) {
  const auto r = load_config_text(R"(
view:
  queue_frames: 0
  mcap: {compression: gzip, max_mb: 0, colour: red}
  server: {enabled: maybe, port: 70000, max_clients: 0}
)",
                                  "bad.yaml");
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(has_issue(r, "view.queue_frames", "")) << dump(r);
  EXPECT_TRUE(has_issue(r, "view.mcap.compression", "")) << dump(r);
  EXPECT_TRUE(has_issue(r, "view.mcap.max_mb", "")) << dump(r);
  EXPECT_TRUE(has_issue(r, "view.mcap.colour", "")) << dump(r);
  EXPECT_TRUE(has_issue(r, "view.server.enabled", "")) << dump(r);
  EXPECT_TRUE(has_issue(r, "view.server.port", "")) << dump(r);
  EXPECT_TRUE(has_issue(r, "view.server.max_clients", "")) << dump(r);
}

}  // namespace
}  // namespace fieldguard::app
