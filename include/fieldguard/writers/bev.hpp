#pragma once
// Bird's-eye picture of one processed rotation: points coloured by height with ground dimmed, obstacle
// boxes with their distance (the hold's labelled "held"), the region of interest, the body box and the stop
// zone, a metre grid.

#include <optional>
#include <span>

#include "fieldguard/perception/obstacle.hpp"
#include "fieldguard/perception/params.hpp"
#include "fieldguard/writers/png_writer.hpp"

namespace fieldguard::app {

struct BevView {
  double x_min_m = -15.0;  // behind the sensor (bottom of the picture)
  double x_max_m = 55.0;   // ahead (top)
  double y_half_m = 15.0;  // each side
  double px_per_m = 10.0;
};

[[nodiscard]] Image render_bev(std::span<const perception::LabeledPoint> points, const perception::FrameResult& result,
                               const perception::PipelineParams& params,
                               const std::optional<perception::Box3>& stop_zone, const BevView& view = {});

// Draws `obstacles`' oriented boxes and distances onto a picture render_bev made with `view` (render_bev draws the
// frame's own): replay adds the hold's obstacles (obstacle_hold.hpp) this way, since the hold runs after the
// worker that rendered the picture. Held ones are drawn in their own colour and labelled so.
void draw_obstacles(Image& img, std::span<const perception::Obstacle> obstacles, const BevView& view = {});

}  // namespace fieldguard::app
