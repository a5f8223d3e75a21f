// fieldguard-score on hand-written frames with known answers.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "tools/tools_test_support.hpp"

namespace fieldguard::score {
namespace {

using Json = nlohmann::json;
using tools_test::run;
using tools_test::ScratchDir;
using tools_test::write_file;

// Ground truth, period 0.1 s:
//  0 (100.0) pedestrian at 12 m            -> detected (band 10-15)
//  1 (100.1) pedestrian at 27 m, 6 hits    -> missed (band 25-30); a false obstacle on a clod at 7 m (band 5-10)
//  2 (100.2) implement                     -> two obstacles: detected, over-segmented
//  3 (100.3) two haystacks 0.4 m apart     -> one obstacle: both detected, under-segmented
//  4 (100.4) crowns A, B (0.4 m apart), C, D, E (2 hits: not visible)
//            -> A, B true positives; C split in two; D missed; a false obstacle at 25.7 m (band 25-30)
//  5 (100.5) crowns F, G 0.4 m apart       -> one obstacle: both merged, under-segmented
//  6 (100.6) nothing detected at all       -> no detection frame: unmatched
//  7 (100.7) detection frame is partial    -> skipped
constexpr const char* kTruth =
    R"({"frame": 0, "stamp": 100.000000, "period_s": 0.1, "objects": [{"id": "p", "class": "pedestrian", "min": [12.0, -0.3, -0.95], "max": [12.5, 0.3, 0.8], "hits": 40, "raised_hits": 40, "distance_m": 12.0}], "terrain": []}
{"frame": 1, "stamp": 100.100000, "period_s": 0.1, "objects": [{"id": "p", "class": "pedestrian", "min": [27.0, -0.3, -0.95], "max": [27.5, 0.3, 0.8], "hits": 6, "raised_hits": 6, "distance_m": 27.0}], "terrain": [{"id": "c1", "class": "clod", "min": [6.9, 0.9, -0.95], "max": [7.3, 1.2, -0.6], "hits": 9, "raised_hits": 9}]}
{"frame": 2, "stamp": 100.200000, "period_s": 0.1, "objects": [{"id": "i", "class": "implement", "min": [20.0, -2.0, -0.95], "max": [23.0, 0.5, 0.55], "hits": 200, "raised_hits": 200, "distance_m": 20.0}]}

{"frame": 3, "stamp": 100.300000, "period_s": 0.1, "objects": [{"id": "h1", "class": "haystack", "min": [15.0, 3.0, -0.95], "max": [16.5, 4.2, 0.55], "hits": 90, "raised_hits": 90, "distance_m": 15.3}, {"id": "h2", "class": "haystack", "min": [15.0, 4.6, -0.95], "max": [16.5, 5.8, 0.55], "hits": 80, "raised_hits": 80, "distance_m": 15.7}]}
{"frame": 4, "stamp": 100.400000, "period_s": 0.1, "objects": [{"id": "A", "class": "crown", "min": [10.0, -3.0, 0.0], "max": [12.0, -1.0, 2.0], "hits": 50, "raised_hits": 50}, {"id": "B", "class": "crown", "min": [12.4, -3.0, 0.0], "max": [14.4, -1.0, 2.0], "hits": 40, "raised_hits": 40}, {"id": "C", "class": "crown", "min": [20.0, -3.0, 0.0], "max": [22.0, -1.0, 2.0], "hits": 30, "raised_hits": 30}, {"id": "D", "class": "crown", "min": [30.0, 2.0, 0.0], "max": [32.0, 4.0, 2.0], "hits": 20, "raised_hits": 20}, {"id": "E", "class": "crown", "min": [40.0, 2.0, 0.0], "max": [42.0, 4.0, 2.0], "hits": 2, "raised_hits": 2}]}
{"frame": 5, "stamp": 100.500000, "period_s": 0.1, "objects": [{"id": "F", "class": "crown", "min": [10.0, -3.0, 0.0], "max": [12.0, -1.0, 2.0], "hits": 50, "raised_hits": 50}, {"id": "G", "class": "crown", "min": [12.4, -3.0, 0.0], "max": [14.4, -1.0, 2.0], "hits": 40, "raised_hits": 40}]}
{"frame": 6, "stamp": 100.600000, "period_s": 0.1, "objects": []}
{"frame": 7, "stamp": 100.700000, "period_s": 0.1, "objects": []}
)";

// Detection frames are numbered from 1 (the replay saw a partial rotation first) and come slightly late:
// they must be paired by stamp. One frame (99.5) has no truth.
constexpr const char* kDetections =
    R"({"frame": 1, "stamp": 100.0004, "points_in": 60000, "obstacles": [{"min": [12.05, -0.2, -0.9], "max": [12.4, 0.25, 0.7], "points": 30}]}
{"frame": 0, "stamp": 99.5, "points_in": 100, "partial": true, "obstacles": []}
{"frame": 2, "stamp": 100.1004, "points_in": 60000, "obstacles": [{"min": [7.0, 1.0, -0.9], "max": [7.4, 1.3, -0.5], "points": 12}]}
{"frame": 3, "stamp": 100.2004, "points_in": 60000, "partial": false, "obstacles": [{"min": [20.0, -2.0, -0.9], "max": [21.2, 0.5, 0.5], "points": 60}, {"min": [21.8, -2.0, -0.9], "max": [23.0, 0.5, 0.5], "points": 70}]}
{"frame": 4, "stamp": 100.3004, "points_in": 60000, "obstacles": [{"min": [15.0, 3.0, -0.9], "max": [16.5, 5.8, 0.5], "points": 150, "distance_m": 15.3}]}
{"frame": 5, "stamp": 100.4004, "points_in": 60000, "obstacles": [{"min": [10.0, -2.9, 0.1], "max": [12.15, -1.1, 1.9]}, {"min": [12.5, -2.9, 0.1], "max": [14.3, -1.1, 1.9]}, {"min": [20.0, -3.0, 0.1], "max": [21.0, -1.0, 1.9]}, {"min": [21.1, -3.0, 0.1], "max": [22.0, -1.0, 1.9]}, {"min": [25.0, 6.0, 0.0], "max": [25.5, 6.5, 1.0]}]}
{"frame": 6, "stamp": 100.5004, "points_in": 60000, "obstacles": [{"min": [10.1, -2.9, 0.1], "max": [14.3, -1.1, 1.9]}]}
{"frame": 8, "stamp": 100.7004, "points_in": 30000, "partial": true, "obstacles": [{"min": [5.0, 5.0, 0.0], "max": [5.5, 5.5, 1.0]}]}
)";

