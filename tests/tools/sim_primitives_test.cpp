// Ray intersection with the simulator's solids and its terrain, on rays whose answers are known by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/primitives.hpp"
#include "sim/terrain.hpp"

namespace fieldguard::sim {
namespace {

Ray ray(Vec3 o, Vec3 d) { return {o, normalized(d)}; }

TEST(SimPrimitives, BoxFaceHitAndNormal) {
  const Primitive box = make_box_minmax({10.0, -1.0, 0.0}, {12.0, 1.0, 2.0});
  Span s;
  ASSERT_TRUE(intersect(box, ray({0.0, 0.0, 1.0}, {1.0, 0.0, 0.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 10.0, 1e-9);
  EXPECT_NEAR(s.t_out, 12.0, 1e-9);
  EXPECT_NEAR(s.normal.x, -1.0, 1e-9);
  // Misses above, and beyond tmax.
  EXPECT_FALSE(intersect(box, ray({0.0, 0.0, 2.5}, {1.0, 0.0, 0.0}), 100.0, s));
  EXPECT_FALSE(intersect(box, ray({0.0, 0.0, 1.0}, {1.0, 0.0, 0.0}), 9.0, s));
  // Through the top at 45 degrees down: enters z = 2 at x = 11.
  ASSERT_TRUE(intersect(box, ray({9.0, 0.0, 4.0}, {1.0, 0.0, -1.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 2.0 * std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(s.normal.z, 1.0, 1e-9);
}

TEST(SimPrimitives, YawedBoxCorner) {
  // A 2 x 2 box turned 45 degrees: its corner points at the ray, sqrt(2) from the centre.
  const Primitive box = make_box({10.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, kPi / 4.0);
  Span s;
  ASSERT_TRUE(intersect(box, ray({0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 10.0 - std::sqrt(2.0), 1e-9);
  const Aabb b = bounds(box);
  EXPECT_NEAR(b.max.x - b.min.x, 2.0 * std::sqrt(2.0), 1e-9);
}

TEST(SimPrimitives, VerticalCylinderSideAndCap) {
  const Primitive cyl = make_vertical_cylinder({5.0, 0.0, 0.0}, 0.5, 2.0);
  Span s;
  ASSERT_TRUE(intersect(cyl, ray({0.0, 0.0, 1.0}, {1.0, 0.0, 0.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 4.5, 1e-9);
  EXPECT_NEAR(s.t_out, 5.5, 1e-9);
  // Off-axis by 0.3: chord half-length 0.4.
  ASSERT_TRUE(intersect(cyl, ray({0.0, 0.3, 1.0}, {1.0, 0.0, 0.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 4.6, 1e-9);
  EXPECT_FALSE(intersect(cyl, ray({0.0, 0.6, 1.0}, {1.0, 0.0, 0.0}), 100.0, s));
  // Straight down onto the top cap.
  ASSERT_TRUE(intersect(cyl, ray({5.1, 0.1, 10.0}, {0.0, 0.0, -1.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 8.0, 1e-9);
  EXPECT_NEAR(s.normal.z, 1.0, 1e-9);
  // Above the top: misses.
  EXPECT_FALSE(intersect(cyl, ray({0.0, 0.0, 2.1}, {1.0, 0.0, 0.0}), 100.0, s));
}

TEST(SimPrimitives, LyingCylinderIsABale) {
  // Axis along y, radius 0.75, centre 0.75 up: a ray along x at the centre height meets it at x = 10 - 0.75.
  const Primitive bale = make_lying_cylinder({10.0, 0.0, 0.75}, 0.75, 0.6, kPi / 2.0);
  Span s;
  ASSERT_TRUE(intersect(bale, ray({0.0, 0.0, 0.75}, {1.0, 0.0, 0.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 9.25, 1e-9);
  EXPECT_FALSE(intersect(bale, ray({0.0, 0.7, 0.75}, {1.0, 0.0, 0.0}), 100.0, s));  // beyond its 0.6 half width
  const Aabb b = bounds(bale);
  EXPECT_NEAR(b.max.y - b.min.y, 1.2, 1e-9);
  EXPECT_NEAR(b.max.z - b.min.z, 1.5, 1e-9);
}

TEST(SimPrimitives, EllipsoidAlongEachAxis) {
  const Primitive e = make_ellipsoid({20.0, 0.0, 2.0}, {1.5, 1.0, 0.5});
  Span s;
  ASSERT_TRUE(intersect(e, ray({0.0, 0.0, 2.0}, {1.0, 0.0, 0.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 18.5, 1e-9);
  EXPECT_NEAR(s.t_out, 21.5, 1e-9);
  ASSERT_TRUE(intersect(e, ray({20.0, 0.0, 10.0}, {0.0, 0.0, -1.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 7.5, 1e-9);
  ASSERT_TRUE(intersect(e, ray({20.0, -5.0, 2.0}, {0.0, 1.0, 0.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 4.0, 1e-9);
  EXPECT_FALSE(intersect(e, ray({0.0, 0.0, 2.6}, {1.0, 0.0, 0.0}), 100.0, s));
}

TEST(SimPrimitives, CapsuleRoundEnds) {
  const Primitive c = make_capsule({0.0, 5.0, 0.0}, {10.0, 5.0, 0.0}, 1.0);
  Span s;
  // Across the middle.
  ASSERT_TRUE(intersect(c, ray({5.0, 0.0, 0.0}, {0.0, 1.0, 0.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 4.0, 1e-9);
  // Along the axis: enters the far end's hemisphere... the near one: x = -1.
  ASSERT_TRUE(intersect(c, ray({-5.0, 5.0, 0.0}, {1.0, 0.0, 0.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 4.0, 1e-9);
  EXPECT_NEAR(s.t_out, 16.0, 1e-9);
  // Past the end cap at 0.5 off the axis: sphere chord.
  ASSERT_TRUE(intersect(c, ray({-0.5, 0.0, 0.5}, {0.0, 1.0, 0.0}), 100.0, s));
  EXPECT_NEAR(s.t_in, 5.0 - std::sqrt(1.0 - 0.25 - 0.25), 1e-9);
}

TEST(SimTerrain, FlatGroundAtKnownRange) {
  Terrain t(TerrainParams{}, {}, 1);
  // From 0.95 m up, 10 degrees down: ground at 0.95 / sin(10 deg).
  const double el = -10.0 * kDegToRad;
  double hit = 0.0;
  ASSERT_TRUE(t.intersect(ray({0.0, 0.0, 0.95}, {std::cos(el), 0.0, std::sin(el)}), 100.0, hit));
  EXPECT_NEAR(hit, 0.95 / std::sin(10.0 * kDegToRad), 2e-3);
  // Level and upward rays never meet flat ground.
  EXPECT_FALSE(t.intersect(ray({0.0, 0.0, 0.95}, {1.0, 0.0, 0.0}), 100.0, hit));
  EXPECT_FALSE(t.intersect(ray({0.0, 0.0, 0.95}, {1.0, 0.0, 0.1}), 100.0, hit));
  // A ray that would reach the ground beyond tmax.
  EXPECT_FALSE(t.intersect(ray({0.0, 0.0, 0.95}, {1.0, 0.0, -0.01}), 50.0, hit));
}

TEST(SimTerrain, SlopeAndFurrowsHitOnTheSurface) {
  TerrainParams p;
  p.grade_x = 0.08;  // climbing ahead
  p.furrow_amplitude_m = 0.05;
  p.furrow_period_m = 0.75;
  p.furrow_heading_deg = 30.0;
  Terrain t(p, {}, 7);
  // A level ray 1 m above the ground at x = 0 meets the slope near x = 1 / 0.08 = 12.5 m.
  double hit = 0.0;
  ASSERT_TRUE(t.intersect(ray({0.0, 0.0, 1.0}, {1.0, 0.0, 0.0}), 100.0, hit));
  EXPECT_NEAR(hit, 12.5, 1.5);
  // Every hit of a fan of rays lies on the surface (within 1 mm) and nothing is above the ray before it.
  for (int k = 0; k < 200; ++k) {
    const double az = 2.0 * kPi * k / 200.0;
    const double el = (-2.0 - 0.14 * k) * kDegToRad;
    const Ray r = ray({0.0, 0.0, 0.95}, {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)});
    if (!t.intersect(r, 100.0, hit)) continue;
    const Vec3 q = r.origin + r.dir * hit;
    EXPECT_NEAR(q.z, t.height(q.x, q.y), 2e-3) << "ray " << k;
    for (double s = 0.0; s < hit - 0.05; s += 0.05) {
      const Vec3 a = r.origin + r.dir * s;
      ASSERT_GT(a.z, t.height(a.x, a.y) - 0.01) << "ray " << k << " passed under the ground at " << s;
    }
  }
}

}  // namespace
}  // namespace fieldguard::sim
