#include "fieldguard/perception/crop.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

using testing::lidar_point;

const Box3 kRoi{{-10.0, -10.0, -1.5}, {50.0, 10.0, 6.0}};
const Box3 kBody{{-5.0, -1.5, -1.5}, {0.4, 1.5, 1.5}};

TEST(CropBox, KeepsTheRoiFacesAndDropsTheBodyFaces) {
  const std::vector<LidarPoint> in = {
      lidar_point(50.0F, 0.0F, 0.0F, 1),     // on the ROI's far face: kept (closed box, as pcl::CropBox)
      lidar_point(-10.0F, 9.0F, 0.0F, 2),    // on the ROI's back face, outside the body: kept
      lidar_point(20.0F, 10.0F, 6.0F, 3),    // on an ROI edge: kept
      lidar_point(50.01F, 0.0F, 0.0F, 4),    // just beyond: dropped
      lidar_point(20.0F, -10.01F, 0.0F, 5),  // just beyond the side: dropped
      lidar_point(0.4F, 0.0F, 0.0F, 6),      // on the body's front face: removed
      lidar_point(-5.0F, 1.5F, 1.5F, 7),     // on a body corner: removed
      lidar_point(0.41F, 0.0F, 0.0F, 8),     // just in front of the body: kept
      lidar_point(-1.0F, 1.51F, 0.0F, 9),    // just beside the body: kept
      lidar_point(-1.0F, 0.0F, 1.51F, 10),   // just above the body: kept
  };
  Cloud out;
  crop_box(in, kRoi, kBody, out);
  ASSERT_EQ(out.size(), 6U);
  const std::vector<std::uint16_t> rings(out.ring.begin(), out.ring.end());
  EXPECT_EQ(rings, (std::vector<std::uint16_t>{1, 2, 3, 8, 9, 10}));  // input order, rings carried
  EXPECT_FLOAT_EQ(out.x[3], 0.41F);
  EXPECT_FLOAT_EQ(out.y[4], 1.51F);
  EXPECT_FLOAT_EQ(out.z[5], 1.51F);
}

TEST(CropBox, DropsNanAndInfinity) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<LidarPoint> in = {lidar_point(nan, 0, 0), lidar_point(5, nan, 0),  lidar_point(5, 0, nan),
                                      lidar_point(inf, 0, 0), lidar_point(5, -inf, 0), lidar_point(5, 0, inf),
                                      lidar_point(5, 1, 0.5F)};
  Cloud out;
  crop_box(in, kRoi, kBody, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_FLOAT_EQ(out.x[0], 5.0F);
  // An infinite ROI lets only finite points through too.
  const double dinf = std::numeric_limits<double>::infinity();
  const Box3 everything{{-dinf, -dinf, -dinf}, {dinf, dinf, dinf}};
  crop_box(in, everything, kBody, out);
  EXPECT_EQ(out.size(), 1U);
}

TEST(CropBox, EmptyInputAndEverythingInTheBody) {
  Cloud out;
  out.push_back(1, 2, 3, 4);  // stale content is replaced
  crop_box({}, kRoi, kBody, out);
  EXPECT_TRUE(out.empty());
  const std::vector<LidarPoint> body = {lidar_point(0, 0, 0), lidar_point(-4, 1, -1), lidar_point(0.3F, -1.4F, 1.4F)};
  crop_box(body, kRoi, kBody, out);
  EXPECT_TRUE(out.empty());
  EXPECT_TRUE(out.ring.empty());
}