class ScoreCli : public ::testing::Test {
 protected:
  void SetUp() override {
    write_file(dir_.file("truth.jsonl"), kTruth);
    write_file(dir_.file("det.jsonl"), kDetections);
  }
  [[nodiscard]] Json score_json(const std::string& extra = "", const std::string& detections = "det.jsonl",
                                const std::string& truth = "truth.jsonl") const {
    const auto r =
        run(FIELDGUARD_SCORE, "--json --detections " + dir_.file(detections) + " --truth " + dir_.file(truth) + extra);
    EXPECT_EQ(r.exit_code, 0) << r.errors;
    Json parsed = Json::parse(r.output, nullptr, /*allow_exceptions=*/false);
    EXPECT_FALSE(parsed.is_discarded()) << r.output;
    return parsed.is_discarded() ? Json::object() : parsed;
  }
  // The number at `path`; -1 if a key is missing, -2 for null.
  static double num(const Json& v, std::initializer_list<const char*> path) {
    const Json* p = &v;
    for (const char* k : path) {
      const auto it = p->find(k);
      if (it == p->end()) return -1.0;
      p = &*it;
    }
    return p->is_null() ? -2.0 : p->get<double>();
  }
  static const Json& band(const Json& v, const char* list, std::size_t i) { return v.at(list).at(i); }
  ScratchDir dir_{"score"};
};

