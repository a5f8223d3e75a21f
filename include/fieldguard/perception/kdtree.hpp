#pragma once
// A compact static 3D k-d tree for radius searches: points copied into tree order (16 bytes each), leaves of
// up to kLeafSize points, split at the median of the widest axis. Exact: a radius search visits every point
// with squared distance below r2, computed in float as FLANN (behind pcl::search::KdTree) computes it, so a
// search with the same radius finds the same neighbours.
// Thread-compatible; const searches may run concurrently.

#include <cstdint>
#include <vector>

#include "fieldguard/perception/cloud.hpp"

namespace fieldguard::perception {

class KdTree {
 public:
  static constexpr std::uint32_t kLeafSize = 8;

  struct Point {
    float x, y, z;
    std::uint32_t index;  // in the cloud the tree was built from
  };

  void build(const Cloud& cloud);

  // Calls visit(position, squared_distance) for every point nearer than sqrt(r2) to q, where position indexes
  // points() (tree order; points()[position].index is the cloud's index). Order: tree order of leaves.
  template <class Visit>
  void radius_visit(float qx, float qy, float qz, float r2, Visit&& visit) const;

  // The cloud indices nearer than `radius`, ascending.
  void radius_search(float qx, float qy, float qz, float radius, std::vector<std::uint32_t>& out) const;

  [[nodiscard]] const Buffer<Point>& points() const { return points_; }
  [[nodiscard]] std::size_t size() const { return points_.size(); }

 private:
  struct Node {
    float split;
    std::uint32_t axis;   // 0, 1, 2; 3 = leaf
    std::uint32_t begin;  // leaf: points [begin, end); inner: left child = this + 1, right child = `end`
    std::uint32_t end;
  };
  std::uint32_t build_node(std::uint32_t begin, std::uint32_t end);

  Buffer<Point> points_;
  std::vector<Node> nodes_;
  mutable std::vector<std::uint32_t> stack_;
};

template <class Visit>
void KdTree::radius_visit(float qx, float qy, float qz, float r2, Visit&& visit) const {
  if (nodes_.empty()) return;
  // A fixed stack: the tree's depth is below 64 for any cloud that fits in memory.
  std::uint32_t stack[64];
  std::uint32_t top = 0;
  stack[top++] = 0;
  const float q[3] = {qx, qy, qz};
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (node.axis == 3) {
      for (std::uint32_t i = node.begin; i < node.end; ++i) {
        const Point& p = points_[i];
        const float dx = p.x - qx, dy = p.y - qy, dz = p.z - qz;
        const float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < r2) visit(i, d2);
      }
      continue;
    }
    const std::uint32_t self = static_cast<std::uint32_t>(&node - nodes_.data());
    const float diff = q[node.axis] - node.split;
    const std::uint32_t near = diff <= 0.F ? self + 1 : node.end;
    const std::uint32_t far = diff <= 0.F ? node.end : self + 1;
    if (diff * diff < r2) stack[top++] = far;
    stack[top++] = near;
  }
}

}  // namespace fieldguard::perception
