#pragma once
// Hand-made clouds for the perception tests.

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/perception/cloud.hpp"
#include "fieldguard/perception/cluster_filter.hpp"
#include "fieldguard/perception/euclidean_cluster.hpp"
#include "perception/random.hpp"

namespace fieldguard::perception::testing {

// Clusters as sets of point indices, and back: for stages that rewrite clusters (absorb, join).
using Sets = std::vector<std::vector<std::uint32_t>>;

inline Sets sets_of(const Clusters& c) {
  Sets s;
  for (std::size_t i = 0; i < c.size(); ++i) s.emplace_back(c[i].begin(), c[i].end());
  return s;
}

// Cluster bounds bit for bit, field by field (not memcmp: the struct's padding is not part of it).
inline bool same_bounds(const ClusterBounds& a, const ClusterBounds& b) {
  const auto bits = [](float v) { return std::bit_cast<std::uint32_t>(v); };
  for (std::size_t k = 0; k < 3; ++k) {
    if (bits(a.min[k]) != bits(b.min[k]) || bits(a.max[k]) != bits(b.max[k])) return false;
  }
  return bits(a.r2) == bits(b.r2) && bits(a.top) == bits(b.top) && bits(a.bottom) == bits(b.bottom) &&
         a.ground_guessed == b.ground_guessed;
}

inline Clusters clusters_of(const Sets& sets) {
  Clusters c;
  c.offsets.push_back(0);
  for (const auto& s : sets) {
    c.indices.insert(c.indices.end(), s.begin(), s.end());
    c.offsets.push_back(static_cast<std::uint32_t>(c.indices.size()));
  }
  return c;
}

inline LidarPoint lidar_point(float x, float y, float z, std::uint16_t ring = 0) {
  LidarPoint p;
  p.x = x;
  p.y = y;
  p.z = z;
  p.ring = ring;
  p.range_m = std::sqrt(x * x + y * y + z * z);
  return p;
}

inline std::vector<LidarPoint> to_lidar(const Cloud& c) {
  std::vector<LidarPoint> out;
  for (std::size_t i = 0; i < c.size(); ++i) out.push_back(lidar_point(c.x[i], c.y[i], c.z[i]));
  return out;
}

// Deterministic uniform numbers, for random clouds that are the same on every platform: the pipeline's own
// SplitMix64 (perception/random.hpp), with a float range on top.
struct TestRng {
  SplitMix64 gen;
  explicit TestRng(std::uint64_t seed) : gen(seed) {}
  std::uint64_t next() { return gen.next(); }
  float uniform(float lo, float hi) {
    return lo + (hi - lo) * static_cast<float>(static_cast<double>(gen.next() >> 40U) * 0x1.0p-24);
  }
};

// A solid block of points on a regular lattice: min corner, counts per axis, spacing.
inline void add_block(Cloud& c, std::array<float, 3> min, std::array<int, 3> counts, float step) {
  for (int i = 0; i < counts[0]; ++i) {
    for (int j = 0; j < counts[1]; ++j) {
      for (int k = 0; k < counts[2]; ++k) {
        c.push_back(min[0] + step * static_cast<float>(i), min[1] + step * static_cast<float>(j),
                    min[2] + step * static_cast<float>(k));
      }
    }
  }
}

// Ground z = a x + b y + c sampled on a grid over [x0, x1] x [y0, y1].
inline void add_plane(Cloud& c, float a, float b, float z0, float x0, float x1, float y0, float y1, float step) {
  for (float x = x0; x <= x1; x += step) {
    for (float y = y0; y <= y1; y += step) c.push_back(x, y, a * x + b * y + z0);
  }
}

}  // namespace fieldguard::perception::testing
