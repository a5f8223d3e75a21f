#include "score/metrics.hpp"

#include <algorithm>

namespace fieldguard::score {

std::string band_name(std::size_t band) {
  if (band + 1 >= kBands) return std::to_string(5 * (kBands - 1)) + "+";
  return std::to_string(5 * band) + "-" + std::to_string(5 * (band + 1));
}

std::size_t band_of(double distance_m) {
  if (!(distance_m >= 0.0)) return 0;
  const auto b = static_cast<std::size_t>(distance_m / 5.0);
  return std::min(b, kBands - 1);
}

namespace {

bool in_region(const Box& b, const ScoreParams& p) {
  if (!p.region) return true;
  const auto& r = *p.region;
  return b.max[0] >= r[0] && b.min[0] <= r[2] && b.max[1] >= r[1] && b.min[1] <= r[3];
}

// One scored frame.
void score_frame(const TruthFrame& t, const DetectionFrame& d, const ScoreParams& p, ScoreReport& rep) {
  const std::size_t n_obj = t.objects.size();
  const std::size_t n_obs = d.obstacles.size();
  std::vector<bool> visible(n_obj, false);
  for (std::size_t i = 0; i < n_obj; ++i) {
    const TruthItem& obj = t.objects[i];
    // raised_hits is -1 where the truth does not say (allowed only with min_raised_hits 0: see main.cpp).
    const bool raised = p.min_raised_hits <= 0 || obj.raised_hits >= p.min_raised_hits;
    visible[i] = obj.hits >= p.min_hits && raised && in_region(obj.box, p);
  }
  // match[o][i]: obstacle o matches object i.
  std::vector<std::vector<bool>> match(n_obs, std::vector<bool>(n_obj, false));
  std::vector<std::size_t> obstacles_on(n_obj, 0);   // per object
  std::vector<std::size_t> visible_under(n_obs, 0);  // per obstacle: visible objects it matches
  std::vector<bool> any_match(n_obs, false);
  for (std::size_t o = 0; o < n_obs; ++o) {
    for (std::size_t i = 0; i < n_obj; ++i) {
      if (!matches(d.obstacles[o].box, t.objects[i].box, p.margin_m, p.min_overlap)) continue;
      match[o][i] = true;
      any_match[o] = true;
      ++obstacles_on[i];
      if (visible[i]) ++visible_under[o];
    }
  }

  std::array<bool, kBands> false_in_band{};
  bool crown_frame = false;
  for (std::size_t i = 0; i < n_obj; ++i) {
    if (!visible[i]) continue;
    const TruthItem& obj = t.objects[i];
    const bool detected = obstacles_on[i] > 0;
    Rate& c = rep.classes[obj.cls];
    ++c.total;
    if (detected) ++c.hits;
    if (obj.cls == "pedestrian") {
      Rate& r = rep.pedestrian[band_of(obj.distance_m)];
      ++r.total;
      if (detected) ++r.hits;
    }
    if (obstacles_on[i] >= 2) ++rep.over_segmented;
    if (obj.cls == "crown") {
      crown_frame = true;
      CrownStats& cs = rep.crowns;
      ++cs.visible;
      if (obstacles_on[i] == 0) {
        ++cs.missed;
      } else if (obstacles_on[i] >= 2) {
        ++cs.split;
      } else {
        std::size_t only = 0;
        while (!match[only][i]) ++only;
        ++(visible_under[only] == 1 ? cs.tp : cs.merged);
      }
    }
  }
  std::uint64_t false_here = 0;
  for (std::size_t o = 0; o < n_obs; ++o) {
    ++rep.obstacles;
    if (visible_under[o] >= 2) ++rep.under_segmented;
    if (any_match[o]) continue;
    ++rep.false_obstacles;
    ++false_here;
    false_in_band[band_of(horizontal_distance(d.obstacles[o].box))] = true;
    const TruthItem* cause = nullptr;
    for (const TruthItem& ti : t.terrain) {
      if (matches(d.obstacles[o].box, ti.box, p.margin_m, p.min_overlap) &&
          (cause == nullptr || ti.hits > cause->hits)) {
        cause = &ti;
      }
    }
    ++rep.false_causes[cause == nullptr ? std::string("none") : cause->cls];
  }
  for (std::size_t b = 0; b < kBands; ++b) {
    ++rep.ground_false[b].total;
    if (false_in_band[b]) ++rep.ground_false[b].hits;
  }
  if (crown_frame) {
    ++rep.crowns.frames;
    rep.crowns.obstacles += n_obs;
    rep.crowns.false_obstacles += false_here;
  }
}

}  // namespace

ScoreReport score(const std::vector<TruthFrame>& truth, const std::vector<DetectionFrame>& detections,
                  const ScoreParams& params) {
  ScoreReport rep;
  rep.params = params;
  rep.period_s = rotation_period(truth);
  rep.tolerance_s = params.tolerance_s.value_or(rep.period_s / 2.0);
  rep.truth_frames = truth.size();
  rep.detection_frames = detections.size();
  const FrameMatch m = match_frames(truth, detections, rep.tolerance_s);
  rep.matched_frames = m.pairs.size();
  for (const std::size_t t : m.truth_unmatched) rep.truth_unmatched_lines.push_back(truth[t].line);
  for (const std::size_t d : m.detections_unmatched) rep.detections_unmatched_lines.push_back(detections[d].line);
  for (const FramePair& pair : m.pairs) {
    const DetectionFrame& d = detections[pair.detection];
    if (d.partial && !params.include_partial) {
      ++rep.partial_skipped;
      continue;
    }
    ++rep.scored_frames;
    score_frame(truth[pair.truth], d, params, rep);
  }
  return rep;
}

}  // namespace fieldguard::score
