#include "fieldguard/perception/euclidean_cluster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace fieldguard::perception {
namespace {

// The grid never has more columns than this many per point (and at least kMinCells): a sparse, wide cloud
// gets larger columns, and searches then scan more points; the clusters stay the same.
constexpr std::size_t kCellsPerPoint = 8;
constexpr std::size_t kMinCells = 16384;

}  // namespace

EuclideanClusterer::EuclideanClusterer(const ClusterParams& params) : params_(params) {
  if (!(params_.tolerance_m > 0.0) || !std::isfinite(params_.tolerance_m)) {
    throw std::invalid_argument("EuclideanClusterer: tolerance_m must be positive");
  }
  // As pcl::EuclideanClusterExtraction: the tolerance goes to float, its square is taken in double and
  // handed to FLANN as float.
  const auto t = static_cast<float>(params_.tolerance_m);
  base_r2_ = static_cast<float>(static_cast<double>(t) * static_cast<double>(t));
  adaptive_ = params_.method == ClusterMethod::Adaptive;
  if (adaptive_) {
    const double g = params_.beam_factor * std::tan(params_.beam_spacing_deg * std::numbers::pi / 180.0);
    if (!(g >= 0.0 && g < 0.5)) {
      throw std::invalid_argument("EuclideanClusterer: beam_factor * tan(beam_spacing_deg) must be in [0, 0.5)");
    }
    growth_ = static_cast<float>(g);
    cap_ = static_cast<float>(std::max(params_.max_tolerance_m, params_.tolerance_m));
  }
}

float EuclideanClusterer::radius_at(float range_m) const {
  const auto t = static_cast<float>(params_.tolerance_m);
  if (!adaptive_) return t;
  return std::min(cap_, std::max(t, growth_ * range_m));
}

void EuclideanClusterer::extract(const Cloud& in, Clusters& out) {
  out.indices.clear();
  out.offsets.clear();
  out.offsets.push_back(0);
  if (in.empty()) return;
  prepare(in);
  if (params_.structure == ClusterStructure::KdTree) {
    extract_kdtree(in, out);
  } else {
    extract_grid(in, out);
  }
}

// Per point: the search radius that reaches every point it may join. With the adaptive radius a farther point
// may have a larger radius than the query's; its range is at most range + d, so d < growth * (range + d)
// bounds d by growth * range / (1 - growth), and by the cap.
void EuclideanClusterer::prepare(const Cloud& in) {
  const std::size_t n = in.size();
  done_.assign(n, 0U);
  pos_of_.resize(n);
  if (!adaptive_) return;
  r2_.resize(n);
  query_.resize(n);
  const auto t = static_cast<float>(params_.tolerance_m);
  const float reach = growth_ / (1.F - growth_);
  for (std::size_t i = 0; i < n; ++i) {
    const float range = std::sqrt(in.x[i] * in.x[i] + in.y[i] * in.y[i] + in.z[i] * in.z[i]);
    const float r = std::min(cap_, std::max(t, growth_ * range));
    r2_[i] = r == t ? base_r2_ : r * r;
    query_[i] = std::max(r, std::min(cap_, reach * range));
  }
}

void EuclideanClusterer::finish_cluster(Clusters& out) {
  const std::size_t first = out.indices.size();
  out.indices.insert(out.indices.end(), queue_.begin(), queue_.end());
  std::uint32_t* b = out.indices.data() + first;
  std::uint32_t* e = out.indices.data() + out.indices.size();
  const std::size_t count = static_cast<std::size_t>(e - b);
  if (count > 64 && count * 8 > done_.size()) {
    // A large share of the cloud (a wall, a building): in order by one pass over a bitmap of the cloud.
    mark_.assign(done_.size(), 0U);
    for (const std::uint32_t* it = b; it < e; ++it) mark_[*it] = 1U;
    std::uint32_t* w = b;
    for (std::size_t i = 0; i < mark_.size(); ++i) {
      if (mark_[i] != 0U) *w++ = static_cast<std::uint32_t>(i);
    }
  } else if (e - b <= 16) {  // most clusters are a few points: insertion sort
    for (std::uint32_t* it = b + 1; it < e; ++it) {
      const std::uint32_t v = *it;
      std::uint32_t* j = it;
      for (; j > b && v < *(j - 1); --j) *j = *(j - 1);
      *j = v;
    }
  } else {
    std::sort(b, e);
  }
  out.offsets.push_back(static_cast<std::uint32_t>(out.indices.size()));
}

