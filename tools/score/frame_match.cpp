#include "score/frame_match.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace fieldguard::score {

double rotation_period(const std::vector<TruthFrame>& truth) {
  if (!truth.empty() && truth.front().period_s > 0.0) return truth.front().period_s;
  std::vector<double> stamps;
  stamps.reserve(truth.size());
  for (const TruthFrame& f : truth) stamps.push_back(f.stamp);
  std::sort(stamps.begin(), stamps.end());
  std::vector<double> steps;
  for (std::size_t i = 1; i < stamps.size(); ++i) {
    if (stamps[i] > stamps[i - 1]) steps.push_back(stamps[i] - stamps[i - 1]);
  }
  if (steps.empty()) return 0.1;
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  return steps[steps.size() / 2];
}

FrameMatch match_frames(const std::vector<TruthFrame>& truth, const std::vector<DetectionFrame>& detections,
                        double tolerance_s) {
  std::vector<std::size_t> by_stamp(detections.size());
  std::iota(by_stamp.begin(), by_stamp.end(), std::size_t{0});
  std::sort(by_stamp.begin(), by_stamp.end(),
            [&](std::size_t a, std::size_t b) { return detections[a].stamp < detections[b].stamp; });

  struct Candidate {
    double gap;
    std::size_t truth;
    std::size_t detection;
  };
  std::vector<Candidate> candidates;
  for (std::size_t t = 0; t < truth.size(); ++t) {
    const double s = truth[t].stamp;
    const auto it = std::lower_bound(by_stamp.begin(), by_stamp.end(), s,
                                     [&](std::size_t d, double v) { return detections[d].stamp < v; });
    double best = tolerance_s;
    std::size_t pick = detections.size();
    for (auto j = it == by_stamp.begin() ? it : it - 1; j != by_stamp.end() && j <= it; ++j) {
      const double gap = std::abs(detections[*j].stamp - s);
      if (gap <= best) {
        best = gap;
        pick = *j;
      }
    }
    if (pick < detections.size()) candidates.push_back({best, t, pick});
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.gap < b.gap; });
  std::vector<bool> truth_used(truth.size(), false);
  std::vector<bool> det_used(detections.size(), false);
  FrameMatch m;
  for (const Candidate& c : candidates) {
    if (truth_used[c.truth] || det_used[c.detection]) continue;
    truth_used[c.truth] = true;
    det_used[c.detection] = true;
    m.pairs.push_back({c.truth, c.detection});
  }
  std::sort(m.pairs.begin(), m.pairs.end(),
            [&](const FramePair& a, const FramePair& b) { return truth[a.truth].stamp < truth[b.truth].stamp; });
  for (std::size_t t = 0; t < truth.size(); ++t) {
    if (!truth_used[t]) m.truth_unmatched.push_back(t);
  }
  for (std::size_t d = 0; d < detections.size(); ++d) {
    if (!det_used[d]) m.detections_unmatched.push_back(d);
  }
  return m;
}

}  // namespace fieldguard::score