// A merged frame: the 2D LiDAR's points go aside, all of them (inside the body box, outside the ROI, NaN), in
// order; the 3D points crop as in a frame without them.
TEST(CropBox, SetsTheScanOfAMergedFrameAside) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<LidarPoint> in, only3d;
  for (int i = 0; i < 40; ++i) {
    const float f = static_cast<float>(i);
    LidarPoint p = lidar_point(-8.F + 0.9F * f, -5.F + 0.3F * f, -1.F + 0.05F * f, static_cast<std::uint16_t>(i));
    if (i % 3 == 0) {
      p.source = static_cast<std::uint8_t>(PointSource::Lidar2d);
      if (i == 9) p.x = nan;
      if (i == 12) p.x = 100.F;  // beyond the ROI
      in.push_back(p);
    } else {
      in.push_back(p);
      only3d.push_back(p);
    }
  }
  in.push_back(lidar_point(0, 0, 0, 77));  // in the body box
  in.back().source = static_cast<std::uint8_t>(PointSource::Lidar2d);
  Cloud out, expected;
  std::vector<LidarPoint> scan = {lidar_point(1, 2, 3)};  // stale content is replaced
  crop_box(in, kRoi, kBody, out, scan);
  crop_box(only3d, kRoi, kBody, expected);
  EXPECT_EQ(std::vector<float>(out.x.begin(), out.x.end()), std::vector<float>(expected.x.begin(), expected.x.end()));
  EXPECT_EQ(std::vector<std::uint16_t>(out.ring.begin(), out.ring.end()),
            std::vector<std::uint16_t>(expected.ring.begin(), expected.ring.end()));
  ASSERT_EQ(scan.size(), 15U);
  for (std::size_t i = 0; i + 1 < scan.size(); ++i) EXPECT_EQ(scan[i].ring, 3 * i);
  EXPECT_EQ(scan.back().ring, 77U);
  // Without a 2D point the overload is the plain crop.
  crop_box(only3d, kRoi, kBody, out, scan);
  EXPECT_TRUE(scan.empty());
  EXPECT_EQ(out.size(), expected.size());
}

// The box tests run four points at a time; every point must get the answer of the plain per-point test, whatever
// its place in a group of four: random points on and around every face of both boxes, NaN and infinity in any
// coordinate, 2D LiDAR points among them, counts that leave a remainder, a finite and an unbounded ROI.
TEST(CropBox, FourAtATimeMatchesThePointByPointTest) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const double dinf = std::numeric_limits<double>::infinity();
  const Box3 half_open{{-10.0, -dinf, -1.5}, {50.0, 10.0, dinf}};
  std::mt19937 rng(7);
  // Coordinates drawn from the faces of both boxes, just beside them, the middle, and the non-finite.
  const std::vector<float> xs = {-10.F, -10.01F, 50.F, 50.01F, -5.F, 0.4F, 0.41F, -1.F, 20.F, nan, inf, -inf};
  const std::vector<float> ys = {-10.F, -10.01F, 10.F, 10.01F, -1.5F, 1.5F, 1.51F, 0.F, 5.F, nan, inf, -inf};
  const std::vector<float> zs = {-1.5F, -1.51F, 6.F, 6.01F, 1.5F, 1.51F, 0.F, 3.F, nan, inf, -inf};
  const auto pick = [&](const std::vector<float>& v) { return v[rng() % v.size()]; };
  const auto inside = [](const Box3& b, const LidarPoint& p) {
    const std::array<float, 3> c = {p.x, p.y, p.z};
    for (std::size_t a = 0; a < 3; ++a) {
      if (!(c[a] >= static_cast<float>(b.min[a]) && c[a] <= static_cast<float>(b.max[a]))) return false;
    }
    return true;
  };
  for (const Box3& roi : {kRoi, half_open}) {
    for (std::size_t n : {0U, 1U, 3U, 4U, 5U, 7U, 64U, 1001U}) {
      std::vector<LidarPoint> in;
      for (std::size_t i = 0; i < n; ++i) {
        in.push_back(lidar_point(pick(xs), pick(ys), pick(zs), static_cast<std::uint16_t>(i)));
        if (rng() % 9 == 0) in.back().source = static_cast<std::uint8_t>(PointSource::Lidar2d);
      }
      std::vector<std::uint16_t> want, want2d;
      for (const LidarPoint& p : in) {
        if (p.source == static_cast<std::uint8_t>(PointSource::Lidar2d)) {
          want2d.push_back(p.ring);
        } else if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && inside(roi, p) &&
                   !inside(kBody, p)) {
          want.push_back(p.ring);
        }
      }
      Cloud out;
      std::vector<LidarPoint> scan;
      crop_box(in, roi, kBody, out, scan);
      EXPECT_EQ(std::vector<std::uint16_t>(out.ring.begin(), out.ring.end()), want) << n << " points";
      std::vector<std::uint16_t> got2d;
      for (const LidarPoint& p : scan) got2d.push_back(p.ring);
      EXPECT_EQ(got2d, want2d) << n << " points";
      for (std::size_t k = 0; k < out.size(); ++k) {
        const LidarPoint& p = in[out.ring[k]];
        EXPECT_EQ(out.x[k], p.x);
        EXPECT_EQ(out.y[k], p.y);
        EXPECT_EQ(out.z[k], p.z);
      }
      // Without the 2D split: the 2D points are cropped as any other.
      std::vector<std::uint16_t> want_all;
      for (const LidarPoint& p : in) {
        if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && inside(roi, p) && !inside(kBody, p)) {
          want_all.push_back(p.ring);
        }
      }
      crop_box(in, roi, kBody, out);
      EXPECT_EQ(std::vector<std::uint16_t>(out.ring.begin(), out.ring.end()), want_all) << n << " points";
    }
  }
}

