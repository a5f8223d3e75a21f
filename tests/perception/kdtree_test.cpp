#include "fieldguard/perception/kdtree.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

std::vector<std::uint32_t> brute_force(const Cloud& c, float qx, float qy, float qz, float radius) {
  const auto r2 = static_cast<float>(static_cast<double>(radius) * static_cast<double>(radius));
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const float dx = c.x[i] - qx, dy = c.y[i] - qy, dz = c.z[i] - qz;
    if (dx * dx + dy * dy + dz * dz < r2) out.push_back(static_cast<std::uint32_t>(i));
  }
  return out;
}

TEST(KdTree, RadiusSearchFindsExactlyThePointsInside) {
  testing::TestRng rng{1};
  Cloud c;
  for (int i = 0; i < 4000; ++i) c.push_back(rng.uniform(0, 20), rng.uniform(0, 10), rng.uniform(0, 3));
  for (int i = 0; i < 50; ++i) c.push_back(5.F, 5.F, 1.F);  // duplicates: equal keys on both sides of a split
  KdTree tree;
  tree.build(c);
  ASSERT_EQ(tree.size(), c.size());
  std::vector<std::uint32_t> got;
  for (int q = 0; q < 300; ++q) {
    const float x = rng.uniform(-1, 21), y = rng.uniform(-1, 11), z = rng.uniform(-1, 4);
    const float r = rng.uniform(0.05F, 1.5F);
    tree.radius_search(x, y, z, r, got);
    ASSERT_EQ(got, brute_force(c, x, y, z, r)) << q;
  }
  tree.radius_search(5.F, 5.F, 1.F, 0.01F, got);
  EXPECT_GE(got.size(), 50U);
}

TEST(KdTree, EmptyAndAllEqual) {
  KdTree tree;
  tree.build(Cloud{});
  std::vector<std::uint32_t> got{1, 2};
  tree.radius_search(0, 0, 0, 1, got);
  EXPECT_TRUE(got.empty());
  Cloud same;
  for (int i = 0; i < 100; ++i) same.push_back(1, 2, 3);
  tree.build(same);
  tree.radius_search(1, 2, 3.5F, 0.6F, got);
  EXPECT_EQ(got.size(), 100U);
  tree.radius_search(1, 2, 3.7F, 0.6F, got);
  EXPECT_TRUE(got.empty());
}

}  // namespace
}  // namespace fieldguard::perception
