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

// check-config says which ring spacing the rules scaled by it take: each sensor's own (auto, with each model's
// nominal rings), or the one the file fixes.
TEST(CheckConfig, SaysWhichRingSpacingIsInForce) {
  auto shipped = run_fieldguard("check-config '" + kSource + "/config/fieldguard.yaml'");
  EXPECT_EQ(shipped.exit_code, 0) << shipped.output;
  EXPECT_NE(shipped.output.find("ring spacing: each sensor's own, at each point's elevation"), std::string::npos)
      << shipped.output;
  EXPECT_NE(shipped.output.find("HDL-32E 32 rings from -30.67 to 10.67 deg, 1.33 deg apart"), std::string::npos)
      << shipped.output;
  EXPECT_NE(shipped.output.find("VLP-16 16 rings from -15.00 to 15.00 deg, 2.00 deg apart"), std::string::npos)
      << shipped.output;
  EXPECT_NE(shipped.output.find("RS-32 from its DIFOP (nominal: 32 rings from -25.00 to 15.02 deg, 0.26 to 10.36"),
            std::string::npos)
      << shipped.output;
  const auto path = std::filesystem::temp_directory_path() / "fieldguard_cli_spacing.yaml";
  std::ofstream(path) << "perception:\n  cluster: {beam_spacing_deg: 2.0}\n";
  auto fixed = run_fieldguard("check-config '" + path.string() + "'");
  EXPECT_EQ(fixed.exit_code, 0) << fixed.output;
  EXPECT_NE(fixed.output.find("ring spacing: 2.00 deg for every sensor"), std::string::npos) << fixed.output;
  std::ofstream(path) << "perception:\n  cluster: {beam_spacing_deg: often}\n";
  auto bad = run_fieldguard("check-config '" + path.string() + "'");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("perception.cluster.beam_spacing_deg"), std::string::npos) << bad.output;
  std::filesystem::remove(path);
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
