// The `pipeline:` and `can:` sections of the configuration.

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "app/config_issues.hpp"
#include "fieldguard/config/config.hpp"

namespace fieldguard::app {
namespace {

using testing::dump;
using testing::has_issue;

TEST(ConfigOutput, DefaultsWithoutTheSections) {
  const auto r = load_config_text("lidar: {model: auto}\n", "d.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_EQ(r.config.pipeline.workers, 1);
  EXPECT_EQ(r.config.pipeline.queue_capacity, 8);
  EXPECT_EQ(r.config.pipeline.drop, PipelineDrop::Oldest);
  EXPECT_EQ(r.config.can.sink, CanSinkKind::SocketCan);
  EXPECT_EQ(r.config.can.interface, "can0");
  EXPECT_EQ(r.config.can.params.source_address, 0x80);
  EXPECT_EQ(r.config.can.params.controller_address, 0x26);
  EXPECT_EQ(r.config.can.params.max_obstacles, 8);
  EXPECT_DOUBLE_EQ(r.config.can.heartbeat_period_s, 0.1);
}

TEST(ConfigOutput, ReadsEveryKey) {
  const auto r = load_config_text(R"(
pipeline: {workers: 4, queue_capacity: 32, drop: newest}
can:
  sink: candump
  interface: vcan1
  log_path: /var/lib/fieldguard/can.log
  source_address: 0xA0
  controller_address: 19
  max_obstacles: 16
  heartbeat_period_s: 0.05
)",
                                  "o.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_EQ(r.config.pipeline.workers, 4);
  EXPECT_EQ(r.config.pipeline.queue_capacity, 32);
  EXPECT_EQ(r.config.pipeline.drop, PipelineDrop::Newest);
  EXPECT_EQ(r.config.can.sink, CanSinkKind::Candump);
  EXPECT_EQ(r.config.can.interface, "vcan1");
  EXPECT_EQ(r.config.can.log_path, "/var/lib/fieldguard/can.log");
  EXPECT_EQ(r.config.can.params.source_address, 0xA0);
  EXPECT_EQ(r.config.can.params.controller_address, 19);
  EXPECT_EQ(r.config.can.params.max_obstacles, 16);
  EXPECT_DOUBLE_EQ(r.config.can.heartbeat_period_s, 0.05);
  EXPECT_EQ(load_config_text("can: {sink: none}\n", "n.yaml").config.can.sink, CanSinkKind::None);
}

TEST(ConfigOutput, ReportsEveryProblemWithLineAndKey) {
  const auto r = load_config_text(R"(pipeline:
  workers: 0
  queue_capacity: 5000
  drop: middle
  threads: 2
can:
  sink: serial
  interface: "can 0"
  source_address: 0xFE
  controller_address: 0x1G
  max_obstacles: 17
  heartbeat_period_s: 5
)",
                                  "bad.yaml");
  EXPECT_TRUE(has_issue(r, "pipeline.workers", "out of range", 2)) << dump(r);
  EXPECT_TRUE(has_issue(r, "pipeline.queue_capacity", "out of range", 3)) << dump(r);
  EXPECT_TRUE(has_issue(r, "pipeline.drop", "not one of oldest, newest", 4)) << dump(r);
  EXPECT_TRUE(has_issue(r, "pipeline.threads", "", 5)) << dump(r);
  EXPECT_TRUE(has_issue(r, "can.sink", "not one of socketcan, candump, none", 7)) << dump(r);
  EXPECT_TRUE(has_issue(r, "can.interface", "", 8)) << dump(r);
  EXPECT_TRUE(has_issue(r, "can.source_address", "null and global", 9)) << dump(r);
  EXPECT_TRUE(has_issue(r, "can.controller_address", "expected a J1939 address", 10)) << dump(r);
  EXPECT_TRUE(has_issue(r, "can.max_obstacles", "out of range", 11)) << dump(r);
  EXPECT_TRUE(has_issue(r, "can.heartbeat_period_s", "out of range", 12)) << dump(r);
  EXPECT_EQ(r.issues.size(), 10U) << dump(r);
}

TEST(ConfigOutput, CandumpNeedsALogAndAddressesMustDiffer) {
  const auto r = load_config_text(R"(can:
  sink: candump
  source_address: 0x26
  controller_address: 38
)",
                                  "c.yaml");
  EXPECT_TRUE(has_issue(r, "can.log_path", "no log_path", 2)) << dump(r);
  EXPECT_TRUE(has_issue(r, "can.controller_address", "cannot share an address", 4)) << dump(r);
  EXPECT_EQ(r.issues.size(), 2U) << dump(r);
  const auto n = load_config_text("can: [socketcan]\n", "s.yaml");
  EXPECT_FALSE(n.ok());
}

TEST(ConfigOutput, SpeedFromTheBus) {
  const auto d = load_config_text("can: {sink: none}\n", "d.yaml");
  ASSERT_TRUE(d.ok()) << dump(d);
  EXPECT_EQ(d.config.can.speed, SpeedInput::None);
  EXPECT_DOUBLE_EQ(d.config.can.speed_timeout_s, 0.5);
  const auto r = load_config_text("can: {sink: none, speed: iso_wheel_based, speed_timeout_s: 0.3}\n", "s.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  EXPECT_EQ(r.config.can.speed, SpeedInput::IsoWheelBased);
  EXPECT_DOUBLE_EQ(r.config.can.speed_timeout_s, 0.3);
  EXPECT_EQ(load_config_text("can: {speed: ccvs1}\n", "c.yaml").config.can.speed, SpeedInput::Ccvs1);
  const auto bad = load_config_text("can:\n  speed: gps\n  speed_timeout_s: 0\n", "b.yaml");
  EXPECT_TRUE(has_issue(bad, "can.speed", "", 2)) << dump(bad);
  EXPECT_TRUE(has_issue(bad, "can.speed_timeout_s", "", 3)) << dump(bad);
}

TEST(ConfigOutput, TheJ1939NodeAndItsName) {
  const auto d = load_config_text("can: {sink: none}\n", "d.yaml");
  ASSERT_TRUE(d.ok()) << dump(d);
  EXPECT_TRUE(d.config.can.j1939.address_claim);
  EXPECT_TRUE(d.config.can.j1939.name.arbitrary_address_capable);
  EXPECT_EQ(d.config.can.j1939.name.industry_group, 2);
  EXPECT_EQ(d.config.can.j1939.name.function, 255);
  EXPECT_FALSE(d.config.can.j1939.controller_name);
  const auto r = load_config_text(R"(can:
  j1939:
    address_claim: false
    arbitrary_address: false
    identity_number: 2097151
    manufacturer_code: 1234
    function: 130
    function_instance: 31
    ecu_instance: 7
    vehicle_system: 127
    vehicle_system_instance: 15
    industry_group: 2
    controller_name: 0xA00C8100AB3C0042
    component_id: fieldguard*FG-1*0042*7*
)",
                                  "j.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& j = r.config.can.j1939;
  EXPECT_FALSE(j.address_claim);
  EXPECT_FALSE(j.name.arbitrary_address_capable);
  EXPECT_EQ(j.name.identity_number, 2097151U);
  EXPECT_EQ(j.name.manufacturer_code, 1234);
  EXPECT_EQ(j.name.function, 130);
  EXPECT_EQ(j.name.function_instance, 31);
  EXPECT_EQ(j.name.ecu_instance, 7);
  EXPECT_EQ(j.name.vehicle_system, 127);
  EXPECT_EQ(j.name.vehicle_system_instance, 15);
  EXPECT_EQ(j.controller_name, 0xA00C8100AB3C0042ULL);
  EXPECT_EQ(j.component_id, "fieldguard*FG-1*0042*7*");

  const auto bad = load_config_text(R"(can:
  j1939:
    identity_number: 2097152
    manufacturer_code: -1
    industry_group: 8
    controller_name: A00C8100AB3C0042
    adress_claim: true
)",
                                    "b.yaml");
  EXPECT_TRUE(has_issue(bad, "can.j1939.identity_number", "out of range", 3)) << dump(bad);
  EXPECT_TRUE(has_issue(bad, "can.j1939.manufacturer_code", "out of range", 4)) << dump(bad);
  EXPECT_TRUE(has_issue(bad, "can.j1939.industry_group", "out of range", 5)) << dump(bad);
  EXPECT_TRUE(has_issue(bad, "can.j1939.controller_name", "0x...", 6)) << dump(bad);
  EXPECT_TRUE(has_issue(bad, "can.j1939.adress_claim", "", 7)) << dump(bad);
  EXPECT_EQ(bad.issues.size(), 5U) << dump(bad);
}

TEST(ConfigRealtime, ReadsEveryKeyAndDefaultsToNormalScheduling) {
  const auto defaults = load_config_text("lidar: {data_port: 2368}\n", "d.yaml");
  ASSERT_TRUE(defaults.ok()) << dump(defaults);
  EXPECT_EQ(defaults.config.realtime.policy, sync::SchedPolicy::Other);
  EXPECT_FALSE(defaults.config.realtime.lock_memory);
  EXPECT_TRUE(defaults.config.realtime.io_cpus.empty());
  const auto r = load_config_text(R"(realtime:
  policy: rr
  io_priority: 70
  worker_priority: 20
  io_cpus: [1]
  worker_cpus: [0, 1]
  lock_memory: true
  latency_budget_ms: 2.5
)",
                                  "rt.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const RealtimeConfig& rt = r.config.realtime;
  EXPECT_EQ(rt.policy, sync::SchedPolicy::RoundRobin);
  EXPECT_EQ(rt.io_priority, 70);
  EXPECT_EQ(rt.worker_priority, 20);
  EXPECT_EQ(rt.io_cpus, std::vector<int>({1}));
  EXPECT_EQ(rt.worker_cpus, std::vector<int>({0, 1}));
  EXPECT_TRUE(rt.lock_memory);
  EXPECT_DOUBLE_EQ(rt.latency_budget_ms, 2.5);
}

TEST(ConfigRealtime, ReportsEveryProblemWithItsLine) {
  const auto r = load_config_text(R"(realtime:
  policy: deadline
  io_priority: 0
  worker_priority: 100
  io_cpus: 1
  worker_cpus: [0, x, -1]
  lock_memory: yes
  latency_budget_ms: 0
  nice: 5
)",
                                  "bad.yaml");
  EXPECT_TRUE(testing::has_issue(r, "realtime.policy", "deadline", 2)) << dump(r);
  EXPECT_TRUE(testing::has_issue(r, "realtime.io_priority", "", 3)) << dump(r);
  EXPECT_TRUE(testing::has_issue(r, "realtime.worker_priority", "", 4)) << dump(r);
  EXPECT_TRUE(testing::has_issue(r, "realtime.io_cpus", "list of CPU numbers", 5)) << dump(r);
  EXPECT_TRUE(testing::has_issue(r, "realtime.worker_cpus", "'x' is not a CPU number", 6)) << dump(r);
  EXPECT_TRUE(testing::has_issue(r, "realtime.worker_cpus", "'-1' is not a CPU number", 6)) << dump(r);
  EXPECT_TRUE(testing::has_issue(r, "realtime.lock_memory", "", 7)) << dump(r);
  EXPECT_TRUE(testing::has_issue(r, "realtime.latency_budget_ms", "", 8)) << dump(r);
  EXPECT_TRUE(testing::has_issue(r, "realtime.nice", "unknown key", 9)) << dump(r);
}

}  // namespace
}  // namespace fieldguard::app
