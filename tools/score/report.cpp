#include "score/report.hpp"

#include <cstdio>

namespace fieldguard::score {

namespace {

std::string fixed(double v, int decimals) {
  char buf[64];
  const int n = std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return std::string(buf, static_cast<std::size_t>(n > 0 ? n : 0));
}

std::string percent(const Rate& r) {
  const auto v = r.value();
  return v ? fixed(*v * 100.0, 2) + "%" : std::string("-");
}

std::string fraction(std::uint64_t a, std::uint64_t b) { return std::to_string(a) + "/" + std::to_string(b); }

std::string pad(std::string s, std::size_t width) {
  if (s.size() < width) s.append(width - s.size(), ' ');
  return s;
}

std::string json_rate(const Rate& r) {
  const auto v = r.value();
  return v ? fixed(*v, 6) : std::string("null");
}

std::string json_lines(const std::vector<std::size_t>& lines) {
  std::string s = "[";
  for (std::size_t i = 0; i < lines.size(); ++i) s += (i > 0 ? ", " : "") + std::to_string(lines[i]);
  return s + "]";
}

std::string list_lines(const std::vector<std::size_t>& lines) {
  std::string s;
  for (std::size_t i = 0; i < lines.size() && i < 10; ++i) s += (i > 0 ? ", " : "") + std::to_string(lines[i]);
  if (lines.size() > 10) s += ", ... (" + std::to_string(lines.size()) + " in all)";
  return s;
}

std::uint64_t cause(const ScoreReport& r, const std::string& name) {
  const auto it = r.false_causes.find(name);
  return it == r.false_causes.end() ? 0 : it->second;
}

}  // namespace

std::string format_text(const ScoreReport& r, const std::string& detections_path, const std::string& truth_path) {
  std::string s = "fieldguard-score: " + detections_path + " against " + truth_path + "\n";
  s += "frames: truth " + std::to_string(r.truth_frames) + ", detections " + std::to_string(r.detection_frames) +
       ", matched " + std::to_string(r.matched_frames) + " (stamps within " + fixed(r.tolerance_s, 4) +
       " s), partial skipped " + std::to_string(r.partial_skipped) + ", scored " + std::to_string(r.scored_frames) +
       "\n";
  if (!r.truth_unmatched_lines.empty())
    s += "  truth lines with no detection frame: " + list_lines(r.truth_unmatched_lines) + "\n";
  if (!r.detections_unmatched_lines.empty()) {
    s += "  detection lines with no truth frame: " + list_lines(r.detections_unmatched_lines) + "\n";
  }
  s += "match: obstacle box overlaps the truth box grown by " + fixed(r.params.margin_m, 2) +
       " m (x, y: by >= " + fixed(r.params.min_overlap * 100.0, 0) +
       "% of the shorter extent); visible: >= " + std::to_string(r.params.min_hits) +
       " returns, >= " + std::to_string(r.params.min_raised_hits) + " of them 0.5 m above the surface";
  if (r.params.region) {
    const auto& g = *r.params.region;
    s += ", box in x " + fixed(g[0], 1) + ".." + fixed(g[2], 1) + " y " + fixed(g[1], 1) + ".." + fixed(g[3], 1) + " m";
  }
  s += "\n\n";
  s += "band (m)  pedestrian detected/visible  rate      ground false frames/frames  rate\n";
  for (std::size_t b = 0; b < kBands; ++b) {
    const Rate& p = r.pedestrian[b];
    const Rate& g = r.ground_false[b];
    s += pad(band_name(b), 10) + pad(fraction(p.hits, p.total), 29) + pad(percent(p), 10) +
         pad(fraction(g.hits, g.total), 28) + percent(g) + "\n";
  }
  s += "\nclass       detected/visible  rate\n";
  for (const auto& [name, rate] : r.classes)
    s += pad(name, 12) + pad(fraction(rate.hits, rate.total), 18) + percent(rate) + "\n";
  const CrownStats& c = r.crowns;
  s += "\ncrowns: visible " + std::to_string(c.visible) + ", true positive " + std::to_string(c.tp) + " (" +
       percent({c.tp, c.visible}) + "), missed " + std::to_string(c.missed) + ", split " + std::to_string(c.split) +
       ", merged " + std::to_string(c.merged) + "; false obstacles " + fraction(c.false_obstacles, c.obstacles) + " (" +
       percent({c.false_obstacles, c.obstacles}) + ") in " + std::to_string(c.frames) + " frames\n";
  s += "segmentation: over-segmented " + std::to_string(r.over_segmented) + " (object, frame), under-segmented " +
       std::to_string(r.under_segmented) + " (obstacle, frame)\n";
  s += "obstacles: " + std::to_string(r.obstacles) + ", false " + std::to_string(r.false_obstacles) + " (on clod " +
       std::to_string(cause(r, "clod")) + ", ridge " + std::to_string(cause(r, "ridge")) + ", crop " +
       std::to_string(cause(r, "crop")) + ", body " + std::to_string(cause(r, "body")) + ", nothing " +
       std::to_string(cause(r, "none")) + ")\n";
  return s;
}

std::string format_json(const ScoreReport& r) {
  std::string s = "{\"params\": {\"margin_m\": " + fixed(r.params.margin_m, 3) +
                  ", \"min_overlap\": " + fixed(r.params.min_overlap, 3) +
                  ", \"min_hits\": " + std::to_string(r.params.min_hits) +
                  ", \"min_raised_hits\": " + std::to_string(r.params.min_raised_hits) + ", \"region\": ";
  if (r.params.region) {
    const auto& g = *r.params.region;
    s += "[" + fixed(g[0], 3) + ", " + fixed(g[1], 3) + ", " + fixed(g[2], 3) + ", " + fixed(g[3], 3) + "]";
  } else {
    s += "null";
  }
  s += std::string(", \"include_partial\": ") + (r.params.include_partial ? "true" : "false") +
       ", \"tolerance_s\": " + fixed(r.tolerance_s, 6) + ", \"period_s\": " + fixed(r.period_s, 6) + "}";
  s += ", \"frames\": {\"truth\": " + std::to_string(r.truth_frames) +
       ", \"detections\": " + std::to_string(r.detection_frames) +
       ", \"matched\": " + std::to_string(r.matched_frames) +
       ", \"partial_skipped\": " + std::to_string(r.partial_skipped) +
       ", \"scored\": " + std::to_string(r.scored_frames) +
       ", \"truth_unmatched_lines\": " + json_lines(r.truth_unmatched_lines) +
       ", \"detections_unmatched_lines\": " + json_lines(r.detections_unmatched_lines) + "}";
  auto band_head = [](std::size_t b) {
    const std::string hi = b + 1 >= kBands ? std::string("null") : std::to_string(5 * (b + 1));
    return "{\"band\": \"" + band_name(b) + "\", \"lo_m\": " + std::to_string(5 * b) + ", \"hi_m\": " + hi;
  };
  s += ", \"pedestrian\": [";
  for (std::size_t b = 0; b < kBands; ++b) {
    const Rate& p = r.pedestrian[b];
    s += (b > 0 ? ", " : "") + band_head(b) + ", \"visible\": " + std::to_string(p.total) +
         ", \"detected\": " + std::to_string(p.hits) + ", \"rate\": " + json_rate(p) + "}";
  }
  s += "], \"ground_false\": [";
  for (std::size_t b = 0; b < kBands; ++b) {
    const Rate& g = r.ground_false[b];
    s += (b > 0 ? ", " : "") + band_head(b) + ", \"frames\": " + std::to_string(g.total) +
         ", \"false_frames\": " + std::to_string(g.hits) + ", \"rate\": " + json_rate(g) + "}";
  }
  s += "], \"classes\": {";
  bool first = true;
  for (const auto& [name, rate] : r.classes) {
    s += (first ? "\"" : ", \"") + name + "\": {\"visible\": " + std::to_string(rate.total) +
         ", \"detected\": " + std::to_string(rate.hits) + ", \"rate\": " + json_rate(rate) + "}";
    first = false;
  }
  const CrownStats& c = r.crowns;
  s += "}, \"crowns\": {\"visible\": " + std::to_string(c.visible) + ", \"tp\": " + std::to_string(c.tp) +
       ", \"missed\": " + std::to_string(c.missed) + ", \"split\": " + std::to_string(c.split) +
       ", \"merged\": " + std::to_string(c.merged) + ", \"tp_rate\": " + json_rate({c.tp, c.visible}) +
       ", \"frames\": " + std::to_string(c.frames) + ", \"obstacles\": " + std::to_string(c.obstacles) +
       ", \"false_obstacles\": " + std::to_string(c.false_obstacles) +
       ", \"false_rate\": " + json_rate({c.false_obstacles, c.obstacles}) + "}";
  s += ", \"segmentation\": {\"over\": " + std::to_string(r.over_segmented) +
       ", \"under\": " + std::to_string(r.under_segmented) + "}";
  s += ", \"obstacles\": {\"total\": " + std::to_string(r.obstacles) +
       ", \"false\": " + std::to_string(r.false_obstacles) +
       ", \"false_by_cause\": {\"clod\": " + std::to_string(cause(r, "clod")) +
       ", \"ridge\": " + std::to_string(cause(r, "ridge")) + ", \"crop\": " + std::to_string(cause(r, "crop")) +
       ", \"body\": " + std::to_string(cause(r, "body")) + ", \"none\": " + std::to_string(cause(r, "none")) + "}}}";
  return s;
}

}  // namespace fieldguard::score
