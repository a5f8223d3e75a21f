// The command line as a user meets it: the real binary, real files, exit codes and messages.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "app/run_command.hpp"

namespace fieldguard {
namespace {

using testing::run_fieldguard;

const std::string kSource = FIELDGUARD_SOURCE_DIR;

TEST(Cli, VersionAndHelp) {
  auto v = run_fieldguard("--version");
  EXPECT_EQ(v.exit_code, 0);
  EXPECT_EQ(v.output.rfind("fieldguard ", 0), 0U) << v.output;
  auto h = run_fieldguard("--help");
  EXPECT_EQ(h.exit_code, 0);
  EXPECT_NE(h.output.find("replay"), std::string::npos);
  EXPECT_NE(h.output.find("check-config"), std::string::npos);
  for (const char* cmd : {"replay", "check-config"}) {
    auto c = run_fieldguard(std::string(cmd) + " --help");
    EXPECT_EQ(c.exit_code, 0) << cmd;
    EXPECT_NE(c.output.find(std::string("usage: fieldguard ") + cmd), std::string::npos) << c.output;
  }
}

TEST(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(run_fieldguard("").exit_code, 2);
  auto u = run_fieldguard("fly");
  EXPECT_EQ(u.exit_code, 2);
  EXPECT_NE(u.output.find("unknown command 'fly'"), std::string::npos);
  auto o = run_fieldguard("replay --config x --pcap y --colour red");
  EXPECT_EQ(o.exit_code, 2);
  EXPECT_NE(o.output.find("unknown option --colour"), std::string::npos) << o.output;
  auto m = run_fieldguard("replay --pcap y");
  EXPECT_EQ(m.exit_code, 2);
  EXPECT_NE(m.output.find("--config and one of --pcap or --session are required"), std::string::npos) << m.output;
  auto both = run_fieldguard("replay --config x --pcap y --session z");
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_NE(both.output.find("one of --pcap or --session"), std::string::npos) << both.output;
}

TEST(CheckConfig, ShippedFilesAreValid) {
  for (const char* f : {"fieldguard.yaml", "published.yaml"}) {
    auto r = run_fieldguard("check-config '" + kSource + "/config/" + f + "'");
    EXPECT_EQ(r.exit_code, 0) << f << "\n" << r.output;
    EXPECT_NE(r.output.find("valid"), std::string::npos);
  }
}

TEST(CheckConfig, ListsEveryProblemWithFileLineAndKey) {
  const auto path = std::filesystem::temp_directory_path() / "fieldguard_cli_bad.yaml";
  std::ofstream(path) << "lidar:\n  model: HDL-64\n  max_range_m: -3\nperception:\n  voxel: {leaf: 0.1}\n";
  auto r = run_fieldguard("check-config '" + path.string() + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find(path.string() + ":2: lidar.model: 'HDL-64' is not one of"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(path.string() + ":3: lidar.max_range_m: -3 is out of range"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(path.string() + ":5: perception.voxel.leaf: unknown key"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("3 problems in"), std::string::npos) << r.output;
  std::filesystem::remove(path);
}

TEST(CheckConfig, MissingFileExitsTwo) {
  auto r = run_fieldguard("check-config /nonexistent.yaml");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("no such file"), std::string::npos);
}

}  // namespace
}  // namespace fieldguard
