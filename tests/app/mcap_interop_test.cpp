// `fieldguard replay --mcap-out`, read by an independent reader: @mcap/core from the npm registry
// (tests/interop/node/mcap_check.mjs, installed by tools/install-deps) reads every record, checks every CRC and
// validates every message against @foxglove/schemas' JSON schemas. What it decoded is then compared with the
// obstacles JSONL of the same run: the same decisions and the same boxes, frame by frame.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"
#include "app/sim_can_support.hpp"

namespace fieldguard {
namespace {

namespace fs = std::filesystem;
using testing::Json;
using testing::run_fieldguard;
using testing::run_shell;

const std::string kSource = FIELDGUARD_SOURCE_DIR;
const std::string kConfig = kSource + "/config/fieldguard.yaml";

std::vector<Json> lines(const std::string& path) {
  std::vector<Json> out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) out.push_back(Json::parse(line));
  return out;
}

struct Check {
  testing::CommandResult result;
  Json summary;
};

// mcap_check.mjs on `mcap`, every channel of a frame expected; `dumps`: topic -> file to write its messages to.
Check check(const std::string& mcap, const std::vector<std::pair<std::string, std::string>>& dumps = {},
            const std::vector<std::string>& topics = {"/lidar/points", "/detection/points", "/detection/obstacles",
                                                      "/detection/zones", "/safety/decision"}) {
  std::string cmd = "node '" + kSource + "/tests/interop/node/mcap_check.mjs' '" + mcap + "'";
  for (const auto& t : topics) cmd += " --expect-topic " + t;
  for (const auto& [topic, file] : dumps) cmd += " --dump " + topic + " '" + file + "'";
  Check c{run_shell(cmd + " 2>&1"), {}};
  const auto brace = c.result.output.find('{');
  if (brace != std::string::npos) c.summary = Json::parse(c.result.output.substr(brace), nullptr, false);
  return c;
}

// Each frame's decision in the MCAP (as @mcap/core decoded it) is the obstacles JSONL's, and each frame's boxes
// are as many as its obstacles.
void expect_same_frames(const std::string& jsonl, const std::string& decisions, const std::string& scenes) {
  const auto frames = lines(jsonl);
  const auto decided = lines(decisions);
  const auto boxes = lines(scenes);
  ASSERT_EQ(decided.size(), frames.size());
  ASSERT_EQ(boxes.size(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const Json& d = frames[i].at("decision");
    EXPECT_EQ(decided[i].at("frame"), frames[i].at("frame"));
    EXPECT_EQ(decided[i].at("stop"), d.at("stop")) << i;
    EXPECT_EQ(decided[i].at("reason"), d.at("reason")) << i;
    EXPECT_EQ(decided[i].at("reasons"), d.at("reasons")) << i;
    EXPECT_EQ(decided[i].at("headline"), d.at("headline")) << i;
    const Json& cubes = boxes[i].at("entities").at(0).at("cubes");
    EXPECT_EQ(cubes.size(), frames[i].at("obstacles").size()) << i;
  }
}

TEST(McapInterop, RealCaptureIsReadByMcapCoreAndMatchesTheJsonl) {
  testing::TempDir dir;
  const std::string mcap = (dir.path() / "r.mcap").string();
  const std::string jsonl = (dir.path() / "o.jsonl").string();
  const auto r =
      run_fieldguard("replay --quiet --config '" + kConfig + "' --pcap '" + std::string(FIELDGUARD_TEST_DATA) +
                     "/hdl32e_monterey_600.pcap' --mcap-out '" + mcap + "' --obstacles-out '" + jsonl + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("mcap "), std::string::npos) << r.output;
  const std::string decisions = (dir.path() / "d.jsonl").string();
  const std::string scenes = (dir.path() / "s.jsonl").string();
  const auto c = check(mcap, {{"/safety/decision", decisions}, {"/detection/obstacles", scenes}});
  ASSERT_EQ(c.result.exit_code, 0) << "@mcap/core (tools/install-deps installs it): " << c.result.output;
  EXPECT_EQ(c.summary.at("compression"), Json::array({"zstd"}));
  expect_same_frames(jsonl, decisions, scenes);
}

TEST(McapInterop, PedestrianStopAndGoAreInTheRecording) {
  testing::PedestrianCapture capture(120);
  ASSERT_TRUE(capture.ok) << capture.command;
  const std::string mcap = (capture.dir.path() / "p.mcap").string();
  const std::string jsonl = (capture.dir.path() / "o.jsonl").string();
  const auto r = run_fieldguard("replay --quiet --config '" + kConfig + "' --pcap '" + capture.pcap + "' --mcap-out '" +
                                mcap + "' --mcap-compression lz4 --obstacles-out '" + jsonl + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string decisions = (capture.dir.path() / "d.jsonl").string();
  const std::string scenes = (capture.dir.path() / "s.jsonl").string();
  const auto c = check(mcap, {{"/safety/decision", decisions}, {"/detection/obstacles", scenes}});
  ASSERT_EQ(c.result.exit_code, 0) << c.result.output;
  EXPECT_EQ(c.summary.at("compression"), Json::array({"lz4"}));
  expect_same_frames(jsonl, decisions, scenes);
  int stops = 0, goes = 0;
  for (const Json& d : lines(decisions)) {
    if (d.at("reason") == "obstacle in zone") {
      ++stops;
      EXPECT_EQ(d.at("headline").get<std::string>().rfind("STOP obstacle ", 0), 0U);
      // While the box is in the zone (not while the stop holds for clear frames) its distance is given.
      const bool in_zone = !d.at("reasons").empty() && d.at("reasons")[0] == "obstacle in zone";
      EXPECT_EQ(d.at("nearest_m").is_number(), in_zone) << d.dump();
    }
    goes += d.at("stop").get<bool>() ? 0 : 1;
  }
  EXPECT_GT(stops, 0);
  EXPECT_GT(goes, 0);
}

TEST(McapInterop, FusedSessionHasItsPoseAndPosition) {
  const testing::FusedSession fused(20);
  ASSERT_TRUE(fused.ok) << fused.command;
  const testing::TempDir& dir = fused.dir;
  const std::string& session = fused.path;
  const std::string mcap = (dir.path() / "f.mcap").string();
  const auto r = run_fieldguard("replay --quiet --config '" + std::string(FIELDGUARD_TEST_DATA) +
                                "/fusion/uneven-drive.yaml' --session '" + session + "' --mcap-out '" + mcap +
                                "' --mcap-compression none");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string fixes = (dir.path() / "fix.jsonl").string();
  const auto c = check(mcap, {{"/gnss/fix", fixes}},
                       {"/lidar/points", "/detection/points", "/safety/decision", "/tf", "/gnss/fix"});
  ASSERT_EQ(c.result.exit_code, 0) << c.result.output;
  // The simulator's field lies where its config's GNSS puts it: a plausible WGS84 position, the same each frame
  // to within a tractor's travel.
  const auto fix = lines(fixes);
  ASSERT_FALSE(fix.empty());
  const double lat0 = fix.front().at("latitude").get<double>();
  for (const Json& f : fix) {
    EXPECT_NEAR(f.at("latitude").get<double>(), lat0, 0.001);
    EXPECT_GE(std::abs(lat0), 1.0);
  }
}

TEST(McapInterop, TheReaderRefusesADamagedFile) {
  // The check can fail: one byte changed in the middle of a recording.
  testing::TempDir dir;
  const std::string mcap = (dir.path() / "r.mcap").string();
  const auto r =
      run_fieldguard("replay --quiet --config '" + kConfig + "' --pcap '" + std::string(FIELDGUARD_TEST_DATA) +
                     "/hdl32e_monterey_600.pcap' --mcap-out '" + mcap + "' --mcap-compression none");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  {
    std::fstream f(mcap, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(static_cast<std::streamoff>(fs::file_size(mcap) / 2));
    const char c = static_cast<char>(f.get());
    f.seekp(static_cast<std::streamoff>(fs::file_size(mcap) / 2));
    f.put(static_cast<char>(c ^ 0x5A));
  }
  const auto c = check(mcap);
  EXPECT_EQ(c.result.exit_code, 1) << c.result.output;
  EXPECT_NE(c.result.output.find("CRC"), std::string::npos) << c.result.output;
}

TEST(McapInterop, TheCheckerPassesAnotherWritersFileAndRefusesASchemaViolation) {
  // A file written by @mcap/core's own writer passes; one whose point cloud lacks point_stride does not.
  testing::TempDir dir;
  const std::string node = "node '" + kSource + "/tests/interop/node/make_sample.mjs' ";
  const std::string good = (dir.path() / "good.mcap").string();
  const std::string bad = (dir.path() / "bad.mcap").string();
  ASSERT_EQ(run_shell(node + "'" + good + "'").exit_code, 0);
  ASSERT_EQ(run_shell(node + "'" + bad + "' --invalid").exit_code, 0);
  const auto ok = check(good, {}, {"/points"});
  EXPECT_EQ(ok.result.exit_code, 0) << ok.result.output;
  const auto refused = check(bad, {}, {"/points"});
  EXPECT_EQ(refused.result.exit_code, 1) << refused.result.output;
  EXPECT_NE(refused.result.output.find("point_stride"), std::string::npos) << refused.result.output;
}

TEST(McapInterop, AnUnwritableRecordingIsAnError) {
  const auto r =
      run_fieldguard("replay --quiet --config '" + kConfig + "' --pcap '" + std::string(FIELDGUARD_TEST_DATA) +
                     "/hdl32e_monterey_600.pcap' --mcap-out /nonexistent/dir/r.mcap");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("cannot write /nonexistent/dir/r.mcap"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace fieldguard
