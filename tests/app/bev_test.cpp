// The bird's-eye picture (cairo): the header says the decision in its colour with the frame and its time, the
// boxes are coloured by kind (the hold's cyan and labelled "held"), the stop zone is drawn in the decision's
// colour, labels cover no box and no other label even in a crowded frame, the picture is at least 800 px tall,
// and the PNG it writes reads back.

#include "fieldguard/writers/bev.hpp"

#include <cairo.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace fieldguard::app {
namespace {

using Px = std::array<std::uint8_t, 3>;

// A 1 m x 1 m obstacle from (x, y) to (x + 1, y + 1), axis-aligned.
perception::Obstacle square(double x, double y, bool held = false) {
  perception::Obstacle o;
  o.min = {static_cast<float>(x), static_cast<float>(y), -0.5F};
  o.max = {static_cast<float>(x + 1), static_cast<float>(y + 1), 1.F};
  o.obb_center = {static_cast<float>(x + 0.5), static_cast<float>(y + 0.5)};
  o.obb_length_m = 1.F;
  o.obb_width_m = 1.F;
  o.distance_m = static_cast<float>(x);
  o.held = held;
  return o;
}

output::safety::Decision decided(bool stop) {
  output::safety::Decision d;
  d.stop = stop;
  d.reason = stop ? output::safety::Reason::ObstacleInZone : output::safety::Reason::None;
  d.reasons = stop ? output::safety::bit(output::safety::Reason::ObstacleInZone) : 0;
  d.nearest_m = stop ? std::optional<float>(5.4F) : std::nullopt;
  d.zone = {0.4, 12.0, 2.0, false};
  return d;
}

// The map pixel of the point (x ahead, y left) in the default view.
Px at(const Picture& p, double x, double y) {
  const BevView v;
  return p.pixel(static_cast<int>(std::floor((v.y_half_m - y) * v.px_per_m)),
                 static_cast<int>(std::floor(64.0 + (v.x_max_m - x) * v.px_per_m)));
}

bool reddish(Px c) { return c[0] > 150 && c[1] < 90 && c[2] < 90; }
bool greenish(Px c) { return c[1] > 110 && c[0] < 90; }

TEST(Bev, HeaderSaysTheDecisionInItsColourAndThePictureIsTallEnough) {
  const perception::PipelineParams params;
  const auto stop = decided(true);
  const auto go = decided(false);
  BevCaption c{123, Stamp{1'718'449'170'100'000'000}, false, &stop, 3};
  const Picture s = render_bev({}, {}, params, std::nullopt, c);
  EXPECT_GE(s.height(), 800);
  EXPECT_TRUE(reddish(s.pixel(s.width() - 5, 5))) << int{s.pixel(s.width() - 5, 5)[0]};
  c.decision = &go;
  const Picture g = render_bev({}, {}, params, std::nullopt, c);
  EXPECT_TRUE(greenish(g.pixel(g.width() - 5, 5)));
  // The word itself: white pixels in the header's left part (STOP or GO drawn, not a blank band).
  int white = 0;
  for (int y = 10; y < 55; ++y) {
    for (int x = 10; x < 110; ++x) white += g.pixel(x, y)[0] > 230 && g.pixel(x, y)[1] > 230 ? 1 : 0;
  }
  EXPECT_GT(white, 50);
}

TEST(Bev, BoxesByKindAndTheHeldOnesLabelledSo) {
  const perception::PipelineParams params;
  std::vector<perception::Obstacle> obstacles = {square(20, 2), square(30, -6, true)};
  obstacles[0].size_class = perception::SizeClass::Small;
  const Picture p = render_bev({}, obstacles, params, std::nullopt, BevCaption{});
  // The near edges' midpoints: red for the filters' small obstacle, cyan for the hold's.
  const Px red = at(p, 20.0, 2.5);
  EXPECT_TRUE(reddish(red)) << int{red[0]} << "," << int{red[1]} << "," << int{red[2]};
  const Px cyan = at(p, 30.0, -5.5);
  EXPECT_TRUE(cyan[2] > 200 && cyan[1] > 150 && cyan[0] < 120) << int{cyan[0]} << "," << int{cyan[1]};
  ASSERT_EQ(p.label_texts.size(), 2U);
  EXPECT_EQ(p.label_texts[0], "20.0 m");
  EXPECT_EQ(p.label_texts[1], "30.0 m held");
}

TEST(Bev, TheStopZoneIsDrawnInTheDecisionsColour) {
  const perception::PipelineParams params;
  const perception::Box3 zone{{0.4, -2.0, -10.0}, {12.0, 2.0, 10.0}};
  const auto stop = decided(true);
  const auto go = decided(false);
  // The zone's far edge, in the middle (nothing else is drawn there but the grid).
  const Picture s = render_bev({}, {}, params, zone, BevCaption{1, {}, false, &stop, 3});
  EXPECT_TRUE(reddish(at(s, 12.0, 0.3)));
  const Picture g = render_bev({}, {}, params, zone, BevCaption{1, {}, false, &go, 3});
  EXPECT_TRUE(greenish(at(g, 12.0, 0.3)));
}

TEST(Bev, LabelsCoverNoBoxAndNoOtherLabelInACrowdedFrame) {
  // Sixteen boxes in a 4 x 4 block, 2.5 m apart, and a row of five touching boxes: labels must find room.
  std::vector<perception::Obstacle> obstacles;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) obstacles.push_back(square(10.0 + 2.5 * i, -5.0 + 2.5 * j));
  }
  for (int k = 0; k < 5; ++k) obstacles.push_back(square(30.0, -6.0 + 1.05 * k));
  const Picture p = render_bev({}, obstacles, perception::PipelineParams{}, std::nullopt, BevCaption{});
  ASSERT_EQ(p.labels.size(), obstacles.size());
  for (std::size_t i = 0; i < p.labels.size(); ++i) {
    for (std::size_t j = 0; j < p.boxes.size(); ++j) {
      EXPECT_FALSE(p.labels[i].overlaps(p.boxes[j])) << "label " << i << " covers box " << j;
    }
    for (std::size_t j = i + 1; j < p.labels.size(); ++j) {
      EXPECT_FALSE(p.labels[i].overlaps(p.labels[j])) << "labels " << i << " and " << j;
    }
  }
}

TEST(Bev, ThePngReadsBack) {
  const auto dir = std::filesystem::temp_directory_path() / "fg_bev_png";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "b.png").string();
  const std::vector<perception::Obstacle> one = {square(20, 2)};
  const Picture p = render_bev({}, one, perception::PipelineParams{}, std::nullopt, BevCaption{});
  ASSERT_EQ(p.write_png(path), "");
  cairo_surface_t* back = cairo_image_surface_create_from_png(path.c_str());
  EXPECT_EQ(cairo_surface_status(back), CAIRO_STATUS_SUCCESS);
  EXPECT_EQ(cairo_image_surface_get_width(back), p.width());
  EXPECT_EQ(cairo_image_surface_get_height(back), p.height());
  cairo_surface_destroy(back);
  const auto bytes = p.png();
  ASSERT_GT(bytes.size(), 8U);
  EXPECT_EQ(bytes[1], 'P');
  EXPECT_NE(p.write_png((dir / "no" / "such" / "b.png").string()), "");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace fieldguard::app
