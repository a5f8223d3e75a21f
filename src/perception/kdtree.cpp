#include "fieldguard/perception/kdtree.hpp"

#include <algorithm>
#include <cmath>

namespace fieldguard::perception {

void KdTree::build(const Cloud& cloud) {
  const std::size_t n = cloud.size();
  points_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    points_[i] = Point{cloud.x[i], cloud.y[i], cloud.z[i], static_cast<std::uint32_t>(i)};
  }
  nodes_.clear();
  if (n == 0) return;
  nodes_.reserve(2 * (n / kLeafSize + 1));
  build_node(0, static_cast<std::uint32_t>(n));
}

std::uint32_t KdTree::build_node(std::uint32_t begin, std::uint32_t end) {
  const auto self = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back(Node{0.F, 3, begin, end});
  if (end - begin <= kLeafSize) return self;
  float lo[3] = {points_[begin].x, points_[begin].y, points_[begin].z};
  float hi[3] = {lo[0], lo[1], lo[2]};
  for (std::uint32_t i = begin + 1; i < end; ++i) {
    const float c[3] = {points_[i].x, points_[i].y, points_[i].z};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], c[a]);
      hi[a] = std::max(hi[a], c[a]);
    }
  }
  std::uint32_t axis = 0;
  for (std::uint32_t a = 1; a < 3; ++a) {
    if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
  }
  if (!(hi[axis] > lo[axis])) return self;  // all points equal: one (large) leaf
  const std::uint32_t mid = begin + (end - begin) / 2;
  const auto key = [axis](const Point& p) { return axis == 0 ? p.x : (axis == 1 ? p.y : p.z); };
  std::nth_element(
      points_.begin() + begin, points_.begin() + mid, points_.begin() + end,
      [&key](const Point& a, const Point& b) { return key(a) < key(b) || (key(a) == key(b) && a.index < b.index); });
  const float split = key(points_[mid]);
  // Left holds [begin, mid) (keys <= split), right [mid, end) (keys >= split).
  build_node(begin, mid);
  const std::uint32_t right = build_node(mid, end);
  nodes_[self] = Node{split, axis, begin, right};
  return self;
}

void KdTree::radius_search(float qx, float qy, float qz, float radius, std::vector<std::uint32_t>& out) const {
  out.clear();
  const auto r = static_cast<float>(static_cast<double>(radius) * static_cast<double>(radius));
  radius_visit(qx, qy, qz, r, [&](std::uint32_t pos, float /*d2*/) { out.push_back(points_[pos].index); });
  std::sort(out.begin(), out.end());
}

}  // namespace fieldguard::perception
