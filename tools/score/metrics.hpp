#pragma once
// The scorer's definitions. In each matched frame (partial detection frames are skipped unless asked):
//
// * An obstacle MATCHES a ground-truth item when, after the item's box is grown by `margin_m` (default
//   0.3 m) on every side, the boxes overlap on z (touching counts) and on x and on y by at least
//   `min_overlap` (default 0.5) of the shorter of the two extents on that axis (+5 cm each): see
//   frames.hpp matches(). So an obstacle on one crown does not also match the next crown 0.3 m away.
// * A real object (pedestrian, implement, haystack, house, tree, crown) is VISIBLE when it has at least
//   `min_hits` returns (default 3: fewer cannot make a cluster with an extent), at least `min_raised_hits`
//   of them (default 3) 0.5 m or more above the field surface under them (the truth's "raised_hits"), and
//   its box overlaps the region (default x -10..50, y -10..10 m: the configured ROI; objects outside it
//   cannot be reported). Returns lower than 0.5 m stand where clods, ridges and furrows stand, which the
//   issue calls terrain: an object seen only there, or by one or two returns above it (a crown seen by
//   one ray through its foliage and at its trunk's foot), has not shown enough of itself to be told from
//   terrain or a stray return. `min_raised_hits` 0 gives the rule before it (any `min_hits` returns).
// * DETECTED: a visible object matched by at least one obstacle. Rates are detected / visible, counted per
//   (frame, object).
// * Pedestrian bands: by the pedestrian's distance_m, [0,5), [5,10), ..., [30,35), [35, inf).
// * FALSE obstacle: one that matches no real object at all (visible or not, in the region or not); it is
//   put down to the terrain item it matches with the most hits (clod, ridge, crop, body) or to "none".
//   Ground false-detection rate of a band: frames with at least one false obstacle whose distance (sensor
//   to the nearest point of its box, horizontal) is in the band / scored frames.
// * Crowns, per visible crown: TP = exactly one obstacle matches it and that obstacle matches no other
//   visible object; MISSED = no obstacle matches it; SPLIT = two or more do; MERGED = the one obstacle
//   that matches it also matches another visible object. Crown false rate = false obstacles / obstacles,
//   over the frames that have at least one visible crown.
// * Over-segmentation: (frame, visible object) pairs matched by two or more obstacles. Under-segmentation:
//   (frame, obstacle) pairs matching two or more visible objects.

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "score/frame_match.hpp"
#include "score/frames.hpp"

namespace fieldguard::score {

struct ScoreParams {
  double margin_m = 0.3;
  double min_overlap = 0.5;
  long min_hits = 3;
  long min_raised_hits = 3;  // needs truth with "raised_hits" when above 0
  std::optional<std::array<double, 4>> region = std::array<double, 4>{-10.0, -10.0, 50.0, 10.0};  // x0 y0 x1 y1
  bool include_partial = false;
  std::optional<double> tolerance_s;  // default: half the rotation period
};

struct Rate {
  std::uint64_t hits = 0;   // numerator
  std::uint64_t total = 0;  // denominator
  [[nodiscard]] std::optional<double> value() const {
    if (total == 0) return std::nullopt;
    return static_cast<double>(hits) / static_cast<double>(total);
  }
};

inline constexpr std::size_t kBands = 8;  // 0-5 ... 30-35, 35+
[[nodiscard]] std::string band_name(std::size_t band);
[[nodiscard]] std::size_t band_of(double distance_m);

struct CrownStats {
  std::uint64_t visible = 0;
  std::uint64_t tp = 0;
  std::uint64_t missed = 0;
  std::uint64_t split = 0;
  std::uint64_t merged = 0;
  std::uint64_t frames = 0;     // frames with a visible crown
  std::uint64_t obstacles = 0;  // obstacles in those frames
  std::uint64_t false_obstacles = 0;
};

struct ScoreReport {
  ScoreParams params;
  double period_s = 0.0;
  double tolerance_s = 0.0;
  std::size_t truth_frames = 0;
  std::size_t detection_frames = 0;
  std::size_t matched_frames = 0;
  std::size_t partial_skipped = 0;
  std::size_t scored_frames = 0;
  std::vector<std::size_t> truth_unmatched_lines;       // 1-based lines in the truth file
  std::vector<std::size_t> detections_unmatched_lines;  // 1-based lines in the detections file
  std::array<Rate, kBands> pedestrian{};
  std::array<Rate, kBands> ground_false{};
  std::map<std::string, Rate> classes;                // by class name
  std::map<std::string, std::uint64_t> false_causes;  // clod, ridge, crop, body, none
  CrownStats crowns;
  std::uint64_t over_segmented = 0;
  std::uint64_t under_segmented = 0;
  std::uint64_t obstacles = 0;
  std::uint64_t false_obstacles = 0;
};

[[nodiscard]] ScoreReport score(const std::vector<TruthFrame>& truth, const std::vector<DetectionFrame>& detections,
                                const ScoreParams& params);

}  // namespace fieldguard::score