TEST_F(ScoreCli, FramesArePairedByStamp) {
  const Json v = score_json();
  EXPECT_EQ(num(v, {"frames", "truth"}), 8);
  EXPECT_EQ(num(v, {"frames", "detections"}), 8);
  EXPECT_EQ(num(v, {"frames", "matched"}), 7);
  EXPECT_EQ(num(v, {"frames", "partial_skipped"}), 1);
  EXPECT_EQ(num(v, {"frames", "scored"}), 6);
  const Json& tu = v.at("frames").at("truth_unmatched_lines");
  ASSERT_EQ(tu.size(), 1U);
  EXPECT_EQ(tu[0], 8);  // line 8 of the truth file: frame 6 (line 4 is blank)
  const Json& du = v.at("frames").at("detections_unmatched_lines");
  ASSERT_EQ(du.size(), 1U);
  EXPECT_EQ(du[0], 2);
  EXPECT_NEAR(num(v, {"params", "tolerance_s"}), 0.05, 1e-9);
}

TEST_F(ScoreCli, PedestrianDetectionAndMissByBand) {
  const Json v = score_json();
  const Json& b10 = band(v, "pedestrian", 2);
  EXPECT_EQ(b10.at("band"), "10-15");
  EXPECT_EQ(b10.at("visible").get<double>(), 1);
  EXPECT_EQ(b10.at("detected").get<double>(), 1);
  EXPECT_EQ(b10.at("rate").get<double>(), 1.0);
  const Json& b25 = band(v, "pedestrian", 5);
  EXPECT_EQ(b25.at("visible").get<double>(), 1);
  EXPECT_EQ(b25.at("detected").get<double>(), 0);
  EXPECT_TRUE(band(v, "pedestrian", 0).at("rate").is_null());
  EXPECT_EQ(num(v, {"classes", "pedestrian", "visible"}), 2);
  EXPECT_EQ(num(v, {"classes", "pedestrian", "detected"}), 1);
  // With --min-hits 7 the 6-return pedestrian is not visible: the miss no longer counts.
  const Json w = score_json(" --min-hits 7");
  EXPECT_EQ(band(w, "pedestrian", 5).at("visible").get<double>(), 0);
}

TEST_F(ScoreCli, GroundFalseDetectionsByBand) {
  const Json v = score_json();
  for (std::size_t b = 0; b < 8; ++b) {
    const Json& g = band(v, "ground_false", b);
    EXPECT_EQ(g.at("frames").get<double>(), 6) << b;
    const double expected = (b == 1 || b == 5) ? 1.0 : 0.0;  // the clod at 7 m; the obstacle at 25.7 m
    EXPECT_EQ(g.at("false_frames").get<double>(), expected) << b;
  }
  EXPECT_NEAR(band(v, "ground_false", 1).at("rate").get<double>(), 1.0 / 6.0, 1e-6);
  EXPECT_EQ(num(v, {"obstacles", "total"}), 11);
  EXPECT_EQ(num(v, {"obstacles", "false"}), 2);
  EXPECT_EQ(num(v, {"obstacles", "false_by_cause", "clod"}), 1);
  EXPECT_EQ(num(v, {"obstacles", "false_by_cause", "none"}), 1);
}

TEST_F(ScoreCli, ClassesAndSegmentation) {
  const Json v = score_json();
  EXPECT_EQ(num(v, {"classes", "implement", "rate"}), 1.0);
  EXPECT_EQ(num(v, {"classes", "haystack", "detected"}), 2);
  EXPECT_EQ(num(v, {"classes", "crown", "visible"}), 6);
  EXPECT_EQ(num(v, {"classes", "crown", "detected"}), 5);
  EXPECT_EQ(num(v, {"segmentation", "over"}), 2);   // the implement, crown C
  EXPECT_EQ(num(v, {"segmentation", "under"}), 2);  // the haystacks, crowns F+G
}

