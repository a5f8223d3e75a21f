#include "fieldguard/perception/voxel_grid.hpp"

#include <gtest/gtest.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

using P3 = std::array<float, 3>;

std::vector<P3> points_of(const Cloud& c) {
  std::vector<P3> v;
  for (std::size_t i = 0; i < c.size(); ++i) v.push_back({c.x[i], c.y[i], c.z[i]});
  return v;
}

std::vector<P3> sorted(std::vector<P3> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// Leaf 0.5 and coordinates that are sums of powers of two: every centroid is exact in float.
TEST(VoxelGrid, CentroidsAreExact) {
  Cloud in;
  in.push_back(0.125F, 0.25F, 0.0F);      // voxel (0,0,0)
  in.push_back(-0.25F, 0.25F, 0.25F);     // voxel (-1,0,0): floor, not truncation
  in.push_back(0.375F, 0.0F, 0.25F);      // voxel (0,0,0)
  in.push_back(0.5F, 0.25F, 0.0F);        // voxel (1,0,0): a point on a boundary belongs to the upper voxel
  in.push_back(0.25F, 0.125F, 0.125F);    // voxel (0,0,0)
  in.push_back(-0.125F, 0.375F, 0.125F);  // voxel (-1,0,0)
  VoxelGrid grid(VoxelParams{0.5, 0.0, 0.45});
  Cloud out;
  grid.filter(in, out);
  ASSERT_EQ(out.size(), 3U);
  EXPECT_EQ(sorted(points_of(out)),
            sorted({{0.25F, 0.125F, 0.125F}, {-0.1875F, 0.3125F, 0.1875F}, {0.5F, 0.25F, 0.0F}}));
  EXPECT_TRUE(out.ring.empty());
}

// The ring cache changes the order of the sums (and of the output), not the voxels or their centroids.
TEST(VoxelGrid, RingCacheDoesNotChangeTheVoxels) {
  testing::TestRng rng{5};
  Cloud with_rings, without;
  for (int i = 0; i < 20000; ++i) {
    const float x = rng.uniform(-10, 50), y = rng.uniform(-10, 10), z = rng.uniform(-1.5F, 3);
    with_rings.push_back(x, y, z, static_cast<std::uint16_t>(rng.next() % 200));  // rings beyond the cache too
    without.push_back(x, y, z);
  }
  VoxelGrid a(VoxelParams{}), b(VoxelParams{});
  Cloud oa, ob;
  a.filter(with_rings, oa);
  b.filter(without, ob);
  ASSERT_EQ(oa.size(), ob.size());
  const auto pa = sorted(points_of(oa)), pb = sorted(points_of(ob));
  for (std::size_t i = 0; i < pa.size(); ++i) {
    for (std::size_t k = 0; k < 3; ++k) ASSERT_NEAR(pa[i][k], pb[i][k], 1e-5F) << i;
  }
}

TEST(VoxelGrid, CoarserLeafWithRange) {
  // Leaf 0.1 m; from 10 m (band 1) the leaf is 0.1 * floor(r / 10): 0.2 m at 20-30 m, capped at 0.3 m.
  VoxelGrid grid(VoxelParams{0.1, 10.0, 0.3});
  Cloud in, out;
  in.push_back(5.01F, 0.01F, 0.01F);   // band 1: leaf 0.1
  in.push_back(5.09F, 0.01F, 0.01F);   // same 0.1 voxel
  in.push_back(5.11F, 0.01F, 0.01F);   // next 0.1 voxel
  in.push_back(25.01F, 0.01F, 0.01F);  // band 2: leaf 0.2 ...
  in.push_back(25.19F, 0.01F, 0.01F);  // ... one voxel
  in.push_back(45.01F, 0.01F, 0.01F);  // band 4: leaf 0.4 capped at 0.3 ...
  in.push_back(45.29F, 0.01F, 0.01F);  // ... one voxel [45.0, 45.3)
  in.push_back(45.31F, 0.01F, 0.01F);  // the next
  grid.filter(in, out);
  ASSERT_EQ(out.size(), 5U);
  std::vector<float> xs(out.x.begin(), out.x.end());
  std::sort(xs.begin(), xs.end());
  EXPECT_NEAR(xs[0], 5.05F, 1e-5F);
  EXPECT_NEAR(xs[1], 5.11F, 1e-5F);
  EXPECT_NEAR(xs[2], 25.10F, 1e-5F);
  EXPECT_NEAR(xs[3], 45.15F, 1e-5F);
  EXPECT_NEAR(xs[4], 45.31F, 1e-5F);
  // Without coarsening every one of those is its own voxel, but for the first pair.
  VoxelGrid fine(VoxelParams{0.1, 0.0, 0.3});
  fine.filter(in, out);
  EXPECT_EQ(out.size(), 7U);
}

TEST(VoxelGrid, EmptyInputAndReuseAcrossFrames) {
  VoxelGrid grid(VoxelParams{});
  Cloud in, out;
  grid.filter(in, out);
  EXPECT_TRUE(out.empty());
  in.push_back(1.0F, 1.0F, 1.0F);
  in.push_back(1.01F, 1.01F, 1.01F);
  grid.filter(in, out);
  ASSERT_EQ(out.size(), 1U);
  Cloud second;
  second.push_back(1.0F, 1.0F, 1.0F);
  second.push_back(3.0F, 1.0F, 1.0F);
  grid.filter(second, out);  // nothing of the first frame is left
  ASSERT_EQ(out.size(), 2U);
  EXPECT_FLOAT_EQ(std::min(out.x[0], out.x[1]), 1.0F);
  EXPECT_FLOAT_EQ(std::max(out.x[0], out.x[1]), 3.0F);
}

// A fresh grid's table grows while the first frame's runs meet it, in the middle of a batch of queued runs:
// the runs after the growth must look their voxels up in the grown table, or a voxel seen again later is
// taken for a new one. Every voxel is visited twice, far apart; coordinates exact in float (leaf 0.5).
TEST(VoxelGrid, TableGrowthInTheMiddleOfABatchKeepsEveryVoxelOnce) {
  constexpr int kVoxels = 5000;
  Cloud in;
  for (int pass = 0; pass < 2; ++pass) {
    for (int i = 0; i < kVoxels; ++i) {
      in.push_back(static_cast<float>(i) * 0.5F + (pass == 0 ? 0.125F : 0.375F), 0.125F, 0.25F);
    }
  }
  VoxelGrid grid(VoxelParams{0.5, 0.0, 0.5});
  Cloud out;
  for (int frame = 0; frame < 2; ++frame) {  // and again with the grown table
    grid.filter(in, out);
    ASSERT_EQ(out.size(), static_cast<std::size_t>(kVoxels));
    std::vector<float> xs(out.x.begin(), out.x.end());
    std::sort(xs.begin(), xs.end());
    for (int i = 0; i < kVoxels; ++i) {
      ASSERT_EQ(xs[static_cast<std::size_t>(i)], static_cast<float>(i) * 0.5F + 0.25F) << i;
      ASSERT_EQ(out.y[static_cast<std::size_t>(i)], 0.125F);
      ASSERT_EQ(out.z[static_cast<std::size_t>(i)], 0.25F);
    }
  }
}

// The same voxels as the stock pcl::VoxelGrid, with the same centroids up to the order of the float sums
// (PCL adds a voxel's points in index order, ours per ring run): rings cycling as an HDL-32E's firings do,
// rings beyond the cache, and no rings. Centroids are paired by the voxel they fall in.
TEST(VoxelGrid, MatchesPclVoxelGrid) {
  testing::TestRng rng{11};
  Cloud in;
  for (int i = 0; i < 30000; ++i) {
    const float a = rng.uniform(-3.1F, 3.1F), r = rng.uniform(1.F, 40.F);
    in.push_back(r * std::cos(a), r * std::sin(a), rng.uniform(-1.5F, 3.F), static_cast<std::uint16_t>(i % 32));
  }
  for (int variant = 0; variant < 3; ++variant) {
    Cloud c = in;
    if (variant == 1) {
      for (auto& ring : c.ring) ring = static_cast<std::uint16_t>(rng.next() % 300);
    }
    if (variant == 2) c.ring.clear();
    VoxelGrid grid(VoxelParams{0.15, 0.0, 0.45});
    Cloud out;
    grid.filter(c, out);
    pcl::PointCloud<pcl::PointXYZ>::Ptr pin(new pcl::PointCloud<pcl::PointXYZ>);
    for (std::size_t i = 0; i < c.size(); ++i) pin->push_back(pcl::PointXYZ(c.x[i], c.y[i], c.z[i]));
    pcl::PointCloud<pcl::PointXYZ> pout;
    pcl::VoxelGrid<pcl::PointXYZ> pcl_grid;
    pcl_grid.setInputCloud(pin);
    pcl_grid.setLeafSize(0.15F, 0.15F, 0.15F);
    pcl_grid.filter(pout);
    ASSERT_EQ(out.size(), pout.size()) << variant;
    const float inv = 1.0F / 0.15F;
    using Key = std::tuple<int, int, int>;
    const auto key = [inv](float x, float y, float z) {
      return Key{static_cast<int>(std::floor(x * inv)), static_cast<int>(std::floor(y * inv)),
                 static_cast<int>(std::floor(z * inv))};
    };
    std::map<Key, P3> ours;
    for (std::size_t i = 0; i < out.size(); ++i) {
      ours[key(out.x[i], out.y[i], out.z[i])] = {out.x[i], out.y[i], out.z[i]};
    }
    ASSERT_EQ(ours.size(), out.size()) << variant;  // one centroid per voxel
    for (const auto& p : pout) {
      const auto it = ours.find(key(p.x, p.y, p.z));
      ASSERT_NE(it, ours.end()) << variant;
      EXPECT_NEAR(it->second[0], p.x, 1e-4F);
      EXPECT_NEAR(it->second[1], p.y, 1e-4F);
      EXPECT_NEAR(it->second[2], p.z, 1e-4F);
    }
  }
}

TEST(VoxelGrid, RefusesAnImpossibleLeaf) {
  EXPECT_THROW(VoxelGrid(VoxelParams{0.0, 0.0, 0.45}), std::invalid_argument);
  EXPECT_THROW(VoxelGrid(VoxelParams{0.2, 10.0, 0.1}), std::invalid_argument);
}

}  // namespace
}  // namespace fieldguard::perception
