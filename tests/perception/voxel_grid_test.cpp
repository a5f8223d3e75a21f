#include "fieldguard/perception/voxel_grid.hpp"

#include <gtest/gtest.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
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

// The coarse keys (one per point, not four at a time) through the ring sort, across chunks and a block's tail:
// with rings the same voxels and centroids (up to the order of the float sums) as without.
TEST(VoxelGrid, CoarserLeafWithRingsAcrossChunks) {
  testing::TestRng rng{37};
  Cloud with_rings, without;
  for (int i = 0; i < 3001; ++i) {
    const float a = rng.uniform(-3.F, 3.F), r = rng.uniform(2.F, 45.F);
    const float x = r * std::cos(a), y = r * std::sin(a), z = rng.uniform(-1.F, 2.F);
    with_rings.push_back(x, y, z, static_cast<std::uint16_t>(i % 32));
    without.push_back(x, y, z);
  }
  VoxelGrid a(VoxelParams{0.1, 10.0, 0.3}), b(VoxelParams{0.1, 10.0, 0.3});
  Cloud oa, ob;
  a.filter(with_rings, oa);
  b.filter(without, ob);
  // The voxels, written plainly: band max(1, floor(r / 10)) up to 3, leaf min(0.1 * band, 0.3).
  using Key = std::tuple<int, int, int, int>;
  const auto voxel = [](float x, float y, float z) {
    const float r = std::sqrt(x * x + y * y) * static_cast<float>(1.0 / 10.0);
    const int band = r >= 3.F ? 3 : std::max(1, static_cast<int>(r));
    const float inv = 1.0F / static_cast<float>(std::min(0.1 * band, 0.3));
    return Key{band, static_cast<int>(std::floor(x * inv)), static_cast<int>(std::floor(y * inv)),
               static_cast<int>(std::floor(z * inv))};
  };
  std::map<Key, int> want;
  for (std::size_t i = 0; i < without.size(); ++i) ++want[voxel(without.x[i], without.y[i], without.z[i])];
  ASSERT_EQ(oa.size(), want.size());
  ASSERT_EQ(ob.size(), want.size());
  ASSERT_LT(want.size(), with_rings.size());  // some points share a voxel
  const auto pa = sorted(points_of(oa)), pb = sorted(points_of(ob));
  for (std::size_t i = 0; i < pa.size(); ++i) {
    for (std::size_t k = 0; k < 3; ++k) ASSERT_NEAR(pa[i][k], pb[i][k], 1e-4F) << i;
  }
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

// The exact contract that byte-identical replays rest on, written plainly: each ring (ring & 127; ring 0 for
// a cloud without rings) sums its consecutive points in one voxel into a run, from +0 and in point order; a run
// ends when its ring moves to another voxel, and at the end the open runs end in ring order; the runs reach
// their voxels in the order they ended, a voxel's first run giving it its place in the output; a centroid is
// each sum divided by the count in float.
std::vector<P3> reference_centroids(const Cloud& c, float leaf) {
  using Key = std::tuple<int, int, int>;
  struct Run {
    Key key;
    P3 sum;
    std::uint32_t n = 0;
  };
  const float inv = 1.0F / leaf;
  const auto voxel = [inv](float v) { return static_cast<int>(std::floor(v * inv)); };
  std::vector<Run> open(128);
  std::map<Key, std::size_t> ids;
  std::vector<P3> sums;
  std::vector<std::uint32_t> counts;
  const auto end_run = [&](const Run& r) {
    const auto [it, fresh] = ids.try_emplace(r.key, sums.size());
    if (fresh) {
      sums.push_back(r.sum);
      counts.push_back(r.n);
      return;
    }
    for (std::size_t k = 0; k < 3; ++k) sums[it->second][k] += r.sum[k];
    counts[it->second] += r.n;
  };
  const bool rings = c.ring.size() == c.size();
  for (std::size_t i = 0; i < c.size(); ++i) {
    const P3 p{c.x[i], c.y[i], c.z[i]};
    const Key key{voxel(p[0]), voxel(p[1]), voxel(p[2])};
    Run& r = open[rings ? c.ring[i] & 127U : 0U];
    if (r.n > 0 && r.key == key) {
      for (std::size_t k = 0; k < 3; ++k) r.sum[k] += p[k];
      ++r.n;
      continue;
    }
    if (r.n > 0) end_run(r);
    r = Run{key, {0.0F + p[0], 0.0F + p[1], 0.0F + p[2]}, 1};
  }
  for (const Run& r : open) {
    if (r.n > 0) end_run(r);
  }
  std::vector<P3> out;
  for (std::size_t v = 0; v < sums.size(); ++v) {
    const auto n = static_cast<float>(counts[v]);
    out.push_back({sums[v][0] / n, sums[v][1] / n, sums[v][2] / n});
  }
  return out;
}

// Bit for bit and in order, as the reference above: an HDL-32E-like rotation (columns of 32 rings, a quarter
// of the returns missing as after a crop, surfaces that keep a ring in one voxel for a few points), also
// with rings beyond the cache and without rings, two frames on one grid (the table grows in the first).
TEST(VoxelGrid, SameBitsAndOrderAsThePlainRunContract) {
  testing::TestRng rng{23};
  Cloud in;
  for (int col = 0; col < 2500; ++col) {
    const float az = static_cast<float>(col) * 0.0035F;
    for (int ring = 0; ring < 32; ++ring) {
      if (rng.uniform(0.F, 1.F) < 0.25F) continue;
      const float fr = static_cast<float>(ring);
      const float r = 4.F + 12.F * std::fabs(std::sin(0.3F * fr + 0.5F * az)) + rng.uniform(0.F, 0.02F);
      in.push_back(r * std::cos(az), r * std::sin(az), -1.6F + 0.09F * fr + rng.uniform(-0.01F, 0.01F),
                   static_cast<std::uint16_t>(ring));
    }
  }
  for (int variant = 0; variant < 3; ++variant) {
    Cloud c = in;
    if (variant == 1) {
      for (auto& ring : c.ring) ring = static_cast<std::uint16_t>(ring * 7U + 100U);  // 100..317: shared slots
    }
    if (variant == 2) c.ring.clear();
    const std::vector<P3> want = reference_centroids(c, 0.15F);
    VoxelGrid grid(VoxelParams{0.15, 0.0, 0.45});
    for (int frame = 0; frame < 2; ++frame) {
      Cloud out;
      grid.filter(c, out);
      ASSERT_EQ(out.size(), want.size()) << variant;
      for (std::size_t v = 0; v < want.size(); ++v) {
        ASSERT_EQ(std::bit_cast<std::uint32_t>(out.x[v]), std::bit_cast<std::uint32_t>(want[v][0])) << v;
        ASSERT_EQ(std::bit_cast<std::uint32_t>(out.y[v]), std::bit_cast<std::uint32_t>(want[v][1])) << v;
        ASSERT_EQ(std::bit_cast<std::uint32_t>(out.z[v]), std::bit_cast<std::uint32_t>(want[v][2])) << v;
      }
    }
  }
}

// The grid sorts a chunk of points (1024) by ring at a time and sums each ring's runs without a branch: bit
// for bit and in order as the plain contract, whatever the rings' shares, numbers and reach across chunks.
// Frames that end in every place around a chunk and a 16-point block; one ring carrying nine tenths of the
// points; one ring staying in one voxel across chunks; rings that appear only in a later chunk, rings that
// share a slot (0, 128 and 256; 127 and 65535), a single ring, and no rings.
TEST(VoxelGrid, ChunkedRingSortKeepsThePlainRunContract) {
  testing::TestRng rng{31};
  const auto shape = [&](std::size_t n, int kind) {
    Cloud c;
    for (std::size_t i = 0; i < n; ++i) {
      const float a = static_cast<float>(i) * 0.002F;
      std::uint16_t ring = static_cast<std::uint16_t>(rng.next() % 32);
      float r = 3.F + 10.F * std::fabs(std::sin(0.7F * static_cast<float>(ring) + a)) + rng.uniform(0.F, 0.05F);
      if (kind == 1) ring = rng.uniform(0.F, 1.F) < 0.9F ? std::uint16_t{0} : ring;
      if (kind == 2 && ring == 7) r = 5.01F;  // ring 7: one voxel from the first point to the last
      if (kind == 3) ring = i < n / 2 ? static_cast<std::uint16_t>(ring % 4) : ring;  // rings 4-31 start late
      if (kind == 4) ring = std::array<std::uint16_t, 5>{0, 128, 256, 127, 65535}[ring % 5];
      if (kind == 5) ring = 9;
      const float z = kind == 2 && ring == 7 ? 0.01F : -1.F + 0.1F * static_cast<float>(ring % 32);
      c.push_back(r * std::cos(a), r * std::sin(a), z + rng.uniform(-0.02F, 0.02F), ring);
    }
    if (kind == 6) c.ring.clear();
    return c;
  };
  VoxelGrid grid(VoxelParams{0.15, 0.0, 0.45});
  for (int kind = 0; kind < 7; ++kind) {
    for (const std::size_t n : {std::size_t{1}, std::size_t{17}, std::size_t{1023}, std::size_t{1024},
                                std::size_t{1025}, std::size_t{2049}, std::size_t{5000}}) {
      const Cloud c = shape(n, kind);
      const std::vector<P3> want = reference_centroids(c, 0.15F);
      Cloud out;
      grid.filter(c, out);
      ASSERT_EQ(out.size(), want.size()) << kind << " " << n;
      for (std::size_t v = 0; v < want.size(); ++v) {
        ASSERT_EQ(std::bit_cast<std::uint32_t>(out.x[v]), std::bit_cast<std::uint32_t>(want[v][0])) << kind << " " << n;
        ASSERT_EQ(std::bit_cast<std::uint32_t>(out.y[v]), std::bit_cast<std::uint32_t>(want[v][1])) << kind << " " << n;
        ASSERT_EQ(std::bit_cast<std::uint32_t>(out.z[v]), std::bit_cast<std::uint32_t>(want[v][2])) << kind << " " << n;
      }
    }
  }
}

// Counts are summed in float lanes, exact below 2^24 points: a larger frame is taken in pieces, the counts
// moved to integers between them. Pieces of 16 to 2051 points here (tails of blocks and of the grid's
// 1024-point chunks, runs open across the cut, voxels met again in later pieces, a frame after): coordinates
// in eighths (leaf 0.5), whose sums are exact in any order, so the centroids must be the one-piece centroids
// exactly.
TEST(VoxelGrid, FramesTakenInPiecesKeepTheirCounts) {
  testing::TestRng rng{29};
  Cloud in;
  for (int i = 0; i < 20000; ++i) {
    const auto eighths = [&](std::uint32_t n) { return static_cast<float>(rng.next() % n) / 8.F - 4.F; };
    in.push_back(eighths(64), eighths(48), eighths(16), static_cast<std::uint16_t>(i % 32));
  }
  VoxelGrid whole(VoxelParams{0.5, 0.0, 0.5});
  Cloud want;
  whole.filter(in, want);
  ASSERT_GT(want.size(), 100U);
  for (const std::size_t piece : {std::size_t{777}, std::size_t{16}, std::size_t{1500}, std::size_t{2051}}) {
    VoxelGrid grid(VoxelParams{0.5, 0.0, 0.5}, piece);
    for (int frame = 0; frame < 2; ++frame) {
      Cloud out;
      grid.filter(in, out);
      EXPECT_EQ(sorted(points_of(out)), sorted(points_of(want))) << piece;
    }
  }
}

TEST(VoxelGrid, RefusesAnImpossibleLeaf) {
  EXPECT_THROW(VoxelGrid(VoxelParams{0.0, 0.0, 0.45}), std::invalid_argument);
  EXPECT_THROW(VoxelGrid(VoxelParams{0.2, 10.0, 0.1}), std::invalid_argument);
}

}  // namespace
}  // namespace fieldguard::perception