TEST_F(ScoreCli, CrownTruePositivesFalseAndMissed) {
  const Json v = score_json();
  EXPECT_EQ(num(v, {"crowns", "visible"}), 6);
  EXPECT_EQ(num(v, {"crowns", "tp"}), 2);
  EXPECT_EQ(num(v, {"crowns", "split"}), 1);
  EXPECT_EQ(num(v, {"crowns", "missed"}), 1);
  EXPECT_EQ(num(v, {"crowns", "merged"}), 2);
  EXPECT_NEAR(num(v, {"crowns", "tp_rate"}), 2.0 / 6.0, 1e-6);
  EXPECT_EQ(num(v, {"crowns", "frames"}), 2);
  EXPECT_EQ(num(v, {"crowns", "obstacles"}), 6);
  EXPECT_EQ(num(v, {"crowns", "false_obstacles"}), 1);
  // A and B are 0.4 m apart and A's obstacle reaches 0.15 m past A: with the 0.3 m margin alone it would also
  // match B (A merged, B split); the overlap rule does not let a 5 cm sliver count.
  const Json loose = score_json(" --min-overlap 0");
  EXPECT_EQ(num(loose, {"crowns", "tp"}), 0);
}

// A crown seen by one ray through its foliage and two at its trunk's foot (9 returns, 1 raised) is not
// visible: nothing that shows that little of itself above terrain height can be told from a clod or a stray
// return. The old rule (--min-raised-hits 0) counts it, and its miss.
TEST_F(ScoreCli, ReturnsBelowTerrainHeightDoNotMakeAnObjectVisible) {
  write_file(
      dir_.file("raised.truth.jsonl"),
      R"({"frame": 0, "stamp": 200.0, "period_s": 0.1, "objects": [)"
      R"({"id": "T", "class": "crown", "min": [20.0, 2.0, -1.0], "max": [22.0, 4.0, 2.0], "hits": 9, "raised_hits": 1},)"
      R"( {"id": "U", "class": "crown", "min": [20.0, -4.0, -1.0], "max": [22.0, -2.0, 2.0], "hits": 12, "raised_hits": 12},)"
      R"( {"id": "P", "class": "pedestrian", "min": [30.0, -0.3, -1.0], "max": [30.5, 0.3, 0.8], "hits": 4, "raised_hits": 2, "distance_m": 30.0}]})"
      "\n");
  write_file(dir_.file("raised.det.jsonl"),
             R"({"frame": 0, "stamp": 200.0, "obstacles": [{"min": [20.2, -3.8, 0.5], "max": [21.8, -2.2, 1.9]}]})"
             "\n");
  const auto score = [&](const std::string& extra) {
    return score_json(extra, "raised.det.jsonl", "raised.truth.jsonl");
  };
  const Json v = score("");
  EXPECT_EQ(num(v, {"params", "min_raised_hits"}), 3);
  EXPECT_EQ(num(v, {"crowns", "visible"}), 1);
  EXPECT_EQ(num(v, {"crowns", "tp"}), 1);
  EXPECT_EQ(num(v, {"crowns", "missed"}), 0);
  EXPECT_EQ(num(v, {"classes", "pedestrian", "visible"}), -1);  // no visible pedestrian: no entry
  const Json old = score(" --min-raised-hits 0");
  EXPECT_EQ(num(old, {"crowns", "visible"}), 2);
  EXPECT_EQ(num(old, {"crowns", "missed"}), 1);
  EXPECT_EQ(num(old, {"classes", "pedestrian", "visible"}), 1);
  EXPECT_EQ(num(old, {"classes", "pedestrian", "detected"}), 0);
  // Two raised returns are enough when asked for two: the pedestrian counts, and is missed.
  EXPECT_EQ(num(score(" --min-raised-hits 2"), {"classes", "pedestrian", "visible"}), 1);
}

