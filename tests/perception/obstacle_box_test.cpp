#include "fieldguard/perception/obstacle_box.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace fieldguard::perception {
namespace {

using P2 = std::array<float, 2>;

// The outline and inside of a 3 m x 1 m rectangle turned by `yaw`, centred at (10, -2).
std::vector<P2> rectangle(float yaw) {
  std::vector<P2> pts;
  const float c = std::cos(yaw), s = std::sin(yaw);
  for (float u = -1.5F; u <= 1.5001F; u += 0.1F) {
    for (float v = -0.5F; v <= 0.5001F; v += 0.1F) pts.push_back({10.F + c * u - s * v, -2.F + s * u + c * v});
  }
  return pts;
}

TEST(MinAreaRect, OfARotatedRectangle) {
  std::vector<P2> hull;
  HullScratch scratch;
  for (const float deg : {0.F, 30.F, -60.F, 89.F, 135.F}) {
    auto pts = rectangle(deg * std::numbers::pi_v<float> / 180.F);
    const OrientedRect r = min_area_rect(pts, hull, scratch);
    EXPECT_NEAR(r.length_m, 3.F, 1e-3F) << deg;
    EXPECT_NEAR(r.width_m, 1.F, 1e-3F) << deg;
    EXPECT_NEAR(r.center[0], 10.F, 1e-3F) << deg;
    EXPECT_NEAR(r.center[1], -2.F, 1e-3F) << deg;
    float expected = deg;  // the length axis, folded into (-90, 90]
    while (expected > 90.F) expected -= 180.F;
    while (expected <= -90.F) expected += 180.F;
    EXPECT_NEAR(r.yaw_rad * 180.F / std::numbers::pi_v<float>, expected, 0.05F) << deg;
  }
}

TEST(MinAreaRect, DegenerateFootprints) {
  std::vector<P2> hull;
  HullScratch scratch;
  std::vector<P2> one{{3.F, 4.F}};
  OrientedRect r = min_area_rect(one, hull, scratch);
  EXPECT_FLOAT_EQ(r.center[0], 3.F);
  EXPECT_FLOAT_EQ(r.center[1], 4.F);
  EXPECT_FLOAT_EQ(r.length_m, 0.F);
  std::vector<P2> same{{1.F, 1.F}, {1.F, 1.F}, {1.F, 1.F}};
  r = min_area_rect(same, hull, scratch);
  EXPECT_FLOAT_EQ(r.length_m, 0.F);
  std::vector<P2> line{{0.F, 0.F}, {1.F, 1.F}, {2.F, 2.F}, {0.5F, 0.5F}};
  r = min_area_rect(line, hull, scratch);
  EXPECT_NEAR(r.length_m, 2.F * std::sqrt(2.F), 1e-5F);
  EXPECT_NEAR(r.width_m, 0.F, 1e-6F);
  EXPECT_NEAR(r.yaw_rad, std::numbers::pi_v<float> / 4.F, 1e-6F);
  EXPECT_NEAR(r.center[0], 1.F, 1e-6F);
  std::vector<P2> none;
  r = min_area_rect(none, hull, scratch);
  EXPECT_FLOAT_EQ(r.length_m, 0.F);
}

TEST(ConvexHull, CounterClockwiseWithoutCollinearPoints) {
  std::vector<P2> pts{{0, 0}, {1, 0}, {2, 0}, {2, 2}, {1, 1}, {0, 2}, {1, 2}};
  std::vector<P2> hull;
  HullScratch scratch;
  convex_hull(pts, hull, scratch);
  EXPECT_EQ(hull, (std::vector<P2>{{0, 0}, {2, 0}, {2, 2}, {0, 2}}));
}

// Many points, a disc and a ring of them: every point inside or on the hull, every vertex an input point.
TEST(ConvexHull, ContainsEveryPoint) {
  std::vector<P2> pts, hull;
  HullScratch scratch;
  for (int i = 0; i < 400; ++i) {
    const float a = 0.0157F * static_cast<float>(i * 7 % 400),
                r = (i % 4 == 0) ? 2.F : 1.F + 0.002F * static_cast<float>(i);
    pts.push_back({3.F + r * std::cos(a), -1.F + r * std::sin(a)});
  }
  convex_hull(pts, hull, scratch);
  // The hull's vertices are exactly the points that no triangle of others contains: check every point is
  // inside or on the hull, and every vertex is an input point.
  for (const auto& p : pts) {
    for (std::size_t k = 0; k < hull.size(); ++k) {
      const auto& a = hull[k];
      const auto& b = hull[(k + 1) % hull.size()];
      const auto d = [](float v) { return static_cast<double>(v); };
      const double c = (d(b[0]) - d(a[0])) * (d(p[1]) - d(a[1])) - (d(b[1]) - d(a[1])) * (d(p[0]) - d(a[0]));
      ASSERT_GE(c, -1e-5) << p[0] << ", " << p[1];
    }
  }
  for (const auto& v : hull) EXPECT_NE(std::find(pts.begin(), pts.end(), v), pts.end());
  EXPECT_GE(hull.size(), 20U);
  // The same hull from the radix-sorted path (over 256 points) as from the comparison sort (a subset of the
  // same points, whose hull must contain no point outside the full hull).
  std::vector<P2> few(pts.begin(), pts.begin() + 200), few_hull;
  convex_hull(few, few_hull, scratch);
  for (const auto& p : few_hull) EXPECT_NE(std::find(pts.begin(), pts.end(), p), pts.end());
}

// The pre-filter (over 64 points) on a filled square grid: its corners are extreme along several of the
// filter's directions at once, so the filter's polygon repeats them; the inside must still be left out (only
// the outline, on the polygon's edges, may be kept) and the hull is the four corners.
TEST(ConvexHull, PrefilterLeavesOutTheInsideOfASquare) {
  std::vector<P2> pts, hull;
  HullScratch scratch;
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j)
      pts.push_back({-5.F + 0.1F * static_cast<float>(i), 2.F + 0.1F * static_cast<float>(j)});
  }
  convex_hull(pts, hull, scratch);
  EXPECT_LE(scratch.points.size(), 396U);  // the outline: 4 * 99 points
  ASSERT_EQ(hull.size(), 4U);
  EXPECT_EQ(hull[0], pts.front());
  EXPECT_EQ(hull[1], pts[99 * 100]);
  EXPECT_EQ(hull[2], pts.back());
  EXPECT_EQ(hull[3], pts[99]);
}