// The counting overload: the same crop, and the count a second pass `x <= limit` over the kept points gives, on
// every path (fours kept whole, fast and full test, fours kept in part, eights holding a 2D point, the last
// points), for a limit on a point's x, between points, NaN and infinite.
TEST(CropBox, CountsTheKeptPointsUpToALimit) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const double dinf = std::numeric_limits<double>::infinity();
  const Box3 half_open{{-10.0, -dinf, -1.5}, {50.0, 10.0, dinf}};
  std::mt19937 rng(11);
  const auto second_pass = [](const Cloud& c, float limit) {
    std::uint32_t n = 0;
    for (const float x : c.x) n += x <= limit ? 1U : 0U;
    return n;
  };
  for (const Box3& roi : {kRoi, half_open}) {
    for (std::size_t n : {0U, 1U, 4U, 7U, 8U, 13U, 1003U}) {
      std::vector<LidarPoint> in;
      for (std::size_t i = 0; i < n; ++i) {
        // x on a 0.25 m grid from -12 m to 55 m (runs inside the ROI ahead of the body, in it, beyond it), y
        // mostly inside, now and then beside the ROI or NaN.
        const float x = -12.F + 0.25F * static_cast<float>(rng() % 269);
        float y = static_cast<float>(rng() % 9) - 4.F;
        if (rng() % 17 == 0) y = 11.F;
        if (rng() % 23 == 0) y = nan;
        in.push_back(lidar_point(x, y, 0.5F, static_cast<std::uint16_t>(i)));
        if (rng() % 29 == 0) in.back().source = static_cast<std::uint8_t>(PointSource::Lidar2d);
        if (rng() % 31 == 0) in.back().x = nan;
      }
      // Sorted runs as well: whole fours kept (the vector count), whole fours beyond the limit.
      if (n > 100)
        std::sort(in.begin(), in.begin() + 400, [](const LidarPoint& a, const LidarPoint& b) { return a.x < b.x; });
      Cloud expected;
      std::vector<LidarPoint> expected2d;
      crop_box(in, roi, kBody, expected, expected2d);
      for (const float limit : {20.F, 20.1F, 50.F, 0.4F, -10.F, -20.F, nan, std::numeric_limits<float>::infinity()}) {
        Cloud out;
        std::vector<LidarPoint> scan;
        const std::uint32_t counted = crop_box(in, roi, kBody, out, scan, limit);
        EXPECT_EQ(counted, second_pass(out, limit)) << n << " points, limit " << limit;
        ASSERT_EQ(out.size(), expected.size());
        for (std::size_t k = 0; k < out.size(); ++k) {
          EXPECT_EQ(out.ring[k], expected.ring[k]);
          EXPECT_EQ(out.x[k], expected.x[k]);
        }
        EXPECT_EQ(scan.size(), expected2d.size());
      }
      if (n == 1003U) {
        // The test has teeth: some kept points lie beyond 20 m and some at or before it.
        const std::uint32_t at_20 = second_pass(expected, 20.F);
        EXPECT_GT(at_20, 0U);
        EXPECT_LT(at_20, expected.size());
        EXPECT_LT(second_pass(expected, 19.9F), at_20);  // points exactly at 20 m are kept and counted
      }
    }
  }
}

}  // namespace
}  // namespace fieldguard::perception
