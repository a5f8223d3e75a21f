#pragma once
// The scorer's output: a text table for people and one JSON object for programs (--json).
//
// JSON layout (rates are fractions 0..1, null where nothing was counted):
// {"params": {"margin_m", "min_overlap", "min_hits", "min_raised_hits", "region": [x0, y0, x1, y1] | null,
// "include_partial", "tolerance_s",
//             "period_s"},
//  "frames": {"truth", "detections", "matched", "partial_skipped", "scored",
//             "truth_unmatched_lines": [...], "detections_unmatched_lines": [...]},
//  "pedestrian": [{"band": "0-5", "lo_m": 0, "hi_m": 5 | null, "visible", "detected", "rate"}, ...],
//  "ground_false": [{"band", "lo_m", "hi_m", "frames", "false_frames", "rate"}, ...],
//  "classes": {"<class>": {"visible", "detected", "rate"}, ...},
//  "crowns": {"visible", "tp", "missed", "split", "merged", "tp_rate", "frames", "obstacles",
//             "false_obstacles", "false_rate"},
//  "segmentation": {"over", "under"},
//  "obstacles": {"total", "false", "false_by_cause": {"clod", "ridge", "crop", "body", "none"}}}

#include <string>

#include "score/metrics.hpp"

namespace fieldguard::score {

[[nodiscard]] std::string format_text(const ScoreReport& r, const std::string& detections_path,
                                      const std::string& truth_path);
[[nodiscard]] std::string format_json(const ScoreReport& r);

}  // namespace fieldguard::score
