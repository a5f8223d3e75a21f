#include "fieldguard/perception/obstacle_hold.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

namespace fieldguard::perception {
namespace {

constexpr std::int64_t kPeriod = 100'000'000;  // 10 Hz (ns)

Obstacle box(std::array<float, 3> min, std::array<float, 3> max) {
  Obstacle o;
  o.min = min;
  o.max = max;
  o.points = 20;
  o.distance_m = std::hypot(min[0], min[1]);
  return o;
}

Fragment fragment(std::array<float, 3> min, std::array<float, 3> max, std::uint32_t points) {
  return Fragment{min, max, points, std::hypot(min[0], min[1]), max[2] + 0.95F};
}

FrameResult frame(std::vector<Obstacle> obstacles, std::vector<Fragment> fragments = {}) {
  FrameResult r;
  r.obstacles = std::move(obstacles);
  r.fragments = std::move(fragments);
  r.counts.obstacles = static_cast<std::uint32_t>(r.obstacles.size());
  return r;
}

// A crown 15 m out, 2 m wide, from 0.8 to 2.8 m above a ground 0.95 m below the sensor.
const Obstacle kCrown = box({15.F, 7.F, -0.15F}, {17.F, 9.F, 1.85F});

HoldParams params() {
  HoldParams p;
  p.enabled = true;
  p.max_age_s = 0.35;
  p.gate_m = 0.3;
  p.min_points = 2;
  return p;
}

// The crown reported, then seen through a gap as two single returns inside its box and one just outside it,
// within the gate: one obstacle from the three, flagged held, with their box and points.
TEST(ObstacleHold, ReportsTheFragmentsWhereAnObstacleWasReportedLately) {
  ObstacleHold hold(params());
  FrameResult first = frame({kCrown});
  EXPECT_EQ(hold.apply(0, first), 0U);
  EXPECT_EQ(first.obstacles.size(), 1U);
  EXPECT_FALSE(first.obstacles[0].held);

  FrameResult next = frame(
      {}, {fragment({15.5F, 7.5F, 0.5F}, {15.5F, 7.5F, 0.5F}, 1), fragment({16.5F, 8.2F, 1.2F}, {16.6F, 8.3F, 1.3F}, 1),
           fragment({17.2F, 9.1F, 1.0F}, {17.25F, 9.2F, 1.0F}, 1)});
  ASSERT_EQ(hold.apply(kPeriod, next), 1U);
  EXPECT_EQ(next.counts.held, 1U);
  ASSERT_EQ(next.obstacles.size(), 1U);
  const Obstacle& h = next.obstacles[0];
  EXPECT_TRUE(h.held);
  EXPECT_EQ(h.points, 3U);
  EXPECT_EQ(h.min, (std::array<float, 3>{15.5F, 7.5F, 0.5F}));
  EXPECT_EQ(h.max, (std::array<float, 3>{17.25F, 9.2F, 1.3F}));
  EXPECT_FLOAT_EQ(h.distance_m, std::hypot(15.5F, 7.5F));
  EXPECT_FLOAT_EQ(h.height_above_ground_m, 1.3F + 0.95F);
  EXPECT_NEAR(h.bearing_deg, std::atan2(8.35, 16.375) * 180.0 / 3.141592653589793, 1e-3);
  EXPECT_FLOAT_EQ(h.obb_length_m, 1.75F);
  EXPECT_FLOAT_EQ(h.obb_width_m, 1.7F);
  EXPECT_FLOAT_EQ(h.obb_yaw_rad, 0.F);
  EXPECT_EQ(h.size_class, SizeClass::Large);
  EXPECT_EQ(h.sources, kSeenBy3d);
}

// Fewer points than min_points, or fragments beyond the gate, hold nothing.
TEST(ObstacleHold, TooFewPointsOrTooFarHoldNothing) {
  ObstacleHold hold(params());
  FrameResult first = frame({kCrown});
  (void)hold.apply(0, first);
  FrameResult one = frame({}, {fragment({16.F, 8.F, 1.F}, {16.F, 8.F, 1.F}, 1),
                               fragment({17.35F, 8.F, 1.F}, {17.4F, 8.F, 1.F}, 5)});  // 0.35 m beyond its x
  EXPECT_EQ(hold.apply(kPeriod, one), 0U);
  EXPECT_TRUE(one.obstacles.empty());
  EXPECT_EQ(one.counts.held, 0U);
  // Each axis's gate: beyond it in y, in z.
  FrameResult side = frame(
      {}, {fragment({16.F, 9.31F, 1.F}, {16.F, 9.4F, 1.F}, 5), fragment({16.F, 8.F, 2.16F}, {16.F, 8.F, 2.2F}, 5)});
  EXPECT_EQ(hold.apply(2 * kPeriod, side), 0U);
  // Within it, the same fragments moved in: held.
  FrameResult in = frame(
      {}, {fragment({16.F, 9.29F, 1.F}, {16.F, 9.4F, 1.F}, 1), fragment({16.F, 8.F, 2.14F}, {16.F, 8.F, 2.2F}, 1)});
  EXPECT_EQ(hold.apply(3 * kPeriod, in), 1U);
}

// Reported again: nothing is held, and the fragments beside the new report are not made a second obstacle.
TEST(ObstacleHold, AnObstacleReportedAgainIsNotHeldBesideItself) {
  ObstacleHold hold(params());
  FrameResult first = frame({kCrown});
  (void)hold.apply(0, first);
  Obstacle moved = kCrown;
  moved.min[0] -= 0.08F;  // the tractor drove 8 cm
  moved.max[0] -= 0.08F;
  moved.max[1] -= 0.9F;  // and saw only half of it
  FrameResult again = frame({moved}, {fragment({16.F, 8.6F, 1.F}, {16.2F, 8.8F, 1.2F}, 4)});
  EXPECT_EQ(hold.apply(kPeriod, again), 0U);
  EXPECT_EQ(again.obstacles.size(), 1U);
}

// Crowns nearly touching: the neighbour reported 0.2 m away is not the crown reported again, so the crown's
// fragments are held. A fragment inside the neighbour's box is the neighbour's, not the crown's.
TEST(ObstacleHold, ANeighbourWithinTheGateIsNotTheObstacleReportedAgain) {
  ObstacleHold hold(params());
  const Obstacle neighbour = box({17.2F, 7.F, -0.15F}, {19.F, 9.F, 1.6F});
  FrameResult first = frame({kCrown, neighbour});
  (void)hold.apply(0, first);
  FrameResult next = frame({neighbour}, {fragment({16.F, 8.F, 1.F}, {16.F, 8.F, 1.F}, 1),
                                         fragment({16.5F, 7.5F, 0.4F}, {16.5F, 7.5F, 0.4F}, 1),
                                         fragment({17.25F, 8.F, 1.F}, {17.3F, 8.1F, 1.F}, 3)});
  ASSERT_EQ(hold.apply(kPeriod, next), 1U);
  ASSERT_EQ(next.obstacles.size(), 2U);
  const Obstacle& h = next.obstacles[0].held ? next.obstacles[0] : next.obstacles[1];
  EXPECT_TRUE(h.held);
  EXPECT_EQ(h.points, 2U);
  EXPECT_FLOAT_EQ(h.max[0], 16.5F);
}

// Held for max_age_s after the filters' last report, however many frames held it in between, and not a frame
// longer: a held obstacle holds nothing itself.
TEST(ObstacleHold, LetsGoMaxAgeAfterTheLastReport) {
  ObstacleHold hold(params());
  FrameResult first = frame({kCrown});
  (void)hold.apply(0, first);
  const std::vector<Fragment> seen{fragment({16.F, 8.F, 1.F}, {16.2F, 8.F, 1.F}, 2)};
  for (int k = 1; k <= 3; ++k) {
    FrameResult f = frame({}, seen);
    EXPECT_EQ(hold.apply(k * kPeriod, f), 1U) << k;
  }
  FrameResult late = frame({}, seen);
  EXPECT_EQ(hold.apply(4 * kPeriod, late), 0U) << "0.4 s after the last report";
  EXPECT_EQ(hold.remembered(), 0U);
  // Exactly max_age_s after it: still held (the bound is inclusive).
  ObstacleHold edge(params());
  FrameResult f0 = frame({kCrown});
  (void)edge.apply(0, f0);
  FrameResult f1 = frame({}, seen);
  EXPECT_EQ(edge.apply(350'000'000, f1), 1U);
  FrameResult f2 = frame({}, seen);
  EXPECT_EQ(edge.apply(350'000'001, f2), 0U);
}

// Rotations lost in between only age what is remembered, and a new report renews it.
TEST(ObstacleHold, AReportRenewsTheMemory) {
  ObstacleHold hold(params());
  const std::vector<Fragment> seen{fragment({16.F, 8.F, 1.F}, {16.2F, 8.F, 1.F}, 2)};
  FrameResult f0 = frame({kCrown});
  (void)hold.apply(0, f0);
  FrameResult f1 = frame({}, seen);
  EXPECT_EQ(hold.apply(3 * kPeriod, f1), 1U);
  FrameResult f2 = frame({kCrown});  // reported again at 0.5 s
  EXPECT_EQ(hold.apply(5 * kPeriod, f2), 0U);
  FrameResult f3 = frame({}, seen);
  EXPECT_EQ(hold.apply(8 * kPeriod, f3), 1U) << "0.3 s after the second report";
}

// One fragment makes one held obstacle: two remembered obstacles whose gates share it do not both take it.
TEST(ObstacleHold, AFragmentGoesToOneHeldObstacle) {
  HoldParams p = params();
  p.min_points = 3;
  ObstacleHold hold(p);
  const Obstacle left = box({15.F, 7.F, 0.F}, {16.F, 8.F, 1.F});
  const Obstacle right = box({16.5F, 7.F, 0.F}, {17.5F, 8.F, 1.F});
  FrameResult first = frame({left, right});
  (void)hold.apply(0, first);
  FrameResult next = frame({}, {fragment({16.1F, 7.5F, 0.5F}, {16.4F, 7.6F, 0.6F}, 3)});
  EXPECT_EQ(hold.apply(kPeriod, next), 1U);
  EXPECT_EQ(next.obstacles.size(), 1U);
}

// Held obstacles take their place in the order of the filters' (sort_obstacles): nearest first.
TEST(ObstacleHold, KeepsTheObstaclesNearestFirst) {
  ObstacleHold hold(params());
  const Obstacle near = box({5.F, -1.F, -0.9F}, {5.5F, -0.5F, 0.8F});
  const Obstacle far = box({30.F, 0.F, -0.9F}, {30.5F, 0.5F, 0.8F});
  FrameResult first = frame({near, kCrown, far});
  (void)hold.apply(0, first);
  FrameResult next = frame({near, far}, {fragment({16.F, 8.F, 1.F}, {16.2F, 8.F, 1.F}, 2)});
  ASSERT_EQ(hold.apply(kPeriod, next), 1U);
  ASSERT_EQ(next.obstacles.size(), 3U);
  EXPECT_FALSE(next.obstacles[0].held);
  EXPECT_TRUE(next.obstacles[1].held);
  EXPECT_FALSE(next.obstacles[2].held);
  EXPECT_FLOAT_EQ(next.obstacles[2].min[0], 30.F);
}

// At 3 m/s the crown comes 0.6 m nearer in 0.2 s: its fragments are beyond the 0.3 m gate unless the speed is
// given, which grows the gate along x (either way: the bus's speed has no sign) by the distance driven.
TEST(ObstacleHold, TheGateGrowsAlongXWithTheDistanceDriven) {
  const std::vector<Fragment> nearer{fragment({14.45F, 8.F, 1.F}, {14.5F, 8.2F, 1.F}, 2)};  // 0.5 m short of it
  const std::vector<Fragment> beside{fragment({16.F, 9.45F, 1.F}, {16.1F, 9.5F, 1.F}, 2)};  // 0.45 m off in y
  for (const std::optional<double> speed : {std::optional<double>{}, std::optional<double>{3.0}}) {
    ObstacleHold hold(params());
    FrameResult f0 = frame({kCrown});
    (void)hold.apply(0, f0);
    FrameResult f1 = frame({}, nearer);
    EXPECT_EQ(hold.apply(2 * kPeriod, f1, speed), speed ? 1U : 0U) << (speed ? "3 m/s" : "speed unknown");
    FrameResult f2 = frame({}, beside);
    EXPECT_EQ(hold.apply(3 * kPeriod, f2, speed), 0U) << "y does not grow";
  }
  // Unusable speeds count as unknown.
  for (const double bad : {-3.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    ObstacleHold hold(params());
    FrameResult f0 = frame({kCrown});
    (void)hold.apply(0, f0);
    FrameResult f1 = frame({}, nearer);
    EXPECT_EQ(hold.apply(2 * kPeriod, f1, bad), 0U) << bad;
  }
}

// At speed the filters' report of the same obstacle has moved by the distance driven: it is still the obstacle
// reported again (no fragment beside it is held), when the speed is given.
TEST(ObstacleHold, AtSpeedTheMovedReportIsTheSameObstacle) {
  const Obstacle person = box({10.F, 0.F, -0.9F}, {10.5F, 0.5F, 0.8F});
  Obstacle moved = person;
  moved.min[0] -= 0.3F;  // 3 m/s, one rotation at 10 Hz
  moved.max[0] -= 0.3F;
  const std::vector<Fragment> arm{fragment({10.25F, 0.55F, 0.3F}, {10.4F, 0.7F, 0.4F}, 2)};
  for (const std::optional<double> speed : {std::optional<double>{}, std::optional<double>{3.0}}) {
    ObstacleHold hold(params());
    FrameResult f0 = frame({person});
    (void)hold.apply(0, f0);
    FrameResult f1 = frame({moved}, arm);
    EXPECT_EQ(hold.apply(kPeriod, f1, speed), speed ? 0U : 1U) << (speed ? "3 m/s" : "speed unknown");
  }
}

constexpr double kDeg = 3.14159265358979323846 / 180.0;

std::array<float, 3> centre(const std::array<float, 3>& min, const std::array<float, 3>& max) {
  return {0.5F * (min[0] + max[0]), 0.5F * (min[1] + max[1]), 0.5F * (min[2] + max[2])};
}

// move_box against what a driver sees: a post straight ahead comes nearer by the distance driven; turning left
// by an angle swings it to the right by that angle; climbing lowers it; a box turned by 90 degrees swaps its
// extents. Plane coordinates of a Gauss-Krueger zone (millions of metres) lose nothing that matters.
TEST(ObstacleHold, MoveBoxTakesTheCornersThroughThePlane) {
  const std::array<float, 3> post_min{20.F, -0.05F, -1.F}, post_max{20.F, 0.05F, 1.F};
  std::array<float, 3> mn{}, mx{};
  for (const double yaw : {0.0, 30.0, -135.0}) {
    const FramePose from{3'512'345.25, 5'401'234.75, 312.5, yaw * kDeg, 33};
    // 1.5 m along the heading, 0.4 m up.
    FramePose ahead = from;
    ahead.x_m += 1.5 * std::cos(from.yaw_rad);
    ahead.y_m += 1.5 * std::sin(from.yaw_rad);
    ahead.z_m += 0.4;
    move_box(post_min, post_max, from, ahead, mn, mx);
    EXPECT_NEAR(mn[0], 18.5F, 1e-4) << yaw;
    EXPECT_NEAR(mx[0], 18.5F, 1e-4) << yaw;
    EXPECT_NEAR(mn[1], -0.05F, 1e-4) << yaw;
    EXPECT_NEAR(mx[1], 0.05F, 1e-4) << yaw;
    EXPECT_NEAR(mn[2], -1.4F, 1e-4) << yaw;
    EXPECT_NEAR(mx[2], 0.6F, 1e-4) << yaw;
    // Turned 10 degrees left where it stands.
    FramePose left = from;
    left.yaw_rad += 10.0 * kDeg;
    move_box(post_min, post_max, from, left, mn, mx);
    const auto c = centre(mn, mx);
    EXPECT_NEAR(c[0], 20.0 * std::cos(10.0 * kDeg), 1e-4) << yaw;
    EXPECT_NEAR(c[1], -20.0 * std::sin(10.0 * kDeg), 1e-4) << yaw;
    EXPECT_NEAR(c[2], 0.F, 1e-6) << yaw;
    // Not moved at all: the same box.
    move_box(post_min, post_max, from, from, mn, mx);
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_NEAR(mn[i], post_min[i], 1e-5) << yaw;
      EXPECT_NEAR(mx[i], post_max[i], 1e-5) << yaw;
    }
  }
  // A 2 m by 0.5 m box seen after a quarter turn left: 0.5 by 2, on the right.
  const FramePose a{100.0, 200.0, 0.0, 0.0, 1};
  const FramePose b{100.0, 200.0, 0.0, 90.0 * kDeg, 1};
  move_box({10.F, 0.F, 0.F}, {12.F, 0.5F, 1.F}, a, b, mn, mx);
  EXPECT_NEAR(mn[0], 0.F, 1e-5);
  EXPECT_NEAR(mx[0], 0.5F, 1e-5);
  EXPECT_NEAR(mn[1], -12.F, 1e-5);
  EXPECT_NEAR(mx[1], -10.F, 1e-5);
}

// Poses of two frames 0.2 s apart in which the tractor drove 1 m and turned 10 degrees left (a headland turn):
// the crown 15-17 m out swings 2.7 m to the right, far out of the gate.
const FramePose kPose0{4'512'000.0, 5'430'000.0, 98.0, 30.0 * kDeg, 4};
FramePose turned() {
  FramePose p = kPose0;
  p.x_m += std::cos(kPose0.yaw_rad);
  p.y_m += std::sin(kPose0.yaw_rad);
  p.yaw_rad += 10.0 * kDeg;
  return p;
}

// Fragments of the box [min, max] (two returns at two corners, 0.1 m inside).
std::vector<Fragment> fragments_in(const std::array<float, 3>& min, const std::array<float, 3>& max) {
  return {fragment({min[0] + 0.1F, min[1] + 0.1F, min[2] + 0.5F}, {min[0] + 0.1F, min[1] + 0.1F, min[2] + 0.5F}, 1),
          fragment({max[0] - 0.1F, max[1] - 0.1F, max[2] - 0.5F}, {max[0] - 0.1F, max[1] - 0.1F, max[2] - 0.5F}, 1)};
}

// With the frames' poses, what the hold remembers is moved into this frame: the crown's fragments where it now
// stands are held, those where it stood are not. Without poses, the other way round.
TEST(ObstacleHold, FollowsWhatItRemembersThroughTheFramePoses) {
  std::array<float, 3> mn{}, mx{};
  move_box(kCrown.min, kCrown.max, kPose0, turned(), mn, mx);
  ASSERT_GT(std::hypot(centre(mn, mx)[0] - 16.F, centre(mn, mx)[1] - 8.F), 2.F) << "moved out of the gate";
  for (const bool poses : {true, false}) {
    const std::optional<FramePose> p0 = poses ? std::optional<FramePose>(kPose0) : std::nullopt;
    const std::optional<FramePose> p1 = poses ? std::optional<FramePose>(turned()) : std::nullopt;
    ObstacleHold hold(params());
    FrameResult f0 = frame({kCrown});
    (void)hold.apply(0, f0, std::nullopt, p0);
    FrameResult now = frame({}, fragments_in(mn, mx));
    EXPECT_EQ(hold.apply(2 * kPeriod, now, std::nullopt, p1), poses ? 1U : 0U)
        << "where it stands now, poses " << poses;
    ObstacleHold hold2(params());
    FrameResult g0 = frame({kCrown});
    (void)hold2.apply(0, g0, std::nullopt, p0);
    FrameResult then = frame({}, fragments_in(kCrown.min, kCrown.max));
    EXPECT_EQ(hold2.apply(2 * kPeriod, then, std::nullopt, p1), poses ? 0U : 1U) << "where it stood, poses " << poses;
  }
}

// The filters' report of the same obstacle after the turn is the obstacle reported again: no fragment beside it
// is held as a second one, though its old box is far from the new.
TEST(ObstacleHold, ThroughThePosesTheMovedReportIsTheSameObstacle) {
  Obstacle moved = kCrown;
  move_box(kCrown.min, kCrown.max, kPose0, turned(), moved.min, moved.max);
  // Shrunk back to the crown's size around the moved box's centre (the moved box of a box is larger).
  const auto c = centre(moved.min, moved.max);
  moved.min = {c[0] - 1.F, c[1] - 1.F, kCrown.min[2]};
  moved.max = {c[0] + 1.F, c[1] + 1.F, kCrown.max[2]};
  const std::vector<Fragment> beside{fragment({moved.max[0] + 0.1F, c[1], 1.F}, {moved.max[0] + 0.15F, c[1], 1.1F}, 2)};
  for (const bool poses : {true, false}) {
    ObstacleHold hold(params());
    FrameResult f0 = frame({kCrown});
    (void)hold.apply(0, f0, std::nullopt, poses ? std::optional<FramePose>(kPose0) : std::nullopt);
    // Remembered anew from this report; the old box (out of place without poses) is what holds the fragment.
    FrameResult f1 = frame({moved}, beside);
    f1.fragments.push_back(fragment({kCrown.max[0] + 0.1F, 8.F, 1.F}, {kCrown.max[0] + 0.15F, 8.F, 1.1F}, 2));
    EXPECT_EQ(hold.apply(kPeriod, f1, std::nullopt, poses ? std::optional<FramePose>(turned()) : std::nullopt),
              poses ? 0U : 1U)
        << "poses " << poses;
  }
}

// A pose is used only when both frames have one, of the same plane, finite: otherwise the box stays where it was
// reported (and the speed, when given, widens the gate).
TEST(ObstacleHold, PosesOfAnotherPlaneOrNotFiniteOrMissingAreNotUsed) {
  FramePose other = turned();
  other.plane = 5;
  FramePose nan = turned();
  nan.yaw_rad = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    const char* what;
    std::optional<FramePose> p0, p1;
  };
  const Case cases[] = {{"another plane", kPose0, other},
                        {"not finite now", kPose0, nan},
                        {"none then", std::nullopt, turned()},
                        {"none now", kPose0, std::nullopt}};
  for (const Case& k : cases) {
    ObstacleHold hold(params());
    FrameResult f0 = frame({kCrown});
    (void)hold.apply(0, f0, std::nullopt, k.p0);
    FrameResult then = frame({}, fragments_in(kCrown.min, kCrown.max));
    EXPECT_EQ(hold.apply(2 * kPeriod, then, std::nullopt, k.p1), 1U) << k.what;
  }
  // A remembered pose with a non-finite one: not remembered as a pose.
  ObstacleHold hold(params());
  FrameResult f0 = frame({kCrown});
  (void)hold.apply(0, f0, std::nullopt, nan);
  FrameResult then = frame({}, fragments_in(kCrown.min, kCrown.max));
  EXPECT_EQ(hold.apply(2 * kPeriod, then, std::nullopt, turned()), 1U) << "not finite then";
}

// A stamp before the last frame's (another capture, a clock step): everything remembered is forgotten.
TEST(ObstacleHold, TimeGoingBackForgets) {
  ObstacleHold hold(params());
  FrameResult first = frame({kCrown});
  (void)hold.apply(10 * kPeriod, first);
  EXPECT_EQ(hold.remembered(), 1U);
  FrameResult back = frame({}, {fragment({16.F, 8.F, 1.F}, {16.2F, 8.F, 1.F}, 2)});
  EXPECT_EQ(hold.apply(9 * kPeriod, back), 0U);
  EXPECT_EQ(hold.remembered(), 0U);
}

TEST(ObstacleHold, DisabledDoesNothing) {
  HoldParams p = params();
  p.enabled = false;
  ObstacleHold hold(p);
  FrameResult first = frame({kCrown});
  (void)hold.apply(0, first);
  FrameResult next = frame({}, {fragment({16.F, 8.F, 1.F}, {16.2F, 8.F, 1.F}, 2)});
  EXPECT_EQ(hold.apply(kPeriod, next), 0U);
  EXPECT_TRUE(next.obstacles.empty());
  EXPECT_EQ(hold.remembered(), 0U);
}

TEST(ObstacleHold, RefusesBadParameters) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double bad : {-0.1, nan, inf}) {
    HoldParams p = params();
    p.max_age_s = bad;
    EXPECT_THROW(ObstacleHold{p}, std::invalid_argument) << bad;
    p = params();
    p.gate_m = bad;
    EXPECT_THROW(ObstacleHold{p}, std::invalid_argument) << bad;
  }
  HoldParams p = params();
  p.min_points = 0;
  EXPECT_THROW(ObstacleHold{p}, std::invalid_argument);
  p.min_points = 1;
  EXPECT_NO_THROW(ObstacleHold{p});
}

}  // namespace
}  // namespace fieldguard::perception
