#include "fieldguard/perception/ransac_ground.hpp"

#include <gtest/gtest.h>
#include <pcl/ModelCoefficients.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <cmath>
#include <numbers>

#include "perception/test_clouds.hpp"

namespace fieldguard::perception {
namespace {

double deg(double rad) { return rad * 180.0 / std::numbers::pi; }

// Angle between two plane normals, sign-free.
double normal_angle_deg_d(double ax, double ay, double az, double bx, double by, double bz) {
  const double c = std::fabs(ax * bx + ay * by + az * bz) /
                   (std::sqrt(ax * ax + ay * ay + az * az) * std::sqrt(bx * bx + by * by + bz * bz));
  return deg(std::acos(std::min(1.0, c)));
}

// Any mix of float and double arguments (the plane's coefficients are float).
template <typename... T>
double normal_angle_deg(T... v) {
  return normal_angle_deg_d(static_cast<double>(v)...);
}

// Ground tilted by the vehicle's roll and pitch (z = a x + b y + c), with noise, and objects standing on it.
Cloud tilted_field(float a, float b, std::uint64_t seed) {
  testing::TestRng rng{seed};
  Cloud c;
  for (int i = 0; i < 8000; ++i) {
    const float x = rng.uniform(-8, 40), y = rng.uniform(-10, 10);
    c.push_back(x, y, a * x + b * y - 0.95F + rng.uniform(-0.03F, 0.03F));
  }
  for (int i = 0; i < 2500; ++i) {  // boxes and poles above the ground: 24 % outliers
    const float x = 5.F + static_cast<float>(i % 5) * 7.F + rng.uniform(0, 1.5F);
    const float y = -6.F + static_cast<float>(i % 3) * 5.F + rng.uniform(0, 1.0F);
    c.push_back(x, y, a * x + b * y - 0.95F + rng.uniform(0.5F, 2.5F));
  }
  return c;
}

TEST(RansacGround, FindsATiltedPlaneWithinOneDegree) {
  const float a = std::tan(5.F * std::numbers::pi_v<float> / 180.F);   // pitch 5 degrees
  const float b = std::tan(-3.F * std::numbers::pi_v<float> / 180.F);  // roll 3 degrees
  const Cloud c = tilted_field(a, b, 3);
  RansacGround ransac(RansacParams{60, 0.3, 42}, 0.95);
  GroundLabels labels;
  ransac.segment(c, labels);
  ASSERT_TRUE(ransac.found());
  const auto& k = ransac.coefficients();
  EXPECT_LT(normal_angle_deg(k[0], k[1], k[2], -a, -b, 1.0), 1.0);
  EXPECT_GT(k[2], 0.F);  // normal up
  EXPECT_NEAR(ransac.ground_z(10.F, 2.F), 10.F * a + 2.F * b - 0.95F, 0.05F);
  EXPECT_LE(ransac.trials(), 60);
  // The ground points are ground, the objects are not, and their heights are above the plane.
  std::size_t ground = 0, wrong = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (i < 8000) {
      ground += labels.ground[i];
    } else {
      wrong += labels.ground[i];
      EXPECT_GT(labels.height_m[i], 0.4F);
    }
  }
  EXPECT_EQ(ground, 8000U);
  EXPECT_EQ(wrong, 0U);
}

TEST(RansacGround, AgreesWithPclSacSegmentation) {
  const Cloud c = tilted_field(0.04F, -0.02F, 9);
  pcl::PointCloud<pcl::PointXYZ>::Ptr pc(new pcl::PointCloud<pcl::PointXYZ>);
  for (std::size_t i = 0; i < c.size(); ++i) pc->push_back(pcl::PointXYZ(c.x[i], c.y[i], c.z[i]));
  pcl::SACSegmentation<pcl::PointXYZ> seg;
  seg.setOptimizeCoefficients(true);
  seg.setModelType(pcl::SACMODEL_PLANE);
  seg.setMethodType(pcl::SAC_RANSAC);
  seg.setMaxIterations(60);
  seg.setDistanceThreshold(0.3);
  seg.setInputCloud(pc);
  pcl::PointIndices inliers;
  pcl::ModelCoefficients coeff;
  seg.segment(inliers, coeff);
  ASSERT_EQ(coeff.values.size(), 4U);

  RansacGround ransac(RansacParams{60, 0.3, 42}, 0.95);
  GroundLabels labels;
  ransac.segment(c, labels);
  const auto& k = ransac.coefficients();
  EXPECT_LT(normal_angle_deg(k[0], k[1], k[2], coeff.values[0], coeff.values[1], coeff.values[2]), 0.5);
  std::size_t ours = 0;
  for (const auto g : labels.ground) ours += g;
  EXPECT_NEAR(static_cast<double>(ours), static_cast<double>(inliers.indices.size()),
              0.01 * static_cast<double>(c.size()));
}

TEST(RansacGround, SameSeedSamePlane) {
  const Cloud c = tilted_field(0.02F, 0.01F, 4);
  RansacGround r1(RansacParams{60, 0.3, 7}, 0.95), r2(RansacParams{60, 0.3, 7}, 0.95);
  GroundLabels l1, l2;
  r1.segment(c, l1);
  r2.segment(c, l2);
  r1.segment(c, l1);  // and the same on the next frame
  EXPECT_EQ(r1.coefficients(), r2.coefficients());
  EXPECT_EQ(r1.trials(), r2.trials());
  EXPECT_TRUE(std::equal(l1.ground.begin(), l1.ground.end(), l2.ground.begin(), l2.ground.end()));
}

TEST(RansacGround, StopsEarlyWhenTheGroundDominates) {
  Cloud c;
  testing::add_plane(c, 0.F, 0.F, -0.95F, 0.F, 30.F, -10.F, 10.F, 0.5F);
  RansacGround ransac(RansacParams{60, 0.3, 42}, 0.95);
  GroundLabels labels;
  ransac.segment(c, labels);
  ASSERT_TRUE(ransac.found());
  EXPECT_LT(ransac.trials(), 10);  // every sample is an inlier: k = log(0.01) / log(1 - 1) ~ 0
}

TEST(RansacGround, TooFewPointsFindNoPlane) {
  RansacGround ransac(RansacParams{60, 0.3, 42}, 1.0);
  GroundLabels labels;
  Cloud c;
  ransac.segment(c, labels);
  EXPECT_FALSE(ransac.found());
  c.push_back(1, 1, -1);
  c.push_back(2, 1, 0.5F);
  ransac.segment(c, labels);
  EXPECT_FALSE(ransac.found());
  ASSERT_EQ(labels.ground.size(), 2U);
  EXPECT_EQ(labels.ground[0], 0U);
  EXPECT_NEAR(labels.height_m[1], 1.5F, 1e-6F);  // above the level plane at -1 m
  // Three identical points make no plane either.
  Cloud same;
  for (int i = 0; i < 3; ++i) same.push_back(1, 1, 1);
  ransac.segment(same, labels);
  EXPECT_FALSE(ransac.found());
}

}  // namespace
}  // namespace fieldguard::perception