void EuclideanClusterer::extract_kdtree(const Cloud& in, Clusters& out) {
  const std::size_t n = in.size();
  tree_.build(in);
  const auto& pts = tree_.points();
  for (std::uint32_t p = 0; p < n; ++p) pos_of_[pts[p].index] = p;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t seed = pos_of_[i];
    if (done_[seed] != 0U) continue;
    queue_.clear();
    queue_.push_back(seed);
    done_[seed] = 1U;
    for (std::size_t qi = 0; qi < queue_.size(); ++qi) {
      const KdTree::Point& p = pts[queue_[qi]];
      if (!adaptive_) {
        tree_.radius_visit(p.x, p.y, p.z, base_r2_, [&](std::uint32_t pos, float /*d2*/) {
          if (done_[pos] != 0U) return;
          done_[pos] = 1U;
          queue_.push_back(pos);
        });
      } else {
        const float own = r2_[p.index];
        const float q = query_[p.index];
        tree_.radius_visit(p.x, p.y, p.z, q * q, [&](std::uint32_t pos, float d2) {
          if (done_[pos] != 0U || !(d2 < std::max(own, r2_[pts[pos].index]))) return;
          done_[pos] = 1U;
          queue_.push_back(pos);
        });
      }
    }
    for (auto& v : queue_) v = pts[v].index;
    finish_cluster(out);
  }
}

