// crop_box against the stock pcl::CropBox it stands in for (the published pipeline: a CropBox for the ROI, then
// a second, setNegative(true), for the tractor's body).
//
// What PCL 1.13 does (pcl/filters/impl/crop_box.hpp, applyFilter): a point is "outside" when one of x < min,
// y < min, z < min, x > max, y > max, z > max holds, else "inside". So its boxes are closed, as ours: a point on
// a face of the ROI is kept, one on a face of the body box is removed. Non-finite points are dropped, in both
// modes, only when the cloud says it may hold them (is_dense false). In a cloud marked dense (pcl::PointCloud's
// default) nothing tests them: a NaN coordinate makes every comparison false, so the point counts as inside
// every box (kept by the ROI, removed by the body), and an infinite one is kept by a box unbounded on its axis.
// crop_box always drops them. The tests below hold the two equal on clouds marked not dense, and pin the dense
// difference down in a test of its own.

#include <gtest/gtest.h>
#include <pcl/filters/crop_box.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "fieldguard/perception/crop.hpp"
#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

using testing::lidar_point;
using testing::TestRng;

const Box3 kRoi{{-10.0, -10.0, -6.0}, {67.0, 10.0, 6.0}};  // fieldguard.yaml's, with the ground context
const Box3 kBody{{-5.0, -1.5, -1.5}, {0.4, 1.5, 1.5}};

Eigen::Vector4f corner(const std::array<double, 3>& a) {
  return {static_cast<float>(a[0]), static_cast<float>(a[1]), static_cast<float>(a[2]), 1.F};
}

// Indices (into `in`) of the points the two PCL passes keep, in order.
pcl::Indices pcl_crop(const std::vector<LidarPoint>& in, const Box3& roi, const Box3& body, bool dense) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (const LidarPoint& p : in) cloud->push_back(pcl::PointXYZ(p.x, p.y, p.z));
  cloud->is_dense = dense;
  pcl::Indices in_roi, kept;
  pcl::CropBox<pcl::PointXYZ> keep;
  keep.setInputCloud(cloud);
  keep.setMin(corner(roi.min));
  keep.setMax(corner(roi.max));
  keep.filter(in_roi);
  pcl::CropBox<pcl::PointXYZ> drop;
  drop.setInputCloud(cloud);
  drop.setIndices(pcl::make_shared<pcl::Indices>(in_roi));
  drop.setMin(corner(body.min));
  drop.setMax(corner(body.max));
  drop.setNegative(true);
  drop.filter(kept);
  return kept;
}

// Ours, as indices: each point carries its index in the ring field.
pcl::Indices our_crop(const std::vector<LidarPoint>& in, const Box3& roi, const Box3& body) {
  Cloud out;
  crop_box(in, roi, body, out);
  pcl::Indices kept;
  for (std::size_t k = 0; k < out.size(); ++k) {
    const LidarPoint& p = in.at(out.ring[k]);
    // The coordinates are the input's, bit for bit.
    EXPECT_EQ(std::bit_cast<std::uint32_t>(out.x[k]), std::bit_cast<std::uint32_t>(p.x));
    EXPECT_EQ(std::bit_cast<std::uint32_t>(out.y[k]), std::bit_cast<std::uint32_t>(p.y));
    EXPECT_EQ(std::bit_cast<std::uint32_t>(out.z[k]), std::bit_cast<std::uint32_t>(p.z));
    kept.push_back(static_cast<int>(out.ring[k]));
  }
  return kept;
}

// A coordinate for axis a: on a face of either box (as the float both sides compare with), one float step to
// either side of it, anywhere from well outside the ROI to well inside it, or not finite.
float draw(TestRng& rng, std::size_t a, const Box3& roi) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::array<float, 4> faces = {static_cast<float>(roi.min[a]), static_cast<float>(roi.max[a]),
                                      static_cast<float>(kBody.min[a]), static_cast<float>(kBody.max[a])};
  const std::uint64_t kind = rng.next() % 16;
  if (kind < 3) return faces[rng.next() % 4];
  if (kind < 5) return std::nextafter(faces[rng.next() % 4], inf);
  if (kind < 7) return std::nextafter(faces[rng.next() % 4], -inf);
  if (kind == 7) return std::array<float, 3>{nan, inf, -inf}[rng.next() % 3];
  if (kind == 8) return -0.F;
  const float lo = std::isfinite(roi.min[a]) ? static_cast<float>(roi.min[a]) : -100.F;
  const float hi = std::isfinite(roi.max[a]) ? static_cast<float>(roi.max[a]) : 100.F;
  return rng.uniform(lo - 5.F, hi + 5.F);
}

std::vector<LidarPoint> random_cloud(TestRng& rng, std::size_t n, const Box3& roi) {
  std::vector<LidarPoint> in;
  for (std::size_t i = 0; i < n; ++i) {
    in.push_back(lidar_point(draw(rng, 0, roi), draw(rng, 1, roi), draw(rng, 2, roi), static_cast<std::uint16_t>(i)));
  }
  return in;
}

TEST(CropBoxVsPcl, ClosedBoxesOnBothSides) {
  // On each face of the ROI (kept by both) and of the body box (removed by both), and a float step beyond each.
  std::vector<LidarPoint> in;
  for (std::size_t a = 0; a < 3; ++a) {
    for (const Box3* b : {&kRoi, &kBody}) {
      for (const double face : {b->min[a], b->max[a]}) {
        const float f = static_cast<float>(face);
        for (const float v : {f, std::nextafter(f, -1000.F), std::nextafter(f, 1000.F)}) {
          std::array<float, 3> c = {b == &kRoi ? 20.F : -2.F, 0.F, 0.F};  // inside the box on the other axes
          c[a] = v;
          in.push_back(lidar_point(c[0], c[1], c[2], static_cast<std::uint16_t>(in.size())));
        }
      }
    }
  }
  const pcl::Indices ours = our_crop(in, kRoi, kBody);
  EXPECT_EQ(ours, pcl_crop(in, kRoi, kBody, false));
  // The faces themselves: every ROI face point kept, every body face point removed.
  for (std::size_t i = 0; i < in.size(); i += 3) {
    const bool roi_face = (i / 3) % 4 < 2;
    const bool kept = std::find(ours.begin(), ours.end(), static_cast<int>(i)) != ours.end();
    EXPECT_EQ(kept, roi_face) << "face point " << i;
  }
}

