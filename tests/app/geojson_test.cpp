// `fieldguard replay --geojson-out`: the obstacles' footprints in WGS84, checked against the obstacles JSONL of
// the same run: one closed, counter-clockwise polygon per obstacle of each frame with a full pose, where the
// simulator put the field (its --origin), each as long and wide as the obstacle's oriented box.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"
#include "app/sim_can_support.hpp"

namespace fieldguard {
namespace {

using testing::Json;
using testing::run_fieldguard;

const std::string kSource = FIELDGUARD_SOURCE_DIR;

// Metres east and north of `origin` (lon, lat) on a sphere of the WGS84 equatorial radius: plenty for a box's
// few metres.
std::pair<double, double> local_m(const Json& p, const Json& origin) {
  constexpr double kR = 6378137.0;
  const double lat0 = origin[1].get<double>() * std::numbers::pi / 180.0;
  const double e = (p[0].get<double>() - origin[0].get<double>()) * std::numbers::pi / 180.0 * kR * std::cos(lat0);
  const double n = (p[1].get<double>() - origin[1].get<double>()) * std::numbers::pi / 180.0 * kR;
  return {e, n};
}

TEST(GeoJson, FusedSessionFootprintsAreTheObstacleBoxesOnTheEarth) {
  const testing::FusedSession fused(20);
  ASSERT_TRUE(fused.ok) << fused.command;
  const testing::TempDir& dir = fused.dir;
  const std::string& session = fused.path;
  const std::string geojson = (dir.path() / "o.geojson").string();
  const std::string jsonl = (dir.path() / "o.jsonl").string();
  const auto r = run_fieldguard("replay --quiet --config '" + std::string(FIELDGUARD_TEST_DATA) +
                                "/fusion/uneven-drive.yaml' --session '" + session + "' --geojson-out '" + geojson +
                                "' --obstacles-out '" + jsonl + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(geojson);
  const Json g = Json::parse(in);
  EXPECT_EQ(g.at("type"), "FeatureCollection");
  EXPECT_NE(g.at("fieldguard").at("projection").get<std::string>().find("Gauss-Krueger"), std::string::npos);
  // The JSONL's obstacles of frames with a pose, in order: the features, one each.
  std::vector<Json> boxes;
  std::ifstream lines(jsonl);
  for (std::string line; std::getline(lines, line);) {
    const Json f = Json::parse(line);
    if (!f.contains("fusion") || f.at("fusion").at("levelling") != "full") continue;
    for (const Json& o : f.at("obstacles")) boxes.push_back(o);
  }
  const Json& features = g.at("features");
  ASSERT_FALSE(features.empty());
  ASSERT_EQ(features.size(), boxes.size());
  for (std::size_t i = 0; i < features.size(); ++i) {
    const Json& ring = features[i].at("geometry").at("coordinates").at(0);
    ASSERT_EQ(ring.size(), 5U);
    EXPECT_EQ(ring[0], ring[4]) << "not closed";
    // The simulator's default origin, 48.1 N 11.6 E: the field is within a few hundred metres of it.
    EXPECT_NEAR(ring[0][1].get<double>(), 48.1, 0.01);
    EXPECT_NEAR(ring[0][0].get<double>(), 11.6, 0.01);
    // Counter-clockwise (RFC 7946's exterior ring), and its sides the box's length and width.
    double area2 = 0.0;
    std::vector<std::pair<double, double>> m;
    for (std::size_t k = 0; k < 5; ++k) m.push_back(local_m(ring[k], ring[0]));
    for (std::size_t k = 0; k < 4; ++k) area2 += m[k].first * m[k + 1].second - m[k + 1].first * m[k].second;
    const double length = boxes[i].at("obb").at("length").get<double>();
    const double width = boxes[i].at("obb").at("width").get<double>();
    if (length * width > 1e-4) {
      EXPECT_GT(area2, 0.0) << features[i].dump();
    }
    const double side0 = std::hypot(m[1].first - m[0].first, m[1].second - m[0].second);
    const double side1 = std::hypot(m[2].first - m[1].first, m[2].second - m[1].second);
    EXPECT_NEAR(side0, length, 0.01) << features[i].dump();
    EXPECT_NEAR(side1, width, 0.01) << features[i].dump();
    EXPECT_EQ(features[i].at("properties").at("class"), boxes[i].at("class"));
    EXPECT_NEAR(features[i].at("properties").at("distance_m").get<double>(), boxes[i].at("distance").get<double>(),
                1e-3);
  }
}

TEST(GeoJson, ACaptureWithoutAPoseSaysSoAndWritesAnEmptyCollection) {
  testing::TempDir dir;
  const std::string geojson = (dir.path() / "o.geojson").string();
  const auto r =
      run_fieldguard("replay --quiet --config '" + kSource + "/config/fieldguard.yaml' --pcap '" +
                     std::string(FIELDGUARD_TEST_DATA) + "/hdl32e_monterey_600.pcap' --geojson-out '" + geojson + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("0 footprints from 0 frames with a pose; 4 frames without one"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("no frame had a full pose"), std::string::npos) << r.output;
  std::ifstream in(geojson);
  const Json g = Json::parse(in);
  EXPECT_TRUE(g.at("features").empty());
}

}  // namespace
}  // namespace fieldguard
