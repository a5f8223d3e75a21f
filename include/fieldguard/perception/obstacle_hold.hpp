#pragma once
// Holding a recent obstacle's place (HoldParams, params.hpp): a hysteresis in time. The filters ask a cluster
// for enough points to tell it from dust and single stray returns; where they reported an obstacle less than
// max_age_s ago, fewer will do. If no obstacle of this frame stands in that obstacle's place (overlapping its box
// in z, and in x and y by half the shorter extent: a neighbour within gate_m is not it), the frame's fragments
// (FrameResult::fragments: groups too few for the filters, standing high enough) within gate_m of its box and in
// no box of this frame are reported as one obstacle, when they hold min_points points together.
//
// Only the filters' obstacles are remembered: a held obstacle holds nothing, so an obstacle the filters have
// not reported for max_age_s is let go whatever its fragments. Boxes are compared in the sensor frame: the
// tractor's travel since the report must fit in the gate, which grows along x with it when the speed is given.
//
// Stateful across frames, so it runs where the frames are in order (replay's and the daemon's delivery), not in
// the workers' Pipeline. Thread-compatible.

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "fieldguard/perception/obstacle.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

class ObstacleHold {
 public:
  // Throws std::invalid_argument for a negative or non-finite max_age_s or gate_m, or min_points < 1.
  explicit ObstacleHold(const HoldParams& params);

  // The frame of `result`, stamped `stamp_ns` (its first packet's time; frames come in order). Adds the held
  // obstacles to result.obstacles (sorted again, sort_obstacles) and counts them in result.counts.held; returns
  // how many. A stamp before the last frame's forgets every obstacle (a new capture, or the clock stepped).
  // `speed_mps`, when known (the tractor's, from the bus): a remembered obstacle's gate grows along x by the
  // distance driven since its report, forwards and backwards alike (the speed has no sign). A negative or
  // non-finite speed counts as unknown. Disabled: does nothing.
  std::size_t apply(std::int64_t stamp_ns, FrameResult& result, std::optional<double> speed_mps = std::nullopt);

  // The obstacles remembered (for tests).
  [[nodiscard]] std::size_t remembered() const { return seen_.size(); }

 private:
  struct Seen {
    std::array<float, 3> min;
    std::array<float, 3> max;
    std::int64_t stamp_ns;  // of the frame whose filters last reported it
  };
  HoldParams params_;
  std::int64_t max_age_ns_ = 0;
  std::int64_t last_ns_ = 0;
  bool any_frame_ = false;
  std::vector<Seen> seen_;
  // Scratch, reused frame to frame.
  std::vector<Seen> next_;
  std::vector<std::uint8_t> used_;     // per fragment of the frame: taken by a held obstacle
  std::vector<std::uint32_t> order_;   // the fragments by their least x
  std::vector<std::uint32_t> picked_;  // the fragments of one held obstacle
};

}  // namespace fieldguard::perception