// Columns: the x-y plane in squares of the smallest radius (larger if that would make more than
// kCellsPerPoint per point). A search scans the free points of the columns within its radius.
void EuclideanClusterer::extract_grid(const Cloud& in, Clusters& out) {
  const std::size_t n = in.size();
  float lo[2] = {in.x[0], in.y[0]};
  float hi[2] = {lo[0], lo[1]};
  for (std::size_t i = 1; i < n; ++i) {
    lo[0] = std::min(lo[0], in.x[i]);
    hi[0] = std::max(hi[0], in.x[i]);
    lo[1] = std::min(lo[1], in.y[i]);
    hi[1] = std::max(hi[1], in.y[i]);
  }
  // With the adaptive radius, columns of 1.25 times the smallest radius: the radius passes the smallest at
  // about 20 m and most far searches then still need only 3 x 3 columns (measured: 2 to 3 % of the
  // pipeline's time saved on an HDL-32E field).
  double edge = params_.tolerance_m * (adaptive_ ? 1.25 : 1.0);
  const std::size_t max_cols = std::max(kMinCells, kCellsPerPoint * n);
  std::size_t nx = 0, ny = 0;
  for (;;) {
    nx = static_cast<std::size_t>(static_cast<double>(hi[0] - lo[0]) / edge) + 1;
    ny = static_cast<std::size_t>(static_cast<double>(hi[1] - lo[1]) / edge) + 1;
    if (nx <= max_cols && ny <= max_cols && nx * ny <= max_cols) break;
    edge *= 1.25;
  }
  const auto inv = static_cast<float>(1.0 / edge);
  const auto e = static_cast<float>(edge);
  // (Through int32: float to a 64-bit unsigned is a slow two-way conversion on x86-64; columns < 2^31.)
  const auto cell = [inv](float v, float origin, std::size_t cells) {
    float f = (v - origin) * inv;
    f = f > 0.F ? f : 0.F;
    f = f < 2.0e9F ? f : 2.0e9F;
    const auto c = static_cast<std::size_t>(static_cast<std::int32_t>(f));
    return c < cells ? c : cells - 1;
  };

  // Counting sort by column; afterwards col_start_[c] is where column c ends, so column c is
  // [c == 0 ? 0 : col_start_[c - 1], col_start_[c]).
  const std::size_t cols = nx * ny;
  col_start_.assign(cols + 1, 0U);
  cell_of_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t c = cell(in.x[i], lo[0], nx) * ny + cell(in.y[i], lo[1], ny);
    cell_of_[i] = static_cast<std::uint32_t>(c);
    ++col_start_[c + 1];
  }
  for (std::size_t c = 0; c < cols; ++c) col_start_[c + 1] += col_start_[c];
  grid_points_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t p = col_start_[cell_of_[i]]++;
    grid_points_[p] = GridPoint{in.x[i], in.y[i], in.z[i], static_cast<std::uint32_t>(i)};
  }
  const auto col_begin = [this](std::size_t c) { return c == 0 ? 0U : col_start_[c - 1]; };
  // Each column keeps the points not yet in a cluster behind a moving boundary: a point that joins a cluster
  // is swapped in front of it. A search then scans only points still free: an object that one cluster has
  // swallowed costs no more searching, however dense (a shed's wall). (Sorting the columns by height to search
  // only the slab within the radius measured slower: a column of a voxelised cloud holds a few dozen points.)
  col_next_.resize(cols);
  for (std::size_t c = 0; c < cols; ++c) col_next_[c] = col_begin(c);
  if (adaptive_) sorted_r2_.resize(n);
  for (std::size_t p = 0; p < n; ++p) {
    const GridPoint& g = grid_points_[p];
    pos_of_[g.index] = static_cast<std::uint32_t>(p);
    if (adaptive_) sorted_r2_[p] = r2_[g.index];
  }

  GridPoint* gp = grid_points_.data();
  float* r2 = adaptive_ ? sorted_r2_.data() : nullptr;
  // Takes the free point at position j of column c into the cluster: to the members, and behind the boundary.
  const auto take = [&](std::uint32_t j, std::size_t c) {
    const std::uint32_t t = col_next_[c]++;
    const GridPoint g = gp[j];
    members_.push_back(Member{g.x, g.y, g.z, g.index, adaptive_ ? r2[j] : base_r2_});
    done_[g.index] = 1U;
    if (t != j) {
      gp[j] = gp[t];
      gp[t] = g;
      pos_of_[gp[j].index] = j;
      pos_of_[g.index] = t;
      if (adaptive_) std::swap(r2[j], r2[t]);
    }
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (done_[i] != 0U) continue;
    members_.clear();
    take(pos_of_[i], cell_of_[i]);
    for (std::size_t qi = 0; qi < members_.size(); ++qi) {
      const Member p = members_[qi];
      std::size_t k = 1;
      float q2 = base_r2_;
      if (adaptive_) {
        const float q = query_[p.index];
        q2 = q * q;
        k = static_cast<std::size_t>(q / e) + 1;  // at least ceil(q / e); a column more is skipped below
      }
      const std::size_t cx = cell(p.x, lo[0], nx), cy = cell(p.y, lo[1], ny);
      const std::size_t x0 = cx >= k ? cx - k : 0, x1 = std::min(cx + k, nx - 1);
      const std::size_t y0 = cy >= k ? cy - k : 0, y1 = std::min(cy + k, ny - 1);
      // Columns of the block whose nearest side is beyond the radius (the corners, when k > 1) are skipped.
      const float px = p.x - lo[0], py = p.y - lo[1];
      for (std::size_t x = x0; x <= x1; ++x) {
        const float fx = static_cast<float>(x) * e;
        const float gx = std::max(0.F, std::max(fx - px, px - (fx + e)));
        for (std::size_t y = y0; y <= y1; ++y) {
          const std::size_t c = x * ny + y;
          const std::uint32_t ce = col_start_[c];
          if (col_next_[c] == ce) continue;  // nothing free here
          if (k > 1) {
            const float fy = static_cast<float>(y) * e;
            const float gy = std::max(0.F, std::max(fy - py, py - (fy + e)));
            if (!(gx * gx + gy * gy < q2)) continue;
          }
          for (std::uint32_t j = col_next_[c]; j < ce; ++j) {
            const float dx = gp[j].x - p.x, dy = gp[j].y - p.y, dz = gp[j].z - p.z;
            const float d2 = dx * dx + dy * dy + dz * dz;
            if (!(d2 < q2)) continue;
            if (adaptive_ && !(d2 < std::max(p.r2, r2[j]))) continue;
            take(j, c);  // the point swapped into j was scanned already: go on after it
          }
        }
      }
    }
    queue_.clear();
    for (const Member& mb : members_) queue_.push_back(mb.index);
    finish_cluster(out);
  }
}

}  // namespace fieldguard::perception
