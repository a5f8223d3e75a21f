#pragma once
// Holding a recent obstacle's place (HoldParams, params.hpp): a hysteresis in time. The filters ask a cluster
// for enough points to tell it from dust and single stray returns; where they reported an obstacle less than
// max_age_s ago, fewer will do. If no obstacle of this frame stands in that obstacle's place (overlapping its box
// in z, and in x and y by half the shorter extent: a neighbour within gate_m is not it), the frame's fragments
// (FrameResult::fragments: groups too few for the filters, standing high enough) within gate_m of its box and in
// no box of this frame are reported as one obstacle, when they hold min_points points together.
//
// Only the filters' obstacles are remembered: a held obstacle holds nothing, so an obstacle the filters have
// not reported for max_age_s is let go whatever its fragments. Boxes are compared in the frame of this frame's
// boxes: given each frame's pose (FramePose: a fused, levelled frame's place and heading), a remembered box is
// moved into this frame first (its corners, then their box), so that the tractor's travel and turning since the
// report need not fit in the gate; without poses the travel must fit, and the gate grows along x with it when the
// speed is given.
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

// Where a frame's boxes stand: its origin in a fixed, horizontal plane (metres) and the angle of its x axis
// from the plane's first axis, counter-clockwise (radians), for a frame whose z axis is vertical (levelled).
// `plane` names the plane (a map zone): poses in different planes are not compared.
struct FramePose {
  double x_m = 0.0;
  double y_m = 0.0;
  double z_m = 0.0;
  double yaw_rad = 0.0;
  int plane = 0;
};

// The box [min, max] of a frame posed `from` as it stands in a frame posed `to`: in x and y the box around its
// four corners moved, in z the box moved by the difference in the origins' heights. The poses must be of the
// same plane.
void move_box(const std::array<float, 3>& min, const std::array<float, 3>& max, const FramePose& from,
              const FramePose& to, std::array<float, 3>& out_min, std::array<float, 3>& out_max);

class ObstacleHold {
 public:
  // Throws std::invalid_argument for a negative or non-finite max_age_s or gate_m, or min_points < 1.
  explicit ObstacleHold(const HoldParams& params);

  // The frame of `result`, stamped `stamp_ns` (its first packet's time; frames come in order). Adds the held
  // obstacles to result.obstacles (sorted again, sort_obstacles) and counts them in result.counts.held; returns
  // how many. A stamp before the last frame's forgets every obstacle (a new capture, or the clock stepped).
  // `speed_mps`, when known (the tractor's, from the bus): a remembered obstacle's gate grows along x by the
  // distance driven since its report, forwards and backwards alike (the speed has no sign). A negative or
  // non-finite speed counts as unknown. `pose`, when known (a value not finite counts as unknown): where this
  // frame's boxes stand; an obstacle remembered with a pose of the same plane is moved into this frame, and
  // the speed is not used for it. Disabled: does nothing.
  std::size_t apply(std::int64_t stamp_ns, FrameResult& result, std::optional<double> speed_mps = std::nullopt,
                    const std::optional<FramePose>& pose = std::nullopt);

  // The obstacles remembered (for tests).
  [[nodiscard]] std::size_t remembered() const { return seen_.size(); }

 private:
  struct Seen {
    std::array<float, 3> min;
    std::array<float, 3> max;
    std::int64_t stamp_ns;          // of the frame whose filters last reported it
    std::optional<FramePose> pose;  // of that frame, when known
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