TEST_F(ScoreCli, TruthWithoutRaisedHitsIsRefusedUnlessTheOldRuleIsAsked) {
  write_file(
      dir_.file("old.truth.jsonl"),
      R"({"frame": 0, "stamp": 100.0, "period_s": 0.1, "objects": [{"id": "p", "class": "pedestrian", "min": [12.0, -0.3, -0.95], "max": [12.5, 0.3, 0.8], "hits": 40}]})"
      "\n");
  auto r = run(FIELDGUARD_SCORE, "--detections " + dir_.file("det.jsonl") + " --truth " + dir_.file("old.truth.jsonl"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.errors.find("old.truth.jsonl:1: p has no \"raised_hits\""), std::string::npos) << r.errors;
  EXPECT_NE(r.errors.find("--min-raised-hits 0"), std::string::npos) << r.errors;
  EXPECT_EQ(
      num(score_json(" --min-raised-hits 0", "det.jsonl", "old.truth.jsonl"), {"classes", "pedestrian", "detected"}),
      1);

  write_file(
      dir_.file("more.truth.jsonl"),
      R"({"frame": 0, "stamp": 100.0, "objects": [{"id": "p", "class": "pedestrian", "min": [12.0, -0.3, -0.95], "max": [12.5, 0.3, 0.8], "hits": 4, "raised_hits": 5}]})"
      "\n");
  r = run(FIELDGUARD_SCORE, "--detections " + dir_.file("det.jsonl") + " --truth " + dir_.file("more.truth.jsonl"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.errors.find("more.truth.jsonl:1: objects[0]: \"raised_hits\" must be from 0 to \"hits\""),
            std::string::npos)
      << r.errors;
  EXPECT_EQ(run(FIELDGUARD_SCORE, "--detections a --truth b --min-raised-hits -1").exit_code, 2);
}

TEST_F(ScoreCli, PartialFramesCanBeIncluded) {
  const Json v = score_json(" --include-partial");
  EXPECT_EQ(num(v, {"frames", "scored"}), 7);
  EXPECT_EQ(num(v, {"obstacles", "false"}), 3);
}

TEST_F(ScoreCli, TextReport) {
  const auto r =
      run(FIELDGUARD_SCORE, "--detections " + dir_.file("det.jsonl") + " --truth " + dir_.file("truth.jsonl"));
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.output.find("25-30"), std::string::npos);
  EXPECT_NE(r.output.find("true positive 2"), std::string::npos);
}

TEST_F(ScoreCli, UnusableInputExitsTwoNamingFileAndLine) {
  write_file(dir_.file("bad.jsonl"), std::string(kDetections).replace(0, 1, "x"));
  auto r = run(FIELDGUARD_SCORE, "--detections " + dir_.file("bad.jsonl") + " --truth " + dir_.file("truth.jsonl"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.errors.find("bad.jsonl:1:"), std::string::npos) << r.errors;

  write_file(dir_.file("bad2.jsonl"),
             "{\"stamp\": 1.0, \"obstacles\": []}\n{\"stamp\": 1.1, \"obstacles\": [{\"min\": [0, 0], \"max\": [1, 1, "
             "1]}]}\n");
  r = run(FIELDGUARD_SCORE, "--detections " + dir_.file("bad2.jsonl") + " --truth " + dir_.file("truth.jsonl"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.errors.find("bad2.jsonl:2: obstacles[0]"), std::string::npos) << r.errors;

  write_file(dir_.file("bad3.jsonl"), "{\"stamp\": 1.0}\n");
  r = run(FIELDGUARD_SCORE, "--detections " + dir_.file("bad3.jsonl") + " --truth " + dir_.file("truth.jsonl"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.errors.find("missing \"obstacles\""), std::string::npos) << r.errors;

  r = run(FIELDGUARD_SCORE, "--detections " + dir_.file("nope.jsonl") + " --truth " + dir_.file("truth.jsonl"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.errors.find("nope.jsonl"), std::string::npos);

  write_file(dir_.file("badtruth.jsonl"),
             "{\"stamp\": 1.0, \"objects\": [{\"min\": [0,0,0], \"max\": [1,1,1], \"hits\": 3}]}\n");
  r = run(FIELDGUARD_SCORE, "--detections " + dir_.file("det.jsonl") + " --truth " + dir_.file("badtruth.jsonl"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.errors.find("badtruth.jsonl:1: objects[0]: \"class\""), std::string::npos) << r.errors;

  EXPECT_EQ(run(FIELDGUARD_SCORE, "--truth " + dir_.file("truth.jsonl")).exit_code, 2);
  EXPECT_EQ(run(FIELDGUARD_SCORE, "--detections a --truth b --margin -1").exit_code, 2);
  EXPECT_EQ(run(FIELDGUARD_SCORE, "--detections a --truth b --region 1,2,3").exit_code, 2);
}

}  // namespace
}  // namespace fieldguard::score
