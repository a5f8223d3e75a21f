// The bird's-eye picture's obstacle boxes: the filters' in red (small) or orange (large), the hold's
// (obstacle_hold.hpp) in cyan and labelled "held", drawn by render_bev or afterwards by draw_obstacles.
#include "fieldguard/writers/bev.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace fieldguard::app {
namespace {

bool same(Rgb a, Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

// A 1 m x 1 m obstacle from (20, 2) to (21, 3), axis-aligned.
perception::Obstacle square(bool held) {
  perception::Obstacle o;
  o.min = {20.F, 2.F, -0.5F};
  o.max = {21.F, 3.F, 1.F};
  o.obb_center = {20.5F, 2.5F};
  o.obb_length_m = 1.F;
  o.obb_width_m = 1.F;
  o.distance_m = 20.1F;
  o.size_class = perception::SizeClass::Small;
  o.held = held;
  return o;
}

// The picture's pixel of the box's near edge's midpoint (x 20, y 2.5), as the default view maps it.
Rgb near_edge(const Image& img) {
  const BevView v;
  return img.get(static_cast<int>((v.y_half_m - 2.5) * v.px_per_m), static_cast<int>((v.x_max_m - 20.0) * v.px_per_m));
}

// Pixels of a colour in the rows just below the box's far edge (its label: distance, then "held").
int label_pixels(const Image& img, Rgb c) {
  const BevView v;
  const int col = static_cast<int>((v.y_half_m - 3.0) * v.px_per_m);
  const int row = static_cast<int>((v.x_max_m - 21.0) * v.px_per_m);
  int n = 0;
  for (int y = row + 1; y < row + 9; ++y) {
    for (int x = col; x < col + 30; ++x) n += same(img.get(x, y), c) ? 1 : 0;
  }
  return n;
}

constexpr Rgb kCyan{60, 220, 255};
constexpr Rgb kRed{255, 50, 50};

TEST(Bev, HeldObstaclesAreCyanAndLabelled) {
  perception::FrameResult r;
  r.obstacles = {square(false)};
  const Image filters = render_bev({}, r, perception::PipelineParams{}, std::nullopt);
  EXPECT_TRUE(same(near_edge(filters), kRed));
  EXPECT_EQ(label_pixels(filters, kCyan), 0);

  r.obstacles = {square(true)};
  const Image held = render_bev({}, r, perception::PipelineParams{}, std::nullopt);
  EXPECT_TRUE(same(near_edge(held), kCyan));
  EXPECT_GT(label_pixels(held, kCyan), 10) << "the word held under the distance";
}

// Replay's way: the worker's picture without the held obstacle, then the hold's drawn onto it.
TEST(Bev, DrawObstaclesAddsToAPicture) {
  perception::FrameResult r;
  Image img = render_bev({}, r, perception::PipelineParams{}, std::nullopt);
  EXPECT_FALSE(same(near_edge(img), kCyan));
  const std::vector<perception::Obstacle> held{square(true)};
  draw_obstacles(img, held);
  EXPECT_TRUE(same(near_edge(img), kCyan));
  perception::FrameResult with;
  with.obstacles = held;
  EXPECT_EQ(img.rgb(), render_bev({}, with, perception::PipelineParams{}, std::nullopt).rgb());
}

}  // namespace
}  // namespace fieldguard::app
