// fieldguard-score: scores a replay's obstacles (JSON lines) against the simulator's ground truth.
#include <array>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cli/cli.hpp"
#include "score/frames.hpp"
#include "score/metrics.hpp"
#include "score/report.hpp"

namespace {

using namespace fieldguard::score;
namespace cli = fieldguard::tools::cli;

constexpr const char* kSynopsis =
    "fieldguard-score --detections FILE --truth FILE [--json] [--margin M] [--min-overlap F]\n"
    "                        [--min-hits N] [--min-raised-hits N] [--region X0,Y0,X1,Y1 | --region none] "
    "[--include-partial]\n"
    "                        [--tolerance S]";

constexpr const char* kAbout =
    "Scores obstacles (fieldguard replay --obstacles-out: one JSON line per rotation with \"stamp\",\n"
    "\"obstacles\": [{\"min\", \"max\", ...}], optionally \"partial\") against ground truth (fieldguard-sim\n"
    "--truth). Frames are paired by stamp: nearest within --tolerance (default half the rotation period).";

constexpr const char* kFooter =
    "Definitions (tools/score/metrics.hpp): an obstacle matches a truth item when their boxes overlap on\n"
    "x, y and z after the item's box is grown by the margin, on x and y by at least --min-overlap of the\n"
    "shorter of the two extents (+5 cm each; no slivers). Detected = visible object with a matching\n"
    "obstacle. False obstacle = matches no real object (visible or not); the ground false-detection rate\n"
    "of a 5 m band = frames with a false obstacle at that distance / scored frames. Crown TP = exactly one\n"
    "obstacle matches the crown and it matches no other visible object; missed = none matches; split =\n"
    "two or more; merged = its one obstacle also matches another visible object. Over-segmentation =\n"
    "(frame, object) matched by >= 2 obstacles; under-segmentation = (frame, obstacle) matching >= 2\n"
    "visible objects.\n\n"
    "Exit codes: 0 scored; 2 unusable input (missing file, bad JSON line: named with its line) or bad\n"
    "command line.";

// "X0,Y0,X1,Y1" with X0 < X1 and Y0 < Y1, or "none" (no region: everywhere).
bool parse_region(std::string_view s, std::optional<std::array<double, 4>>& out) {
  if (s == "none") {
    out.reset();
    return true;
  }
  std::array<double, 4> r{};
  for (std::size_t i = 0; i < 4; ++i) {
    const std::size_t comma = s.find(',');
    const std::string_view part = i < 3 ? s.substr(0, comma) : s;
    if ((i < 3 && comma == std::string_view::npos) || !cli::parse_number(part, r[i])) return false;
    if (i < 3) s.remove_prefix(comma + 1);
  }
  if (!(r[0] < r[2] && r[1] < r[3])) return false;
  out = r;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  std::string detections_path;
  std::string truth_path;
  bool json = false;
  ScoreParams params;
  cli::Tool tool("fieldguard-score", kSynopsis, kAbout, kFooter, "(fieldguard-score --help lists the options)");
  CLI::App& app = tool.app();
  app.add_option("--detections", detections_path, "obstacles to score (fieldguard replay --obstacles-out)")
      ->type_name("FILE");
  app.add_option("--truth", truth_path, "ground truth (fieldguard-sim --truth)")->type_name("FILE");
  app.add_flag("--json", json, "print one JSON object instead of the tables (layout: tools/score/report.hpp)");
  cli::number(
      app, "--margin", params.margin_m, [](double m) { return m >= 0.0; }, "metres >= 0",
      "grow truth boxes by M metres on every side before testing overlap (default 0.3)")
      ->type_name("M");
  cli::number(app, "--min-overlap", params.min_overlap, cli::Between<double>{0.0, 1.0}, "a fraction from 0 to 1",
              "on x and y the overlap must be at least F of the shorter extent (default 0.5)")
      ->type_name("F");
  cli::number(
      app, "--min-hits", params.min_hits, [](long n) { return n >= 1; }, "a whole number >= 1",
      "a real object is visible with at least N returns (default 3)")
      ->type_name("N");
  cli::number(
      app, "--min-raised-hits", params.min_raised_hits, [](long n) { return n >= 0; }, "a whole number >= 0",
      "and at least N of them 0.5 m or more above the field surface under them\n"
      "(default 3; the truth's \"raised_hits\"; 0: any returns count, as before)")
      ->type_name("N");
  cli::checked(
      app, "--region", params.region, parse_region, [](const auto& /*region*/) { return true; },
      "X0,Y0,X1,Y1 with X0 < X1 and Y0 < Y1 (metres), or none",
      "and only if its box overlaps this x-y rectangle (default -10,-10,50,10: the\n"
      "configured region of interest); 'none' for everywhere")
      ->type_name("X0,Y0,X1,Y1|none");
  app.add_flag("--include-partial", params.include_partial,
               "also score detection frames marked \"partial\": true (skipped by default)");
  cli::number(
      app, "--tolerance", params.tolerance_s, [](double t) { return t > 0.0; }, "seconds > 0",
      "largest stamp difference of paired frames, seconds")
      ->type_name("S");
  if (const auto exit_code = tool.parse(argc, argv)) return *exit_code;
  if (detections_path.empty() || truth_path.empty())
    return tool.fail("--detections FILE and --truth FILE are required");

  std::vector<TruthFrame> truth;
  std::vector<DetectionFrame> detections;
  std::string error;
  if (!read_truth(truth_path, truth, error) || !read_detections(detections_path, detections, error)) {
    std::cerr << "fieldguard-score: " << error << "\n";
    return 2;
  }
  if (params.min_raised_hits > 0) {
    for (const TruthFrame& f : truth) {
      for (const TruthItem& o : f.objects) {
        if (o.raised_hits >= 0) continue;
        std::cerr << "fieldguard-score: " << truth_path << ":" << f.line << ": " << o.id
                  << " has no \"raised_hits\" (truth from an older simulator): score it with --min-raised-hits 0\n";
        return 2;
      }
    }
  }
  const ScoreReport report = score(truth, detections, params);
  std::cout << (json ? format_json(report) + "\n" : format_text(report, detections_path, truth_path));
  return 0;
}
