// The Foxglove messages of a frame: base64 against RFC 4648's vectors, each message valid JSON whose point
// bytes decode back to the frame's points, labels and boxes, the decision as the safety monitor made it.
// Validation against @foxglove/schemas itself is tests/app/mcap_interop_test.cpp's.

#include "fieldguard/writers/foxglove_json.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/json_reader.hpp"

namespace fieldguard::app {
namespace {

using testing::Json;

std::string b64(std::string_view s) {
  std::string out;
  foxglove::base64(out, std::as_bytes(std::span(s.data(), s.size())));
  return out;
}

std::vector<unsigned char> unbase64(const std::string& s) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
  };
  std::vector<unsigned char> out;
  unsigned bits = 0;
  int n = 0;
  for (const char c : s) {
    const int v = value(c);
    if (v < 0) break;
    bits = (bits << 6U) | static_cast<unsigned>(v);
    n += 6;
    if (n >= 8) {
      n -= 8;
      out.push_back(static_cast<unsigned char>((bits >> static_cast<unsigned>(n)) & 0xFFU));
    }
  }
  return out;
}

template <class T>
T at(const std::vector<unsigned char>& b, std::size_t offset) {
  T v{};
  std::memcpy(&v, b.data() + offset, sizeof v);
  return v;
}

TEST(FoxgloveJson, Base64MatchesRfc4648) {
  EXPECT_EQ(b64(""), "");
  EXPECT_EQ(b64("f"), "Zg==");
  EXPECT_EQ(b64("fo"), "Zm8=");
  EXPECT_EQ(b64("foo"), "Zm9v");
  EXPECT_EQ(b64("foob"), "Zm9vYg==");
  EXPECT_EQ(b64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(b64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(b64("\xff\xfe\xfd"), "//79");
}

TEST(FoxgloveJson, EverySchemaIsJsonNamingItsTitle) {
  ASSERT_EQ(foxglove::schemas().size(), 6U);
  for (const auto& s : foxglove::schemas()) {
    const Json j = Json::parse(s.json);
    EXPECT_EQ(j.at("title"), s.name);
    EXPECT_EQ(j.at("type"), "object");
    EXPECT_FALSE(j.at("required").empty()) << s.name;
  }
  EXPECT_EQ(foxglove::schema("foxglove.PointCloud").name, "foxglove.PointCloud");
  EXPECT_THROW(static_cast<void>(foxglove::schema("foxglove.Nothing")), std::out_of_range);
  // The point data is marked base64, which is how Foxglove knows to decode a JSON message's bytes.
  const Json pc = Json::parse(foxglove::schema("foxglove.PointCloud").json);
  EXPECT_EQ(pc.at("properties").at("data").at("contentEncoding"), "base64");
}

TEST(FoxgloveJson, RawCloudDecodesToTheFramePoints) {
  LidarFrame f;
  LidarPoint a;
  a.x = 1.5F;
  a.y = -2.25F;
  a.z = 0.125F;
  a.intensity = 300.F;  // beyond a byte: clamped
  a.ring = 31;
  LidarPoint b = a;
  b.x = -7.F;
  b.intensity = 17.F;
  b.source = 1;
  b.ring = 540;
  f.points = {a, b};
  std::string out;
  foxglove::raw_cloud(out, 1'700'000'000'123'456'789, f);
  const Json j = Json::parse(out);
  EXPECT_EQ(j.at("timestamp").at("sec"), 1'700'000'000);
  EXPECT_EQ(j.at("timestamp").at("nsec"), 123'456'789);
  EXPECT_EQ(j.at("frame_id"), "lidar");
  EXPECT_EQ(j.at("point_stride"), 16);
  const auto bytes = unbase64(j.at("data").get<std::string>());
  ASSERT_EQ(bytes.size(), 32U);
  EXPECT_EQ(at<float>(bytes, 0), 1.5F);
  EXPECT_EQ(at<float>(bytes, 4), -2.25F);
  EXPECT_EQ(at<float>(bytes, 8), 0.125F);
  EXPECT_EQ(at<std::uint8_t>(bytes, 12), 255);
  EXPECT_EQ(at<std::uint16_t>(bytes, 14), 31);
  EXPECT_EQ(at<float>(bytes, 16), -7.F);
  EXPECT_EQ(at<std::uint8_t>(bytes, 28), 17);
  EXPECT_EQ(at<std::uint8_t>(bytes, 29), 1);
  EXPECT_EQ(at<std::uint16_t>(bytes, 30), 540);
  // Each field's offset and type as the bytes are laid out (7 float32, 1 uint8, 3 uint16).
  const Json& fields = j.at("fields");
  ASSERT_EQ(fields.size(), 6U);
  EXPECT_EQ(fields[3].at("name"), "intensity");
  EXPECT_EQ(fields[3].at("offset"), 12);
  EXPECT_EQ(fields[3].at("type"), 1);
  EXPECT_EQ(fields[5].at("name"), "ring");
  EXPECT_EQ(fields[5].at("type"), 3);
}

TEST(FoxgloveJson, LabelledCloudNamesTheBoxOfEachObstaclePoint) {
  perception::Obstacle o;
  o.min = {4.F, -1.F, -1.F};
  o.max = {5.F, 1.F, 1.F};
  const std::vector<perception::Obstacle> obstacles = {perception::Obstacle{}, o};  // the first holds nothing here
  const std::vector<perception::LabeledPoint> points = {{4.5F, 0.F, 0.F, perception::PointLabel::Obstacle},
                                                        {9.F, 0.F, -1.F, perception::PointLabel::Ground},
                                                        {4.5F, 0.F, 0.F, perception::PointLabel::Rejected}};
  std::string out;
  foxglove::labelled_cloud(out, 5, points, obstacles);
  const auto bytes = unbase64(Json::parse(out).at("data").get<std::string>());
  ASSERT_EQ(bytes.size(), 48U);
  EXPECT_EQ(at<std::uint8_t>(bytes, 12), 1);  // obstacle
  EXPECT_EQ(at<std::int16_t>(bytes, 14), 1);
  EXPECT_EQ(at<std::uint8_t>(bytes, 28), 0);  // ground
  EXPECT_EQ(at<std::int16_t>(bytes, 30), -1);
  EXPECT_EQ(at<std::uint8_t>(bytes, 44), 2);  // rejected: no box even inside one
  EXPECT_EQ(at<std::int16_t>(bytes, 46), -1);
}

TEST(FoxgloveJson, ObstacleInTheZoneIsRedAndLabelledWithItsDistance) {
  perception::Obstacle in;
  in.min = {5.F, -0.3F, -0.9F};
  in.max = {5.4F, 0.3F, 0.8F};
  in.obb_center = {5.2F, 0.F};
  in.obb_length_m = 0.4F;
  in.obb_width_m = 0.6F;
  in.distance_m = 5.F;
  in.height_above_ground_m = 1.7F;
  perception::Obstacle out_of_zone = in;
  out_of_zone.min[1] = 8.F;
  out_of_zone.max[1] = 9.F;
  out_of_zone.obb_center = {5.2F, 8.5F};
  out_of_zone.distance_m = 9.9F;
  output::safety::Zone zone{0.4, 12.0, 2.0, false};
  std::string msg;
  const std::vector<perception::Obstacle> obstacles = {in, out_of_zone};
  foxglove::obstacles_scene(msg, 1, obstacles, &zone);
  const Json j = Json::parse(msg);
  const Json& e = j.at("entities").at(0);
  EXPECT_EQ(e.at("id"), "obstacles");
  ASSERT_EQ(e.at("cubes").size(), 2U);
  EXPECT_GT(e.at("cubes")[0].at("color").at("r").get<double>(), 0.8);
  EXPECT_LT(e.at("cubes")[0].at("color").at("g").get<double>(), 0.2);
  EXPECT_GT(e.at("cubes")[1].at("color").at("g").get<double>(), 0.4);  // orange: outside the zone
  EXPECT_NEAR(e.at("cubes")[0].at("size").at("z").get<double>(), 1.7, 1e-3);
  EXPECT_NEAR(e.at("cubes")[0].at("pose").at("position").at("z").get<double>(), -0.05, 1e-3);
  ASSERT_EQ(e.at("texts").size(), 2U);
  EXPECT_EQ(e.at("texts")[0].at("text"), "5.0 m, 1.7 m high");
  EXPECT_EQ(e.at("texts")[1].at("text"), "9.9 m, 1.7 m high");
}

TEST(FoxgloveJson, DecisionCarriesTheHeadlineAndReasons) {
  output::safety::Decision d;
  d.stop = true;
  d.reason = output::safety::Reason::ObstacleInZone;
  d.reasons = output::safety::bit(output::safety::Reason::ObstacleInZone);
  d.nearest_m = 5.4F;
  d.obstacles_in_zone = 1;
  d.zone = {0.4, 14.5, 2.0, true};
  std::string msg;
  foxglove::decision(msg, 2'000'000'000, 17, d, 3);
  Json j = Json::parse(msg);
  EXPECT_EQ(j.at("frame"), 17);
  EXPECT_TRUE(j.at("stop").get<bool>());
  EXPECT_EQ(j.at("reason"), "obstacle in zone");
  EXPECT_EQ(j.at("reasons"), Json::array({"obstacle in zone"}));
  EXPECT_EQ(j.at("headline"), "STOP obstacle 5.4 m ahead");
  EXPECT_NEAR(j.at("nearest_m").get<double>(), 5.4, 1e-6);
  EXPECT_NEAR(j.at("zone").at("x_max").get<double>(), 14.5, 1e-6);

  d = output::safety::Decision{};
  d.stop = false;
  d.reason = output::safety::Reason::None;
  foxglove::decision(msg, 1, 18, d, 3);
  j = Json::parse(msg);
  EXPECT_EQ(j.at("headline"), "GO");
  EXPECT_TRUE(j.at("nearest_m").is_null());
  EXPECT_TRUE(j.at("reasons").empty());
}

TEST(FoxgloveJson, StopZoneColourFollowsTheDecision) {
  output::safety::Decision d;
  d.zone = {0.4, 10.0, 2.0, false};
  d.stop = true;
  std::string msg;
  foxglove::zones_scene(msg, 1, perception::Box3{{-10, -10, -6}, {52, 10, 6}},
                        perception::Box3{{-5, -1.5, -1.5}, {0.4, 1.5, 1.5}}, -0.95, &d);
  Json j = Json::parse(msg);
  const Json& lines = j.at("entities").at(0).at("lines");
  ASSERT_EQ(lines.size(), 3U);  // ROI, body, stop zone
  EXPECT_EQ(lines[2].at("type"), 1);
  EXPECT_EQ(lines[2].at("points").size(), 4U);
  EXPECT_NEAR(lines[2].at("points")[1].at("x").get<double>(), 10.0, 1e-9);
  EXPECT_GT(lines[2].at("color").at("r").get<double>(), 0.8);
  EXPECT_EQ(j.at("entities").at(0).at("texts").at(0).at("text"), "stop zone: STOP");
  d.stop = false;
  foxglove::zones_scene(msg, 1, perception::Box3{}, perception::Box3{}, -0.95, &d);
  j = Json::parse(msg);
  EXPECT_GT(j.at("entities").at(0).at("lines")[2].at("color").at("g").get<double>(), 0.6);
  // Without a decision: only the ROI and the body box.
  foxglove::zones_scene(msg, 1, perception::Box3{}, perception::Box3{}, -0.95, nullptr);
  EXPECT_EQ(Json::parse(msg).at("entities").at(0).at("lines").size(), 2U);
}

TEST(FoxgloveJson, FrameTransformIsThePoseLessTheOrigin) {
  perception::FramePose p;
  p.x_m = 500'010.5;
  p.y_m = 4'000'020.25;
  p.z_m = 101.0;
  p.yaw_rad = std::numbers::pi / 2;
  std::string msg;
  foxglove::frame_transform(msg, 1, p, {500'000.0, 4'000'000.0, 100.0});
  const Json j = Json::parse(msg);
  EXPECT_EQ(j.at("parent_frame_id"), "field");
  EXPECT_EQ(j.at("child_frame_id"), "lidar");
  EXPECT_NEAR(j.at("translation").at("x").get<double>(), 10.5, 1e-9);
  EXPECT_NEAR(j.at("translation").at("y").get<double>(), 20.25, 1e-9);
  EXPECT_NEAR(j.at("rotation").at("z").get<double>(), std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(j.at("rotation").at("w").get<double>(), std::sqrt(0.5), 1e-6);
}

TEST(FoxgloveJson, HealthListsEverySensorWithTheStatusLine) {
  const std::vector<foxglove::SensorState> sensors = {
      {"lidar", "ok", 10.0}, {"gnss", "silent 1.4 s", 0.0}, {"ahrs", "off", 0.0}};
  std::string msg;
  foxglove::health(msg, 3'000'000'001, sensors, "STOP gnss silent | gnss silent 1.4 s");
  const Json j = Json::parse(msg);
  EXPECT_EQ(j.at("timestamp").at("sec"), 3);
  EXPECT_EQ(j.at("timestamp").at("nsec"), 1);
  ASSERT_EQ(j.at("sensors").size(), 3U);
  EXPECT_EQ(j.at("sensors")[1].at("state"), "silent 1.4 s");
  EXPECT_NEAR(j.at("sensors")[0].at("rate_hz").get<double>(), 10.0, 1e-9);
  EXPECT_EQ(j.at("status"), "STOP gnss silent | gnss silent 1.4 s");
}

TEST(FoxgloveJson, LocationFixInDegrees) {
  std::string msg;
  foxglove::location_fix(msg, 1, geo::Geodetic{52.123456789, 13.5, 44.25});
  const Json j = Json::parse(msg);
  EXPECT_NEAR(j.at("latitude").get<double>(), 52.123456789, 1e-9);
  EXPECT_NEAR(j.at("longitude").get<double>(), 13.5, 1e-9);
  EXPECT_EQ(j.at("position_covariance").size(), 9U);
}

}  // namespace
}  // namespace fieldguard::app
