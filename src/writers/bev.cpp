#include "fieldguard/writers/bev.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace fieldguard::app {
namespace {

struct Projector {
  const BevView& v;
  [[nodiscard]] int col(double y) const { return static_cast<int>(std::lround((v.y_half_m - y) * v.px_per_m)); }
  [[nodiscard]] int row(double x) const { return static_cast<int>(std::lround((v.x_max_m - x) * v.px_per_m)); }
};

// Blue (low) -> cyan -> green -> yellow -> red (high), over z in [-1.5, 3] m of the sensor frame.
Rgb height_colour(float z, float brightness) {
  const float t = std::clamp((z + 1.5F) / 4.5F, 0.F, 1.F);
  const float r = std::clamp(4.F * t - 2.F, 0.F, 1.F);
  const float g = std::clamp(t < 0.75F ? 4.F * t : 4.F - 4.F * t, 0.F, 1.F);
  const float b = std::clamp(2.F - 4.F * t, 0.F, 1.F);
  auto u8 = [brightness](float c) { return static_cast<std::uint8_t>(std::lround(55.F + 200.F * c * brightness)); };
  return {u8(r), u8(g), u8(b)};
}

void rect(Image& img, const Projector& p, double x0, double y0, double x1, double y1, Rgb c) {
  img.line(p.col(y0), p.row(x0), p.col(y1), p.row(x0), c);
  img.line(p.col(y1), p.row(x0), p.col(y1), p.row(x1), c);
  img.line(p.col(y1), p.row(x1), p.col(y0), p.row(x1), c);
  img.line(p.col(y0), p.row(x1), p.col(y0), p.row(x0), c);
}

}  // namespace

Image render_bev(std::span<const perception::LabeledPoint> points, const perception::FrameResult& result,
                 const perception::PipelineParams& params, const std::optional<perception::Box3>& stop_zone,
                 const BevView& view) {
  const int w = static_cast<int>(std::lround(2.0 * view.y_half_m * view.px_per_m));
  const int h = static_cast<int>(std::lround((view.x_max_m - view.x_min_m) * view.px_per_m));
  Image img(w + 1, h + 1, {16, 16, 20});
  const Projector p{view};

  // Metre grid, every 10 m brighter and labelled with the distance ahead.
  for (int x = static_cast<int>(std::ceil(view.x_min_m)); x <= static_cast<int>(view.x_max_m); ++x) {
    const Rgb c = x % 10 == 0 ? Rgb{70, 70, 80} : Rgb{32, 32, 40};
    img.line(0, p.row(x), w, p.row(x), c);
    if (x % 10 == 0) img.text(2, p.row(x) - 8, std::to_string(x) + "m", {120, 120, 130});
  }
  for (int y = -static_cast<int>(view.y_half_m); y <= static_cast<int>(view.y_half_m); ++y) {
    img.line(p.col(y), 0, p.col(y), h, y % 10 == 0 ? Rgb{70, 70, 80} : Rgb{32, 32, 40});
  }

  for (const auto& pt : points) {
    const bool ground = pt.label == perception::PointLabel::Ground;
    const Rgb c =
        ground ? Rgb{60, 60, 60} : height_colour(pt.z, pt.label == perception::PointLabel::Obstacle ? 1.F : 0.55F);
    img.set(p.col(static_cast<double>(pt.y)), p.row(static_cast<double>(pt.x)), c);
  }

  rect(img, p, params.roi.min[0], params.roi.min[1], params.roi.max[0], params.roi.max[1], {200, 200, 60});
  rect(img, p, params.body.min[0], params.body.min[1], params.body.max[0], params.body.max[1], {80, 120, 255});
  if (stop_zone) {
    rect(img, p, stop_zone->min[0], stop_zone->min[1], stop_zone->max[0], stop_zone->max[1], {255, 60, 200});
  }

  draw_obstacles(img, result.obstacles, view);
  return img;
}

void draw_obstacles(Image& img, std::span<const perception::Obstacle> obstacles, const BevView& view) {
  const Projector p{view};
  for (const auto& o : obstacles) {
    // Held (obstacle_hold.hpp): cyan, and said so under the distance.
    const Rgb c = o.held                                         ? Rgb{60, 220, 255}
                  : o.size_class == perception::SizeClass::Small ? Rgb{255, 50, 50}
                                                                 : Rgb{255, 150, 40};
    const double cy = std::cos(static_cast<double>(o.obb_yaw_rad));
    const double sy = std::sin(static_cast<double>(o.obb_yaw_rad));
    const double hl = static_cast<double>(o.obb_length_m) / 2.0;
    const double hw = static_cast<double>(o.obb_width_m) / 2.0;
    const auto cx0 = static_cast<double>(o.obb_center[0]);
    const auto cy0 = static_cast<double>(o.obb_center[1]);
    const double corners[4][2] = {{hl, hw}, {-hl, hw}, {-hl, -hw}, {hl, -hw}};
    for (int i = 0; i < 4; ++i) {
      const auto& a = corners[i];
      const auto& b = corners[(i + 1) % 4];
      img.line(p.col(cy0 + a[0] * sy + a[1] * cy), p.row(cx0 + a[0] * cy - a[1] * sy),
               p.col(cy0 + b[0] * sy + b[1] * cy), p.row(cx0 + b[0] * cy - b[1] * sy), c);
    }
    char label[32];
    std::snprintf(label, sizeof label, "%.1fm", static_cast<double>(o.distance_m));
    const int col = p.col(static_cast<double>(o.max[1]));
    const int row = p.row(static_cast<double>(o.max[0]));
    img.text(col, row - 9, label, {255, 255, 255});
    if (o.held) img.text(col, row + 1, "held", c);
  }
}

}  // namespace fieldguard::app
