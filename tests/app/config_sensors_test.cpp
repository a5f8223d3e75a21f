// The sensor sections of the configuration other than the 3D LiDAR's.

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "app/config_issues.hpp"
#include "fieldguard/config/config.hpp"

namespace fieldguard::app {
namespace {

using testing::dump;
using testing::has_issue;

TEST(ConfigSensors, ReadsEveryKey) {
  const auto r = load_config_text(R"(
scan2d:
  enabled: true
  host: 10.0.0.7
  port: 10941
  start_step: 180
  end_step: 900
  intensity: true
  connect_timeout_s: 1.5
  silence_timeout_s: 0.2
  backoff_max_s: 3
  mounting: {x_m: 4, z_m: 0.4, yaw_deg: 1}
gnss: {enabled: true, device: /dev/ttyUSB3, baud: 921600, framing: 7E2, silence_timeout_s: 2, reopen_interval_s: 0.5}
ahrs:
  enabled: true
  device: /dev/serial/by-id/xsens
  baud: 460800
  mounting: {roll_deg: 180}
)",
                                  "s.yaml");
  ASSERT_TRUE(r.ok()) << dump(r);
  const auto& c = r.config;
  EXPECT_TRUE(c.scan2d.enabled);
  EXPECT_EQ(c.scan2d.host, "10.0.0.7");
  EXPECT_EQ(c.scan2d.port, 10941);
  EXPECT_EQ(c.scan2d.start_step, 180);
  EXPECT_EQ(c.scan2d.end_step, 900);
  EXPECT_TRUE(c.scan2d.intensity);
  EXPECT_DOUBLE_EQ(c.scan2d.connect_timeout_s, 1.5);
  EXPECT_DOUBLE_EQ(c.scan2d.silence_timeout_s, 0.2);
  EXPECT_DOUBLE_EQ(c.scan2d.backoff_max_s, 3.0);
  EXPECT_DOUBLE_EQ(c.scan2d.mounting.x_m, 4.0);
  EXPECT_DOUBLE_EQ(c.scan2d.mounting.yaw_deg, 1.0);
  EXPECT_TRUE(c.gnss.serial.enabled);
  EXPECT_EQ(c.gnss.serial.device, "/dev/ttyUSB3");
  EXPECT_EQ(c.gnss.serial.baud, 921600U);
  EXPECT_EQ(c.gnss.serial.data_bits, 7U);
  EXPECT_EQ(c.gnss.serial.parity, 'E');
  EXPECT_EQ(c.gnss.serial.stop_bits, 2U);
  EXPECT_DOUBLE_EQ(c.gnss.serial.silence_timeout_s, 2.0);
  EXPECT_DOUBLE_EQ(c.gnss.serial.reopen_interval_s, 0.5);
  EXPECT_EQ(c.ahrs.serial.device, "/dev/serial/by-id/xsens");
  EXPECT_EQ(c.ahrs.serial.baud, 460800U);
  EXPECT_DOUBLE_EQ(c.ahrs.mounting.roll_deg, 180.0);
}

TEST(ConfigSensors, ReportsEveryProblemWithLineAndKey) {
  const std::string text =
      "scan2d:\n"                        // 1
      "  start_step: 900\n"              // 2
      "  end_step: 100\n"                // 3  end < start
      "  port: 0\n"                      // 4  out of range
      "gnss:\n"                          // 5
      "  enabled: yes please\n"          // 6  not a boolean
      "  baud: 12345\n"                  // 7  not a baud rate
      "  framing: 9X3\n"                 // 8
      "ahrs:\n"                          // 9
      "  enabled: true\n"                // 10 no device
      "  mounting: {pitch_deg: 120}\n";  // 11
  const auto r = load_config_text(text, "bad.yaml");
  EXPECT_TRUE(has_issue(r, "scan2d.end_step", "must not be less than start_step", 3)) << dump(r);
  EXPECT_TRUE(has_issue(r, "scan2d.port", "out of range", 4)) << dump(r);
  EXPECT_TRUE(has_issue(r, "gnss.enabled", "not one of false, true", 6)) << dump(r);
  EXPECT_TRUE(has_issue(r, "gnss.baud", "not one of 9600", 7)) << dump(r);
  EXPECT_TRUE(has_issue(r, "gnss.framing", "not a framing like 8N1", 8)) << dump(r);
  EXPECT_TRUE(has_issue(r, "ahrs.device", "names no device", 10)) << dump(r);
  EXPECT_TRUE(has_issue(r, "ahrs.mounting.pitch_deg", "out of range", 11)) << dump(r);
  EXPECT_EQ(r.issues.size(), 7U) << dump(r);
}

}  // namespace
}  // namespace fieldguard::app