// A hull vertex that is extreme along none of the filter's 16 directions, 10 um outside the line between
// two that are: the float test must keep it (too near the edge to tell), and the exact hull finds it.
TEST(ConvexHull, PrefilterKeepsAVertexJustOutsideItsPolygon) {
  std::vector<P2> pts, hull;
  HullScratch scratch;
  // A filled triangle (0, 0), (10, -5), (10, 1), and above its top edge, at a third of its length, p.
  for (int i = 0; i <= 40; ++i) {
    const float x = 0.25F * static_cast<float>(i);
    for (float y = -0.5F * x; y <= 0.1F * x; y += 0.25F) pts.push_back({x, y});
    pts.push_back({x, 0.1F * x});  // the top edge itself
  }
  const P2 p{10.F / 3.F, 1.F / 3.F + 1e-5F};
  pts.push_back(p);
  ASSERT_GT(pts.size(), 64U);
  convex_hull(pts, hull, scratch);
  EXPECT_EQ(hull, (std::vector<P2>{{0.F, 0.F}, {10.F, -5.F}, {10.F, 1.F}, p}));
}

// Interior points and points just inside the hull's edges (outside the filter's polygon, so kept by it, but
// no vertices) around a 100-gon: the hull is the 100 corners, counter-clockwise from the lowest-leftmost.
TEST(ConvexHull, PrefilterAroundAPolygonOfManyCorners) {
  std::vector<P2> corners, pts, hull;
  HullScratch scratch;
  constexpr int kCorners = 100;
  for (int k = 0; k < kCorners; ++k) {
    const double a = 2.0 * std::numbers::pi * k / kCorners;
    corners.push_back({static_cast<float>(3.0 + 10.0 * std::cos(a)), static_cast<float>(-7.0 + 10.0 * std::sin(a))});
  }
  for (int k = 0; k < kCorners; ++k) {
    const P2& a = corners[static_cast<std::size_t>(k)];
    const P2& b = corners[static_cast<std::size_t>((k + 1) % kCorners)];
    // The edge's midpoint, pulled towards the centre by a tenth of the edge's 5 mm sagitta.
    const float mx = 0.5F * (a[0] + b[0]), my = 0.5F * (a[1] + b[1]);
    pts.push_back({3.F + (mx - 3.F) * 0.9999F, -7.F + (my + 7.F) * 0.9999F});
    for (int r = 1; r <= 9; ++r)
      pts.push_back(
          {3.F + (a[0] - 3.F) * 0.1F * static_cast<float>(r), -7.F + (a[1] + 7.F) * 0.1F * static_cast<float>(r)});
  }
  pts.insert(pts.end(), corners.begin(), corners.end());
  convex_hull(pts, hull, scratch);
  ASSERT_EQ(hull.size(), corners.size());
  const auto first = std::min_element(corners.begin(), corners.end());  // lowest x, then y
  std::vector<P2> expected(first, corners.end());
  expected.insert(expected.end(), corners.begin(), first);
  EXPECT_EQ(hull, expected);
}

TEST(SizeClass, PersonSizedIsSmall) {
  EXPECT_EQ(size_class(0.6F, 0.4F, 1.8F), SizeClass::Small);
  EXPECT_EQ(size_class(1.2F, 1.2F, 2.2F), SizeClass::Small);
  EXPECT_EQ(size_class(1.3F, 0.4F, 1.0F), SizeClass::Large);  // an implement's drawbar
  EXPECT_EQ(size_class(0.5F, 0.5F, 2.5F), SizeClass::Large);  // a pole
  EXPECT_EQ(to_string(SizeClass::Large), "large");
}

}  // namespace
}  // namespace fieldguard::perception

namespace fieldguard::perception {
namespace {

// Two faces of a 4 m x 2.6 m box seen at a corner: an L of points whose hull is a right triangle. The
// rectangle follows the faces, not the hypotenuse (both have the same area).
TEST(MinAreaRect, TwoFacesSeenAtACornerGiveTheBox) {
  for (const float yaw : {0.3F, 1.3F, -0.9F}) {
    const float c = std::cos(yaw), s = std::sin(yaw);
    std::vector<P2> pts;
    for (float u = 0.F; u <= 4.0001F; u += 0.1F) pts.push_back({c * u, s * u});    // long face
    for (float v = 0.1F; v <= 2.6001F; v += 0.1F) pts.push_back({-s * v, c * v});  // short face
    std::vector<P2> hull;
    HullScratch scratch;
    const OrientedRect r = min_area_rect(pts, hull, scratch);
    EXPECT_NEAR(r.length_m, 4.F, 1e-3F) << yaw;
    EXPECT_NEAR(r.width_m, 2.6F, 1e-3F) << yaw;
    EXPECT_NEAR(r.yaw_rad, yaw, 1e-3F) << yaw;
  }
}

}  // namespace
}  // namespace fieldguard::perception
