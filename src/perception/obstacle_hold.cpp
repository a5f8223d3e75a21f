#include "fieldguard/perception/obstacle_hold.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "fieldguard/perception/obstacle_box.hpp"

namespace fieldguard::perception {

namespace {

// Boxes [amin, amax] grown by `g` on every side (and by `gx` more along x) and [bmin, bmax] share a point (closed
// boxes).
bool touch(const std::array<float, 3>& amin, const std::array<float, 3>& amax, float g,
           const std::array<float, 3>& bmin, const std::array<float, 3>& bmax, float gx = 0.F) {
  for (std::size_t i = 0; i < 3; ++i) {
    const float grow = i == 0 ? g + gx : g;
    if (bmax[i] < amin[i] - grow || bmin[i] > amax[i] + grow) return false;
  }
  return true;
}

// Boxes that are one obstacle seen twice: overlapping in z, and in x and in y by at least half the shorter of the
// two extents (0.05 m added to both sides, for boxes of a single return). Neighbouring crowns whose boxes come
// within the gate of each other, or overlap by a sliver, are not. `ax` grows a's box along x on both sides first
// (the distance driven since a was reported).
bool same_place(const std::array<float, 3>& amin, const std::array<float, 3>& amax, const std::array<float, 3>& bmin,
                const std::array<float, 3>& bmax, float ax) {
  constexpr float kSingle = 0.05F;
  if (bmax[2] < amin[2] || bmin[2] > amax[2]) return false;
  for (std::size_t i = 0; i < 2; ++i) {
    const float lo = i == 0 ? amin[i] - ax : amin[i], hi = i == 0 ? amax[i] + ax : amax[i];
    const float common = std::min(hi, bmax[i]) - std::max(lo, bmin[i]);
    const float shorter = std::min(hi - lo, bmax[i] - bmin[i]);
    if (common + kSingle < 0.5F * (shorter + kSingle)) return false;
  }
  return true;
}

bool finite(const FramePose& p) {
  return std::isfinite(p.x_m) && std::isfinite(p.y_m) && std::isfinite(p.z_m) && std::isfinite(p.yaw_rad);
}

}  // namespace

// Through the plane (p_plane = origin + Rz(yaw) p) corner by corner, in double: plane coordinates are millions
// of metres.
void move_box(const std::array<float, 3>& min, const std::array<float, 3>& max, const FramePose& from,
              const FramePose& to, std::array<float, 3>& out_min, std::array<float, 3>& out_max) {
  const double c0 = std::cos(from.yaw_rad), s0 = std::sin(from.yaw_rad);
  const double c1 = std::cos(to.yaw_rad), s1 = std::sin(to.yaw_rad);
  const double dx = from.x_m - to.x_m, dy = from.y_m - to.y_m;
  double lo[2] = {HUGE_VAL, HUGE_VAL}, hi[2] = {-HUGE_VAL, -HUGE_VAL};
  for (const double x : {static_cast<double>(min[0]), static_cast<double>(max[0])}) {
    for (const double y : {static_cast<double>(min[1]), static_cast<double>(max[1])}) {
      const double px = dx + c0 * x - s0 * y, py = dy + s0 * x + c0 * y;  // from `to`'s origin, plane axes
      const double q[2] = {c1 * px + s1 * py, -s1 * px + c1 * py};        // in `to`'s axes
      for (std::size_t i = 0; i < 2; ++i) {
        lo[i] = std::min(lo[i], q[i]);
        hi[i] = std::max(hi[i], q[i]);
      }
    }
  }
  const double dz = from.z_m - to.z_m;
  for (std::size_t i = 0; i < 2; ++i) {
    out_min[i] = static_cast<float>(lo[i]);
    out_max[i] = static_cast<float>(hi[i]);
  }
  out_min[2] = static_cast<float>(static_cast<double>(min[2]) + dz);
  out_max[2] = static_cast<float>(static_cast<double>(max[2]) + dz);
}

ObstacleHold::ObstacleHold(const HoldParams& params) : params_(params) {
  if (!std::isfinite(params.max_age_s) || params.max_age_s < 0.0) {
    throw std::invalid_argument("ObstacleHold: max_age_s must be finite and not negative");
  }
  if (!std::isfinite(params.gate_m) || params.gate_m < 0.0) {
    throw std::invalid_argument("ObstacleHold: gate_m must be finite and not negative");
  }
  if (params.min_points < 1) throw std::invalid_argument("ObstacleHold: min_points must be at least 1");
  max_age_ns_ = std::llround(params.max_age_s * 1e9);
}

std::size_t ObstacleHold::apply(std::int64_t stamp_ns, FrameResult& result, std::optional<double> speed_mps,
                                const std::optional<FramePose>& pose) {
  if (!params_.enabled) return 0;
  const double speed = speed_mps && std::isfinite(*speed_mps) && *speed_mps > 0.0 ? *speed_mps : 0.0;
  const std::optional<FramePose> here = pose && finite(*pose) ? pose : std::nullopt;
  if (any_frame_ && stamp_ns < last_ns_) seen_.clear();
  any_frame_ = true;
  last_ns_ = stamp_ns;
  std::erase_if(seen_, [&](const Seen& s) { return stamp_ns - s.stamp_ns > max_age_ns_; });

  const auto gate = static_cast<float>(params_.gate_m);
  const std::size_t reported = result.obstacles.size();
  const std::vector<Fragment>& fragments = result.fragments;
  used_.assign(fragments.size(), 0U);
  // Fragments in order of their boxes' least x, with the widest box's x extent: those that can touch a box
  // reaching from x0 to x1 start in [x0 - widest, x1].
  order_.resize(fragments.size());
  float widest = 0.F;
  for (std::size_t i = 0; i < fragments.size(); ++i) {
    order_[i] = static_cast<std::uint32_t>(i);
    widest = std::max(widest, fragments[i].max[0] - fragments[i].min[0]);
  }
  std::sort(order_.begin(), order_.end(), [&](std::uint32_t a, std::uint32_t b) {
    return fragments[a].min[0] != fragments[b].min[0] ? fragments[a].min[0] < fragments[b].min[0] : a < b;
  });

  next_.clear();
  std::size_t held = 0;
  for (const Seen& s : seen_) {
    // Its box where it stands in this frame: moved there by the two poses, or as reported, with the distance
    // driven since as slack along x.
    std::array<float, 3> smin = s.min, smax = s.max;
    auto driven = static_cast<float>(speed * static_cast<double>(stamp_ns - s.stamp_ns) * 1e-9);
    if (here && s.pose && s.pose->plane == here->plane) {
      move_box(s.min, s.max, *s.pose, *here, smin, smax);
      driven = 0.F;
    }
    bool again = false;
    for (std::size_t o = 0; o < reported && !again; ++o) {
      again = same_place(smin, smax, result.obstacles[o].min, result.obstacles[o].max, driven);
    }
    if (again) continue;  // reported this frame: remembered from this frame's report
    next_.push_back(s);

    const float x0 = smin[0] - gate - driven, x1 = smax[0] + gate + driven;
    auto it = std::lower_bound(order_.begin(), order_.end(), x0 - widest,
                               [&](std::uint32_t f, float x) { return fragments[f].min[0] < x; });
    picked_.clear();
    std::uint32_t points = 0;
    for (; it != order_.end() && fragments[*it].min[0] <= x1; ++it) {
      const std::uint32_t f = *it;
      const Fragment& fr = fragments[f];
      if (used_[f] != 0U || !touch(smin, smax, gate, fr.min, fr.max, driven)) continue;
      // Inside an obstacle of this frame's (a part the filters have already reported): not this one's.
      bool inside = false;
      for (std::size_t o = 0; o < reported && !inside; ++o) {
        inside = touch(result.obstacles[o].min, result.obstacles[o].max, 0.F, fr.min, fr.max);
      }
      if (inside) continue;
      picked_.push_back(f);
      points += fr.points;
    }
    if (points < static_cast<std::uint32_t>(params_.min_points)) continue;

    Obstacle h;
    h.min = fragments[picked_.front()].min;
    h.max = fragments[picked_.front()].max;
    h.distance_m = fragments[picked_.front()].distance_m;
    for (const std::uint32_t f : picked_) {
      const Fragment& fr = fragments[f];
      used_[f] = 1U;
      for (std::size_t i = 0; i < 3; ++i) {
        h.min[i] = std::min(h.min[i], fr.min[i]);
        h.max[i] = std::max(h.max[i], fr.max[i]);
      }
      h.distance_m = std::min(h.distance_m, fr.distance_m);
      h.height_above_ground_m = std::max(h.height_above_ground_m, fr.height_above_ground_m);
    }
    h.points = points;
    const float cx = 0.5F * (h.min[0] + h.max[0]), cy = 0.5F * (h.min[1] + h.max[1]);
    h.bearing_deg =
        static_cast<float>(std::atan2(static_cast<double>(cy), static_cast<double>(cx)) * 180.0 / std::numbers::pi);
    const float dx = h.max[0] - h.min[0], dy = h.max[1] - h.min[1];
    h.obb_center = {cx, cy};
    h.obb_length_m = std::max(dx, dy);
    h.obb_width_m = std::min(dx, dy);
    h.obb_yaw_rad = dx >= dy ? 0.F : static_cast<float>(std::numbers::pi / 2);
    h.size_class = size_class(h.obb_length_m, h.obb_width_m, h.max[2] - h.min[2]);
    h.sources = kSeenBy3d;
    h.held = true;
    result.obstacles.push_back(h);
    ++held;
  }
  for (std::size_t o = 0; o < reported; ++o) {
    next_.push_back(Seen{result.obstacles[o].min, result.obstacles[o].max, stamp_ns, here});
  }
  seen_.swap(next_);
  if (held > 0) sort_obstacles(result.obstacles);
  result.counts.held = static_cast<std::uint32_t>(held);
  return held;
}

}  // namespace fieldguard::perception
