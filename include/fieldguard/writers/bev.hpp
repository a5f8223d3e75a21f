#pragma once
// The bird's-eye picture of one processed frame, drawn with cairo (Debian's libcairo2), for `replay --bev-dir` and
// the status page: a header with the decision (STOP in red with its reason, GO in green), the frame and its time;
// the points coloured by height with the ground dimmed; the region of interest, the body box and the stop zone;
// each obstacle's oriented box with its distance (the hold's labelled "held"), labels placed where they cover no
// box and no other label; a 1 m grid, a scale bar and a legend of every colour. At least 800 px tall by default.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fieldguard/core/time.hpp"
#include "fieldguard/output/safety_monitor.hpp"
#include "fieldguard/perception/obstacle.hpp"
#include "fieldguard/perception/params.hpp"

struct _cairo_surface;  // NOLINT(bugprone-reserved-identifier,cert-dcl37-c,cert-dcl51-cpp): cairo's own name

namespace fieldguard::app {

struct BevView {
  double x_min_m = -15.0;  // behind the sensor (bottom of the map)
  double x_max_m = 55.0;   // ahead (top)
  double y_half_m = 15.0;  // each side
  double px_per_m = 12.0;  // 70 m of map: 840 px, with the header 904 px tall
};

// What the header says: the frame, its time and (when decided) the decision.
struct BevCaption {
  std::uint64_t frame = 0;
  Stamp stamp;
  bool partial = false;
  const output::safety::Decision* decision = nullptr;
  int clear_frames = 3;  // safety.clear_frames, for the headline
};

// A rectangle in pixels (x right, y down), for the layout's tests.
struct PixelRect {
  double x0 = 0.0;
  double y0 = 0.0;
  double x1 = 0.0;
  double y1 = 0.0;
  [[nodiscard]] bool overlaps(const PixelRect& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
};

// A drawn picture (a cairo image surface). Move-only.
class Picture {
 public:
  Picture(int width, int height);
  ~Picture();
  Picture(Picture&& o) noexcept;
  Picture& operator=(Picture&& o) noexcept;
  Picture(const Picture&) = delete;
  Picture& operator=(const Picture&) = delete;

  [[nodiscard]] int width() const;
  [[nodiscard]] int height() const;
  [[nodiscard]] std::array<std::uint8_t, 3> pixel(int x, int y) const;  // r, g, b; black outside
  // "" on success, else what went wrong.
  [[nodiscard]] std::string write_png(const std::string& path) const;
  [[nodiscard]] std::vector<std::uint8_t> png() const;  // empty when cairo fails

  // Where render_bev put each obstacle's box (its bounding rectangle) and its label, in obstacle order, and the
  // label's text.
  std::vector<PixelRect> boxes;
  std::vector<PixelRect> labels;
  std::vector<std::string> label_texts;

  [[nodiscard]] _cairo_surface* surface() const { return surface_; }

 private:
  _cairo_surface* surface_ = nullptr;
};

// The safety monitor's zone as the box render_bev draws (every height).
[[nodiscard]] perception::Box3 stop_zone_box(const output::safety::Zone& z);

[[nodiscard]] Picture render_bev(std::span<const perception::LabeledPoint> points,
                                 std::span<const perception::Obstacle> obstacles,
                                 const perception::PipelineParams& params,
                                 const std::optional<perception::Box3>& stop_zone, const BevCaption& caption,
                                 const BevView& view = {});

}  // namespace fieldguard::app
