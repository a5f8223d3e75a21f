// The whole detection chain on a small simulated scene: fieldguard-sim writes a capture with its ground truth,
// `fieldguard replay` runs config/fieldguard.yaml's pipeline over it, and the scorer holds the obstacles to the
// truth. The scene is the rough field (clods up to 40 cm, a 35 cm ridge, 3.5 degrees of roll and 3 of pitch)
// with the pedestrian crossing at 5 to 30 m: a ground segmentation that takes the ridge or clods for obstacles,
// or a clustering that splits or drops the far pedestrian's few returns, fails it. The orchard holds the crowns:
// a clustering radius that does not grow with range the right way, or a cluster stage or ground rule switched
// off, fails it.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "score/frames.hpp"
#include "score/metrics.hpp"
#include "tools/tools_test_support.hpp"

namespace fieldguard::score {
namespace {

using tools_test::run;
using tools_test::ScratchDir;

// Six rotations per crossing (5, 10, ..., 30 m): a few seconds of CPU even in a sanitizer Debug build.
constexpr int kRotations = 36;
// The orchard's first four seconds: 38 scored frames, 1,250 visible crowns.
constexpr int kOrchardRotations = 40;

struct Outcome {
  ScoreReport report;
  std::string log;
  std::string summary;    // replay's stdout
  std::string obstacles;  // the obstacles.jsonl
};

Outcome sim_replay_score(const std::string& config, const ScratchDir& dir,
                         const std::string& scene = "rough-pedestrian", int rotations = kRotations) {
  Outcome o;
  const std::string pcap = dir.file("scene.pcap");
  const std::string truth = dir.file("scene.truth.jsonl");
  const std::string obstacles = dir.file("scene.obstacles.jsonl");
  const auto sim = run(FIELDGUARD_SIM, "--scene " + scene + " --rotations " + std::to_string(rotations) +
                                           " --seed 1 --quiet --pcap '" + pcap + "'");
  EXPECT_EQ(sim.exit_code, 0) << sim.errors;
  const auto replay = run(FIELDGUARD_BINARY, "replay --quiet --config '" + config + "' --pcap '" + pcap +
                                                 "' --obstacles-out '" + obstacles + "'");
  EXPECT_EQ(replay.exit_code, 0) << replay.errors;
  o.log = sim.errors + replay.errors;
  o.summary = replay.output;
  o.obstacles = tools_test::read_file(obstacles);
  std::vector<TruthFrame> t;
  std::vector<DetectionFrame> d;
  std::string error;
  EXPECT_TRUE(read_truth(truth, t, error)) << error;
  EXPECT_TRUE(read_detections(obstacles, d, error)) << error;
  o.report = score(t, d, ScoreParams{});
  return o;
}

TEST(SimScorePipeline, RoughFieldPedestrianCrossingsWithOurConfig) {
  const ScratchDir dir("sim_score_pipeline");
  const Outcome o = sim_replay_score(std::string(FIELDGUARD_CONFIG_DIR) + "/fieldguard.yaml", dir);
  const ScoreReport& r = o.report;
  ASSERT_EQ(r.matched_frames, static_cast<std::size_t>(kRotations)) << o.log;
  ASSERT_GE(r.scored_frames, static_cast<std::size_t>(kRotations - 2));  // the first and last are partial

  // Every crossing is seen in every scored frame at 5-25 m, and at 30 m (side-on, a handful of returns) in all
  // but one. (On the full scene the acceptance is >= 99 % and >= 97 %; six frames a band allow no finer.)
  std::uint64_t visible = 0, missed = 0;
  for (std::size_t b = 1; b <= 6; ++b) {
    const Rate& p = r.pedestrian[b];
    EXPECT_GE(p.total, 4U) << "band " << band_name(b) << ": the scene has a crossing in every band";
    visible += p.total;
    missed += p.total - p.hits;
    if (b <= 5) {
      EXPECT_EQ(p.hits, p.total) << "pedestrian missed in band " << band_name(b);
    }
  }
  EXPECT_GE(visible, 30U);
  EXPECT_LE(missed, 1U) << "pedestrian frames missed: " << missed << " of " << visible;
  // One person, one obstacle: at 25-30 m an HDL-32E's rings cross the body 0.6-0.7 m apart, and a radius that
  // does not grow with range makes one cluster per ring.
  EXPECT_EQ(r.over_segmented, 0U);

  // Nothing but the pedestrian is an obstacle here: clods, the ridge and the tilted ground are terrain.
  std::string causes;
  for (const auto& [cause, n] : r.false_causes) causes += " " + cause + " " + std::to_string(n);
  EXPECT_LE(r.false_obstacles, 1U) << "false obstacles, by what they lie on:" << causes;
  EXPECT_EQ(r.under_segmented, 0U);
}

// Orchard rows of crowns of different sizes, some 0.3-0.5 m apart. Measured on these frames: 98.4 % true
// positives, no crown merged, 4 split, no false obstacle. Each of these broken stages fails it (measured on the
// same frames): a fixed 0.6 m radius (92.3 %: far crowns split by ring), a radius that grows alike in every
// direction (58.6 %: neighbouring crowns merged), the split off (97.4 %, 12 merged), the ground's lower envelope
// off (95.5 %: crowns behind a row taken for ground), one RANSAC plane (95.5 %), a horizontal radius of 3 beam
// spacings (94.8 %, 50 merged), floating fragments not joined to what stands under them (97.0 %, 21 split).
TEST(SimScorePipeline, OrchardCrownsWithOurConfig) {
  const ScratchDir dir("sim_score_orchard");
  const Outcome o =
      sim_replay_score(std::string(FIELDGUARD_CONFIG_DIR) + "/fieldguard.yaml", dir, "orchard", kOrchardRotations);
  const CrownStats& c = o.report.crowns;
  ASSERT_GE(o.report.scored_frames, static_cast<std::size_t>(kOrchardRotations - 2)) << o.log;
  ASSERT_GE(c.visible, 1000U);
  // The full scene's acceptance is 97 %; on these frames a working pipeline leaves about 20 crowns of 1,250.
  EXPECT_GE(c.tp * 1000, c.visible * 975) << "crown true positives " << c.tp << " of " << c.visible;
  EXPECT_LE(c.merged * 200, c.visible) << "crowns merged: " << c.merged;
  EXPECT_LE(c.split * 100, c.visible) << "crowns split: " << c.split;
  EXPECT_LE(c.false_obstacles * 200, c.obstacles) << "false obstacles among crowns: " << c.false_obstacles;
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// The hold (obstacle_hold.hpp) in replay: the orchard's first ten seconds with and without it, the same capture.
// Measured: 10 obstacles held, 6 more crown frames detected (3,343 against 3,337 of 3,401), no false obstacle
// either way. Held obstacles are flagged in the JSON and counted in the summary; each is a crown (a held
// obstacle on nothing would be a false one) and none splits a crown the filters reported. A hold that is not
// called, not written, or that makes its boxes anywhere but on the fragments fails it.
TEST(SimScorePipeline, OrchardHoldReportsCrownsSeenThroughGaps) {
  constexpr int kHoldRotations = 100;
  const ScratchDir dir("sim_score_hold");
  const std::string ours = std::string(FIELDGUARD_CONFIG_DIR) + "/fieldguard.yaml";
  std::string text = tools_test::read_file(ours);
  const std::string on = "  hold:";
  const std::size_t at = text.find("    enabled: true", text.find(on));
  ASSERT_NE(text.find(on), std::string::npos);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 17, "    enabled: false");
  const std::string off = dir.file("no-hold.yaml");
  {
    std::ofstream f(off);
    f << text;
  }
  const Outcome with = sim_replay_score(ours, dir, "orchard", kHoldRotations);
  const Outcome without = sim_replay_score(off, dir, "orchard", kHoldRotations);
  ASSERT_GE(with.report.scored_frames, static_cast<std::size_t>(kHoldRotations - 2)) << with.log;

  const std::size_t held = count_of(with.obstacles, "\"held\":true");
  EXPECT_GE(held, 5U);
  EXPECT_NE(with.summary.find("(" + std::to_string(held) + " of them held from fragments)"), std::string::npos)
      << with.summary;
  EXPECT_EQ(count_of(without.obstacles, "\"held\""), 0U);
  EXPECT_EQ(without.summary.find("held"), std::string::npos) << without.summary;

  const Rate& a = with.report.classes.at("crown");
  const Rate& b = without.report.classes.at("crown");
  EXPECT_EQ(a.total, b.total);
  EXPECT_GE(a.hits, b.hits + 3) << "crown frames detected: " << a.hits << " with the hold, " << b.hits << " without";
  EXPECT_EQ(with.report.false_obstacles, without.report.false_obstacles);
  EXPECT_GE(with.report.crowns.tp, without.report.crowns.tp + 3);
  EXPECT_EQ(with.report.crowns.split, without.report.crowns.split);
}

}  // namespace
}  // namespace fieldguard::score
