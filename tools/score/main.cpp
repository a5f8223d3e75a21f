// fieldguard-score: scores a replay's obstacles (JSON lines) against the simulator's ground truth.
#include <charconv>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "score/frames.hpp"
#include "score/metrics.hpp"
#include "score/report.hpp"

namespace {

using namespace fieldguard::score;

void usage(std::ostream& os) {
  os << "usage: fieldguard-score --detections FILE --truth FILE [--json] [--margin M] [--min-overlap F]\n"
        "                        [--min-hits N] [--min-raised-hits N] [--region X0,Y0,X1,Y1 | --region none] [--include-partial]\n"
        "                        [--tolerance S]\n\n"
        "Scores obstacles (fieldguard replay --obstacles-out: one JSON line per rotation with \"stamp\",\n"
        "\"obstacles\": [{\"min\", \"max\", ...}], optionally \"partial\") against ground truth (fieldguard-sim\n"
        "--truth). Frames are paired by stamp: nearest within --tolerance (default half the rotation period).\n\n"
        "  --json              print one JSON object instead of the tables (layout: tools/score/report.hpp)\n"
        "  --margin M          grow truth boxes by M metres on every side before testing overlap (default 0.3)\n"
"  --min-overlap F     on x and y the overlap must be at least F of the shorter extent (default 0.5)\n"
        "  --min-hits N        a real object is visible with at least N returns (default 3)\n"
        "  --min-raised-hits N and at least N of them 0.5 m or more above the field surface under them\n"
        "                      (default 3; the truth's \"raised_hits\"; 0: any returns count, as before)\n"
        "  --region ...        and only if its box overlaps this x-y rectangle (default -10,-10,50,10: the\n"
        "                      configured region of interest); 'none' for everywhere\n"
        "  --include-partial   also score detection frames marked \"partial\": true (skipped by default)\n"
        "  --tolerance S       largest stamp difference of paired frames, seconds\n\n"
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
        "command line.\n";
}

int bad_usage(const std::string& msg) {
  std::cerr << "fieldguard-score: " << msg << "\n(fieldguard-score --help lists the options)\n";
  return 2;
}

template <typename T>
bool parse_number(std::string_view s, T& out) {
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc{} && ptr == s.data() + s.size();
}

bool parse_region(std::string_view s, std::array<double, 4>& out) {
  for (std::size_t i = 0; i < 4; ++i) {
    const std::size_t comma = s.find(',');
    const std::string_view part = i < 3 ? s.substr(0, comma) : s;
    if ((i < 3 && comma == std::string_view::npos) || !parse_number(part, out[i])) return false;
    if (i < 3) s.remove_prefix(comma + 1);
  }
  return out[0] < out[2] && out[1] < out[3];
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string_view> args(argv + 1, argv + argc);
  std::string detections_path;
  std::string truth_path;
  bool json = false;
  ScoreParams params;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string_view a = args[i];
    if (a == "--help" || a == "-h") {
      usage(std::cout);
      return 0;
    }
    if (a == "--json") {
      json = true;
      continue;
    }
    if (a == "--include-partial") {
      params.include_partial = true;
      continue;
    }
    if (i + 1 >= args.size()) return bad_usage(std::string(a) + (a.starts_with("--") ? " needs a value" : ": unknown argument"));
    const std::string_view v = args[++i];
    const std::string vs(v);
    if (a == "--detections") {
      detections_path = vs;
    } else if (a == "--truth") {
      truth_path = vs;
    } else if (a == "--margin") {
      if (!parse_number(v, params.margin_m) || params.margin_m < 0.0) return bad_usage("--margin wants metres >= 0, not '" + vs + "'");
    } else if (a == "--min-overlap") {
      if (!parse_number(v, params.min_overlap) || params.min_overlap < 0.0 || params.min_overlap > 1.0) {
        return bad_usage("--min-overlap wants a fraction from 0 to 1, not '" + vs + "'");
      }
    } else if (a == "--min-hits") {
      if (!parse_number(v, params.min_hits) || params.min_hits < 1) return bad_usage("--min-hits wants a whole number >= 1, not '" + vs + "'");
    } else if (a == "--min-raised-hits") {
      if (!parse_number(v, params.min_raised_hits) || params.min_raised_hits < 0) {
        return bad_usage("--min-raised-hits wants a whole number >= 0, not '" + vs + "'");
      }
    } else if (a == "--region") {
      if (v == "none") {
        params.region.reset();
      } else {
        std::array<double, 4> r{};
        if (!parse_region(v, r)) return bad_usage("--region wants X0,Y0,X1,Y1 with X0 < X1 and Y0 < Y1 (metres), or none; not '" + vs + "'");
        params.region = r;
      }
    } else if (a == "--tolerance") {
      double t = 0.0;
      if (!parse_number(v, t) || t <= 0.0) return bad_usage("--tolerance wants seconds > 0, not '" + vs + "'");
      params.tolerance_s = t;
    } else {
      return bad_usage("unknown option '" + std::string(a) + "'");
    }
  }
  if (detections_path.empty() || truth_path.empty()) return bad_usage("--detections FILE and --truth FILE are required");

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
