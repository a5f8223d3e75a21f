// The stop zone's overlap test: box edges, oriented footprints, non-finite values.

#include <gtest/gtest.h>

#include <limits>

#include "fieldguard/output/safety_monitor.hpp"
#include "output/test_obstacles.hpp"

namespace fieldguard::output::safety {
namespace {

constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();

using test::box;

TEST(SafetyZone, BoxOverlappingTheEdgeOverlapsThoughItsCentreIsOutside) {
  const Monitor m(Params{});
  const Zone z = m.zone_for(std::nullopt);                  // y within +-2 m
  EXPECT_TRUE(overlaps(box(5.0F, 1.9F, 6.0F, 3.0F), z));    // centre at y 2.45 m, edge 0.1 m inside
  EXPECT_TRUE(overlaps(box(5.0F, -3.0F, 6.0F, -2.0F), z));  // touching counts
  EXPECT_FALSE(overlaps(box(5.0F, 2.01F, 6.0F, 3.0F), z));
  const double far_edge = z.x_max_m;
  EXPECT_TRUE(overlaps(box(static_cast<float>(far_edge) - 0.1F, -0.2F, static_cast<float>(far_edge) + 2.F, 0.2F), z));
  EXPECT_FALSE(overlaps(box(static_cast<float>(far_edge) + 0.1F, -0.2F, static_cast<float>(far_edge) + 2.F, 0.2F), z));
  // Beside the tractor, behind its front.
  EXPECT_TRUE(overlaps(box(-3.0F, 1.6F, -2.0F, 2.5F), z));
  EXPECT_FALSE(overlaps(box(-7.0F, 1.6F, -5.5F, 2.5F), z));  // behind the zone's rear edge
}

TEST(SafetyZone, DiagonalFootprintBesideTheZoneCornerDoesNotStop) {
  const Monitor m(Params{});
  const Zone z = m.zone_for(std::nullopt);
  // A 6 m x 0.4 m hedge at 45 degrees whose axis-aligned box covers the zone's corner (x_max, 2) but whose
  // footprint passes 1.9 m outside it.
  perception::Obstacle o;
  const float cx = static_cast<float>(z.x_max_m) + 1.5F;
  const float cy = 3.5F;
  o.obb_center = {cx, cy};
  o.obb_length_m = 6.0F;
  o.obb_width_m = 0.4F;
  o.obb_yaw_rad = -0.7853982F;  // along (1, -1): forward and to the right
  o.min = {cx - 2.26F, cy - 2.26F, 0.F};
  o.max = {cx + 2.26F, cy + 2.26F, 1.F};
  EXPECT_TRUE(static_cast<double>(o.min[0]) < z.x_max_m && static_cast<double>(o.min[1]) < z.half_width_m);
  // Centre offset (1.5, 1.5) from the corner: distance along the footprint's normal (1, 1)/sqrt2 is 2.12 m,
  // minus half its width 0.2 m: 1.9 m clear of the corner.
  EXPECT_FALSE(overlaps(o, z));
  // The same hedge turned to run along (1, 1) points at the corner and reaches into the zone.
  o.obb_yaw_rad = 0.7853982F;
  EXPECT_TRUE(overlaps(o, z));
}

TEST(SafetyZone, NaNFootprintFallsBackToTheBox) {
  const Zone z = Monitor(Params{}).zone_for(std::nullopt);
  auto o = box(5.0F, -0.2F, 6.0F, 0.2F);
  o.obb_yaw_rad = kNaNf;
  EXPECT_TRUE(overlaps(o, z));
  o = box(5.0F, 2.5F, 6.0F, 3.0F);
  o.obb_center[0] = kNaNf;
  EXPECT_FALSE(overlaps(o, z));
}

}  // namespace
}  // namespace fieldguard::output::safety
