#include "fieldguard/perception/ransac_ground.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "perception/random.hpp"

namespace fieldguard::perception {
namespace {

constexpr double kConfidence = 0.99;  // pcl::SampleConsensus's default probability

}  // namespace

std::size_t count_plane_inliers(const Cloud& in, const std::array<float, 4>& plane, float threshold) {
  const std::size_t n = in.size();
  const float* x = in.x.data();
  const float* y = in.y.data();
  const float* z = in.z.data();
  const float a = plane[0], b = plane[1], c = plane[2], d = plane[3];
  // Fixed-width inner loop: the compiler turns it into packed multiplies and compares at -O2.
  constexpr std::size_t kLanes = 8;
  std::array<std::uint32_t, kLanes> acc{};
  std::size_t i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    for (std::size_t k = 0; k < kLanes; ++k) {
      acc[k] += std::fabs(a * x[i + k] + b * y[i + k] + c * z[i + k] + d) < threshold ? 1U : 0U;
    }
  }
  std::size_t count = 0;
  for (const auto v : acc) count += v;
  for (; i < n; ++i) count += std::fabs(a * x[i] + b * y[i] + c * z[i] + d) < threshold ? 1U : 0U;
  return count;
}

RansacGround::RansacGround(const RansacParams& params, double sensor_height_m)
    : params_(params), sensor_height_m_(static_cast<float>(sensor_height_m)) {
  if (params_.iterations < 1) throw std::invalid_argument("RansacGround: iterations must be at least 1");
  if (!(params_.distance_m > 0.0)) throw std::invalid_argument("RansacGround: distance_m must be positive");
  coeff_ = {0.F, 0.F, 1.F, sensor_height_m_};
}

float RansacGround::ground_z(float x, float y) const {
  const float nz = coeff_[2];
  if (nz < 1e-3F) return -sensor_height_m_;
  return -(coeff_[0] * x + coeff_[1] * y + coeff_[3]) / nz;
}

void RansacGround::segment(const Cloud& in, GroundLabels& out) {
  const std::size_t n = in.size();
  out.resize(n);
  found_ = false;
  trials_ = 0;
  coeff_ = {0.F, 0.F, 1.F, sensor_height_m_};
  const auto threshold = static_cast<float>(params_.distance_m);
  const float* x = in.x.data();
  const float* y = in.y.data();
  const float* z = in.z.data();

  if (n >= 3) {
    SplitMix64 rng(params_.seed);
    std::size_t best = 0;
    std::array<float, 4> best_plane{};
    double k = std::numeric_limits<double>::max();
    const double log_probability = std::log(1.0 - kConfidence);
    const auto max_skips = static_cast<long>(params_.iterations) * 10;
    long skips = 0;
    const auto un = static_cast<std::uint32_t>(n);
    while (trials_ < params_.iterations && static_cast<double>(trials_) < k) {
      const std::uint32_t i0 = rng.below(un);
      std::uint32_t i1 = rng.below(un);
      std::uint32_t i2 = rng.below(un);
      const Eigen::Vector3f p0(x[i0], y[i0], z[i0]);
      const Eigen::Vector3f p1(x[i1], y[i1], z[i1]);
      const Eigen::Vector3f p2(x[i2], y[i2], z[i2]);
      const Eigen::Vector3f cross = (p1 - p0).cross(p2 - p0);
      const float norm = cross.norm();
      // Repeated or collinear samples make no plane (pcl: dummy_precision for float, 1e-5).
      if (i0 == i1 || i0 == i2 || i1 == i2 || !(norm >= 1e-5F)) {
        if (++skips >= max_skips) break;
        continue;
      }
      const Eigen::Vector3f nrm = cross / norm;
      const std::array<float, 4> plane{nrm.x(), nrm.y(), nrm.z(), -nrm.dot(p0)};
      const std::size_t count = count_plane_inliers(in, plane, threshold);
      ++trials_;
      if (count > best) {
        best = count;
        best_plane = plane;
        const double w = static_cast<double>(best) / static_cast<double>(n);
        double p_outliers = 1.0 - w * w * w;
        p_outliers = std::clamp(p_outliers, std::numeric_limits<double>::epsilon(),
                                1.0 - std::numeric_limits<double>::epsilon());
        k = log_probability / std::log(p_outliers);
      }
    }
    if (best >= 3) {
      // Refit to the inliers: the plane through their centroid normal to the covariance's least axis.
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      inliers_.clear();
      const float a = best_plane[0], b = best_plane[1], c = best_plane[2], d = best_plane[3];
      for (std::size_t i = 0; i < n; ++i) {
        if (std::fabs(a * x[i] + b * y[i] + c * z[i] + d) < threshold) {
          inliers_.push_back(static_cast<std::uint32_t>(i));
          mean += Eigen::Vector3d(static_cast<double>(x[i]), static_cast<double>(y[i]), static_cast<double>(z[i]));
        }
      }
      mean /= static_cast<double>(inliers_.size());
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (const std::uint32_t i : inliers_) {
        const Eigen::Vector3d q =
            Eigen::Vector3d(static_cast<double>(x[i]), static_cast<double>(y[i]), static_cast<double>(z[i])) - mean;
        cov.noalias() += q * q.transpose();
      }
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
      Eigen::Vector3d nrm = eig.eigenvectors().col(0);  // eigenvalues ascending
      if (!nrm.allFinite() || nrm.norm() < 0.5)
        nrm = Eigen::Vector3d(static_cast<double>(best_plane[0]), static_cast<double>(best_plane[1]),
                              static_cast<double>(best_plane[2]));
      nrm.normalize();
      if (nrm.z() < 0.0) nrm = -nrm;
      coeff_ = {static_cast<float>(nrm.x()), static_cast<float>(nrm.y()), static_cast<float>(nrm.z()),
                static_cast<float>(-nrm.dot(mean))};
      found_ = true;
    }
  }

  const float a = coeff_[0], b = coeff_[1], c = coeff_[2], d = coeff_[3];
  // Height above the plane along z where the plane is not vertical; the distance along the normal otherwise.
  const float inv_nz = c > 1e-3F ? 1.0F / c : 1.0F;
  std::uint8_t* g = out.ground.data();
  float* h = out.height_m.data();
  for (std::size_t i = 0; i < n; ++i) {
    const float dist = a * x[i] + b * y[i] + c * z[i] + d;
    h[i] = dist * inv_nz;
    g[i] = (found_ && std::fabs(dist) < threshold) ? 1U : 0U;
  }
  std::fill(out.guessed.begin(), out.guessed.end(), std::uint8_t{0});  // one plane for the whole frame
}

}  // namespace fieldguard::perception
