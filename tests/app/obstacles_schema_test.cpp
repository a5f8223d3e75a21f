// The obstacles JSONL of `fieldguard replay --obstacles-out`, checked line by line against its JSON Schema
// (docs/obstacles.schema.json) by an independent validator (Debian's python3-jsonschema,
// tests/interop/validate_jsonl.py): a real HDL-32E capture, the simulator's pedestrian crossing the stop zone,
// and a fused session; and a line the schema must refuse.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"
#include "app/sim_can_support.hpp"
#include "fieldguard/writers/obstacles_jsonl.hpp"

namespace fieldguard {
namespace {

namespace fs = std::filesystem;
using testing::Json;
using testing::run_fieldguard;
using testing::run_shell;

const std::string kSource = FIELDGUARD_SOURCE_DIR;
const std::string kSchema = kSource + "/docs/obstacles.schema.json";

testing::CommandResult validate(const std::string& jsonl) {
  return run_shell("/usr/bin/python3 '" + kSource + "/tests/interop/validate_jsonl.py' '" + kSchema + "' '" + jsonl +
                   "' 2>&1");
}

std::string first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

TEST(ObstaclesSchema, RealCaptureLinesAreValid) {
  testing::TempDir dir;
  const std::string out = (dir.path() / "o.jsonl").string();
  const auto r =
      run_fieldguard("replay --quiet --config '" + kSource + "/config/fieldguard.yaml' --pcap '" +
                     std::string(FIELDGUARD_TEST_DATA) + "/hdl32e_monterey_600.pcap' --obstacles-out '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto v = validate(out);
  EXPECT_EQ(v.exit_code, 0) << "python3-jsonschema (tools/install-deps installs it): " << v.output;
  EXPECT_NE(v.output.find(" with a decision"), std::string::npos) << v.output;
  // Every line has its version, and (no --can-log needed) the frame's decision.
  const Json j = Json::parse(first_line(out));
  EXPECT_EQ(j.at("version"), app::kObstaclesJsonVersion);
  ASSERT_TRUE(j.contains("decision")) << first_line(out);
  EXPECT_TRUE(j.at("decision").at("stop").get<bool>());
  EXPECT_EQ(j.at("decision").at("reason"), "starting up");
  EXPECT_EQ(j.at("decision").at("headline"), "STOP starting up, clear 1 of 3 frames");
}

TEST(ObstaclesSchema, PedestrianInTheZoneStopsAndTheLinesSaySo) {
  testing::PedestrianCapture capture(120);
  ASSERT_TRUE(capture.ok) << capture.command;
  const std::string out = (capture.dir.path() / "o.jsonl").string();
  const auto r = run_fieldguard("replay --quiet --config '" + kSource + "/config/fieldguard.yaml' --pcap '" +
                                capture.pcap + "' --obstacles-out '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto v = validate(out);
  EXPECT_EQ(v.exit_code, 0) << v.output;
  // Stops for the pedestrian with its distance, and goes again: both in the lines, with the obstacles' yaw in
  // degrees.
  std::ifstream in(out);
  int stops = 0, goes = 0;
  bool yaw_in_degrees = false;
  for (std::string line; std::getline(in, line);) {
    const Json j = Json::parse(line);
    const auto& d = j.at("decision");
    const auto& reasons = d.at("reasons");
    if (d.at("reason") == "obstacle in zone" &&
        std::find(reasons.begin(), reasons.end(), Json("obstacle in zone")) != reasons.end()) {
      ++stops;
      EXPECT_EQ(d.at("headline").get<std::string>().rfind("STOP obstacle ", 0), 0U) << line;
      EXPECT_NE(d.at("headline").get<std::string>().find(" m ahead"), std::string::npos) << line;
    }
    if (!d.at("stop").get<bool>()) {
      ++goes;
      EXPECT_EQ(d.at("headline"), "GO");
      EXPECT_EQ(d.at("reason"), "none");
      EXPECT_TRUE(d.at("reasons").empty());
    }
    for (const auto& o : j.at("obstacles")) {
      EXPECT_FALSE(o.at("obb").contains("yaw")) << line;
      // Radians never exceed pi/2 here: a larger magnitude shows degrees.
      yaw_in_degrees = yaw_in_degrees || std::abs(o.at("obb").at("yaw_deg").get<double>()) > 1.6;
    }
  }
  EXPECT_GT(stops, 0);
  EXPECT_GT(goes, 0);
  EXPECT_TRUE(yaw_in_degrees) << "no box's yaw beyond 1.6 in 120 rotations: radians?";
}

TEST(ObstaclesSchema, FusedSessionLinesAreValid) {
  const testing::FusedSession fused(30);
  ASSERT_TRUE(fused.ok) << fused.command;
  const testing::TempDir& dir = fused.dir;
  const std::string& session = fused.path;
  const std::string out = (dir.path() / "o.jsonl").string();
  const auto r = run_fieldguard("replay --quiet --config '" + std::string(FIELDGUARD_TEST_DATA) +
                                "/fusion/uneven-drive.yaml' --session '" + session + "' --obstacles-out '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto v = validate(out);
  EXPECT_EQ(v.exit_code, 0) << v.output;
  EXPECT_EQ(v.output.find(" 0 with fusion"), std::string::npos) << v.output;
}

TEST(ObstaclesSchema, TheSchemaRefusesWhatItDoesNotDescribe) {
  // The validator and the schema can fail: an old line (yaw in radians, no version), a misspelt reason, an
  // undocumented key.
  testing::TempDir dir;
  const std::string bad = (dir.path() / "bad.jsonl").string();
  std::ofstream(bad)
      << R"({"frame":0,"stamp":1.0,"partial":false,"points_in":10,"obstacles":[]})" << '\n'
      << R"({"version":2,"frame":1,"stamp":1.1,"partial":false,"points_in":10,"decision":{"stop":true,)"
      << R"("reason":"obstacle","reasons":[],"headline":"STOP"},"obstacles":[]})" << '\n'
      << R"({"version":2,"frame":2,"stamp":1.2,"partial":false,"points_in":10,"obstacles":[{"min":[0,0,0],)"
      << R"("max":[1,1,1],"points":5,"obb":{"center":[0.5,0.5],"length":1,"width":1,"yaw":0.1},"distance":1,)"
      << R"("bearing":0,"height":1,"class":"small"}]})" << '\n'
      << R"({"version":2,"frame":3,"stamp":1.3,"partial":false,"points_in":10,"obstacles":[],"colour":"red"})" << '\n';
  const auto v = validate(bad);
  EXPECT_EQ(v.exit_code, 1) << v.output;
  EXPECT_NE(v.output.find("4 of 4 lines invalid"), std::string::npos) << v.output;
}

}  // namespace
}  // namespace fieldguard