// Random clouds, points on and beside every face, NaN and infinity in any coordinate, -0, counts that leave a
// remainder of the four-at-a-time loop; a finite ROI and one unbounded on some axes.
TEST(CropBoxVsPcl, SamePointsInTheSameOrderOnRandomClouds) {
  const double dinf = std::numeric_limits<double>::infinity();
  const Box3 half_open{{-10.0, -dinf, -6.0}, {67.0, 10.0, dinf}};
  TestRng rng(20261122);
  for (const Box3& roi : {kRoi, half_open}) {
    for (const std::size_t n : {0U, 1U, 3U, 4U, 6U, 17U, 256U, 4099U}) {
      for (int rep = 0; rep < 4; ++rep) {
        const std::vector<LidarPoint> in = random_cloud(rng, n, roi);
        const pcl::Indices ours = our_crop(in, roi, kBody);
        EXPECT_EQ(ours, pcl_crop(in, roi, kBody, false)) << n << " points";
        if (n == 4099U) {
          EXPECT_GT(ours.size(), n / 8) << "the draw should keep a fair share";
        }
      }
    }
  }
}

// Long runs, as a rotation gives them: all kept, all beyond the ROI, all in the body, with the odd point
// breaking a run, so that every path of the four-at-a-time loop (kept whole, dropped whole, in part) is taken.
TEST(CropBoxVsPcl, RunsOfKeptAndDroppedPoints) {
  TestRng rng(5);
  std::vector<LidarPoint> in;
  for (int run = 0; run < 60; ++run) {
    const int kind = run % 4;
    const std::size_t len = 3 + rng.next() % 40;
    for (std::size_t i = 0; i < len; ++i) {
      float x = 0, y = 0, z = 0;
      if (kind == 0) {  // ahead of the body, in the ROI
        x = rng.uniform(0.41F, 66.F), y = rng.uniform(-9.F, 9.F), z = rng.uniform(-5.F, 5.F);
      } else if (kind == 1) {  // beside the body, in the ROI
        x = rng.uniform(-9.F, 0.F), y = rng.uniform(1.6F, 9.F), z = rng.uniform(-5.F, 5.F);
      } else if (kind == 2) {  // in the body
        x = rng.uniform(-4.9F, 0.3F), y = rng.uniform(-1.4F, 1.4F), z = rng.uniform(-1.4F, 1.4F);
      } else {  // beyond the ROI
        x = rng.uniform(-30.F, -10.5F), y = rng.uniform(-20.F, 20.F), z = rng.uniform(-5.F, 5.F);
      }
      if (rng.next() % 23 == 0) x = std::numeric_limits<float>::quiet_NaN();
      in.push_back(lidar_point(x, y, z, static_cast<std::uint16_t>(in.size())));
    }
  }
  EXPECT_EQ(our_crop(in, kRoi, kBody), pcl_crop(in, kRoi, kBody, false));
}

// The one difference: in a cloud marked dense PCL does not test for NaN, and NaN fails every comparison, so
// a NaN coordinate never puts a point outside a box: the ROI pass keeps such a point unless another coordinate
// lies beyond the ROI, and the body pass removes it unless another coordinate lies beyond the body.
// crop_box drops every one.
TEST(CropBoxVsPcl, DenseCloudKeepsNanPointsThatCropBoxDrops) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<LidarPoint> in = {
      lidar_point(20.F, 0.F, 0.F, 0),  // an ordinary point: kept by both
      lidar_point(nan, 5.F, 0.F, 1),   // NaN x, beside the body in y: PCL (dense) keeps it
      lidar_point(20.F, nan, 0.F, 2),  // NaN y, ahead of the body in x: PCL (dense) keeps it
      lidar_point(nan, 0.F, 0.F, 3),   // NaN x, in the body's y and z: "inside" the body, PCL removes it
      lidar_point(nan, 50.F, 0.F, 4),  // NaN x, beyond the ROI in y: PCL drops it
  };
  const pcl::Indices ours = our_crop(in, kRoi, kBody);
  EXPECT_EQ(ours, (pcl::Indices{0}));
  EXPECT_EQ(pcl_crop(in, kRoi, kBody, false), ours);  // not dense: the same
  EXPECT_EQ(pcl_crop(in, kRoi, kBody, true), (pcl::Indices{0, 1, 2}));
  // Infinity on an axis the ROI leaves unbounded: PCL (dense) keeps it, crop_box drops it.
  const double dinf = std::numeric_limits<double>::infinity();
  const Box3 open_top{kRoi.min, {kRoi.max[0], kRoi.max[1], dinf}};
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<LidarPoint> tall = {lidar_point(20.F, 0.F, inf, 0), lidar_point(20.F, 0.F, 3.F, 1)};
  EXPECT_EQ(our_crop(tall, open_top, kBody), (pcl::Indices{1}));
  EXPECT_EQ(pcl_crop(tall, open_top, kBody, false), (pcl::Indices{1}));
  EXPECT_EQ(pcl_crop(tall, open_top, kBody, true), (pcl::Indices{0, 1}));
}

}  // namespace
}  // namespace fieldguard::perception
