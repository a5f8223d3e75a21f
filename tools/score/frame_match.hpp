#pragma once
// Pairs detection frames with ground-truth frames by stamp: each truth frame takes the detection frame with
// the nearest stamp if it is within the tolerance (half a rotation period by default); when two truth frames
// want the same detection frame the closer pair wins. Every frame is used at most once.

#include <cstddef>
#include <vector>

#include "score/frames.hpp"

namespace fieldguard::score {

struct FramePair {
  std::size_t truth = 0;      // index into the truth frames
  std::size_t detection = 0;  // index into the detection frames
};

struct FrameMatch {
  std::vector<FramePair> pairs;  // in truth-stamp order
  std::vector<std::size_t> truth_unmatched;
  std::vector<std::size_t> detections_unmatched;
};

// The rotation period: "period_s" of the first truth line, else the median step between truth stamps,
// else 0.1 s.
[[nodiscard]] double rotation_period(const std::vector<TruthFrame>& truth);

[[nodiscard]] FrameMatch match_frames(const std::vector<TruthFrame>& truth,
                                      const std::vector<DetectionFrame>& detections, double tolerance_s);

}  // namespace fieldguard::score
