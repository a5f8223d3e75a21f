#include "fieldguard/perception/euclidean_cluster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "perception/simd.hpp"

namespace fieldguard::perception {
namespace {

// The grid's x-y column table has at most this many columns per point (and at least kMinColumns); a cloud
// spread wider (not one a region of interest has cut) is clustered over the k-d tree instead: same clusters.
constexpr std::size_t kColumnsPerPoint = 16;
constexpr std::size_t kMinColumns = std::size_t{1} << 20;
// Metres by which a gap between two cells is taken short: a point's cell comes from (v - lo) / edge in float,
// and that rounding must not make a cell pair look farther apart than two of its points are.
constexpr float kSlack = 1e-3F;

// Union-find over cells: the root of `c`, halving the path on the way.
inline std::uint32_t find_root(std::uint32_t* parent, std::uint32_t c) {
  while (parent[c] != c) {
    parent[c] = parent[parent[c]];
    c = parent[c];
  }
  return c;
}

// Whether a point of [a0, a1) and one of [b0, b1) join (grid order; coordinates and radii squared per point,
// padded by four): each point of the first against four of the second at a time. Lane by lane the same
// operations in the same order as the scalar tests (EuclideanClusterer::joins_anisotropic, d^2 < r^2), so the
// same answers to the bit.
bool cells_join(std::uint32_t a0, std::uint32_t a1, std::uint32_t b0, std::uint32_t b1, const float* sx,
                const float* sy, const float* sz, const float* r2, const float* h2, bool aniso) {
  using simd::f32x4;
  const auto lanes = static_cast<std::int32_t>(b1 - b0);
  for (std::uint32_t i = a0; i < a1; ++i) {
    const f32x4 px = simd::splat(sx[i]), py = simd::splat(sy[i]), pz = simd::splat(sz[i]);
    const f32x4 pv = simd::splat(r2[i]), ph = simd::splat(h2[i]);
    simd::i32x4 lane = {0, 1, 2, 3};
    for (std::uint32_t j = b0; j < b1; j += 4, lane += 4) {
      const f32x4 dx = simd::load(sx + j) - px, dy = simd::load(sy + j) - py, dz = simd::load(sz + j) - pz;
      const f32x4 dxy2 = dx * dx + dy * dy;
      const f32x4 qv = simd::load(r2 + j);
      const f32x4 v = pv < qv ? qv : pv;  // std::max(r2[i], r2[j])
      simd::i32x4 hit;
      if (aniso) {
        const f32x4 qh = simd::load(h2 + j);
        const f32x4 h = ph < qh ? qh : ph;
        hit = dxy2 * v + (dz * dz) * h < h * v;
      } else {
        hit = dxy2 + dz * dz < v;
      }
      hit &= lane < simd::splat(lanes);  // lanes past b1 are another cell's points or padding
      if (simd::mask_bits(hit) != 0U) return true;
    }
  }
  return false;
}

}  // namespace

EuclideanClusterer::EuclideanClusterer(const ClusterParams& params) : params_(params) {
  if (!(params_.tolerance_m > 0.0) || !std::isfinite(params_.tolerance_m)) {
    throw std::invalid_argument("EuclideanClusterer: tolerance_m must be positive");
  }
  // As pcl::EuclideanClusterExtraction: the tolerance goes to float, its square is taken in double and
  // handed to FLANN as float.
  const auto t = static_cast<float>(params_.tolerance_m);
  base_r2_ = static_cast<float>(static_cast<double>(t) * static_cast<double>(t));
  anisotropic_ = params_.method == ClusterMethod::Anisotropic;
  adaptive_ = params_.method == ClusterMethod::Adaptive || anisotropic_;
  if (adaptive_) {
    const double spacing = std::tan(params_.beam_spacing_deg * std::numbers::pi / 180.0);
    const double g = params_.beam_factor * spacing;
    if (!(g >= 0.0 && g < 0.5)) {
      throw std::invalid_argument("EuclideanClusterer: beam_factor * tan(beam_spacing_deg) must be in [0, 0.5)");
    }
    growth_ = static_cast<float>(g);
    cap_ = static_cast<float>(std::max(params_.max_tolerance_m, params_.tolerance_m));
    if (anisotropic_) {
      const double gh = params_.horizontal_beam_factor * spacing;
      if (!(gh >= 0.0 && gh < 0.5)) {
        throw std::invalid_argument(
            "EuclideanClusterer: horizontal_beam_factor * tan(beam_spacing_deg) must be in [0, 0.5)");
      }
      if (!std::isfinite(params_.horizontal_max_tolerance_m)) {
        throw std::invalid_argument("EuclideanClusterer: horizontal_max_tolerance_m must be finite");
      }
      growth_h_ = static_cast<float>(gh);
      cap_h_ = static_cast<float>(std::max(params_.horizontal_max_tolerance_m, params_.tolerance_m));
    }
  }
}

// A radius that grows with range: tolerance_m up close, `growth` per metre of range farther out, at most `cap`.
float EuclideanClusterer::grown(float growth, float cap, float range_m) const {
  return std::min(cap, std::max(static_cast<float>(params_.tolerance_m), growth * range_m));
}

float EuclideanClusterer::horizontal_radius_at(float range_m) const {
  return anisotropic_ ? grown(growth_h_, cap_h_, range_m) : radius_at(range_m);
}

float EuclideanClusterer::radius_at(float range_m) const {
  return adaptive_ ? grown(growth_, cap_, range_m) : static_cast<float>(params_.tolerance_m);
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
  if (anisotropic_) h2_.resize(n);
  const auto t = static_cast<float>(params_.tolerance_m);
  // Anisotropic: each radius is at most max(t, g * range) capped, with g the larger growth and the larger cap,
  // so the same bound holds with those.
  const float g = anisotropic_ ? std::max(growth_, growth_h_) : growth_;
  const float cap = anisotropic_ ? std::max(cap_, cap_h_) : cap_;
  const float reach = g / (1.F - g);
  for (std::size_t i = 0; i < n; ++i) {
    const float range = std::sqrt(in.x[i] * in.x[i] + in.y[i] * in.y[i] + in.z[i] * in.z[i]);
    const float v = grown(growth_, cap_, range);
    r2_[i] = v == t ? base_r2_ : v * v;
    float farthest = v;
    if (anisotropic_) {
      const float h = grown(growth_h_, cap_h_, range);
      h2_[i] = h == t ? base_r2_ : h * h;
      farthest = std::max(v, h);
    }
    query_[i] = std::max(farthest, std::min(cap, reach * range));
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
      } else if (!anisotropic_) {
        const float own = r2_[p.index];
        const float q = query_[p.index];
        tree_.radius_visit(p.x, p.y, p.z, q * q, [&](std::uint32_t pos, float d2) {
          if (done_[pos] != 0U || !(d2 < std::max(own, r2_[pts[pos].index]))) return;
          done_[pos] = 1U;
          queue_.push_back(pos);
        });
      } else {
        const float own_v = r2_[p.index], own_h = h2_[p.index];
        const float q = query_[p.index];
        tree_.radius_visit(p.x, p.y, p.z, q * q, [&](std::uint32_t pos, float /*d2*/) {
          if (done_[pos] != 0U) return;
          const KdTree::Point& o = pts[pos];
          const float dx = o.x - p.x, dy = o.y - p.y, dz = o.z - p.z;
          if (!joins_anisotropic(dx * dx + dy * dy, dz * dz, std::max(own_h, h2_[o.index]),
                                 std::max(own_v, r2_[o.index]))) {
            return;
          }
          done_[pos] = 1U;
          queue_.push_back(pos);
        });
      }
    }
    for (auto& v : queue_) v = pts[v].index;
    finish_cluster(out);
  }
}

// Cells: cubes of edge a bit under tolerance / sqrt(3), so that any two points of one cell are nearer than the
// smallest radius and join. A cell is therefore a piece of one cluster, and clustering is union-find over
// cells: two neighbouring cells join when any pair of their points is within the pair's radius (the test
// stops at the first such pair, and is skipped when the two are already joined or the boxes of their points lie
// beyond reach). A dense surface (a wall, a shed's roof) thus costs a few tests per cell instead of a radius
// search per point. The connected components are those of the point graph, so the clusters are exactly the
// k-d tree's.
void EuclideanClusterer::extract_grid(const Cloud& in, Clusters& out) {
  const std::size_t n = in.size();
  float lo[3] = {in.x[0], in.y[0], in.z[0]};
  float hi[3] = {lo[0], lo[1], lo[2]};
  bool finite = true;
  for (std::size_t i = 0; i < n; ++i) {
    const float x = in.x[i], y = in.y[i], z = in.z[i];
    finite = finite && std::isfinite(x) && std::isfinite(y) && std::isfinite(z);
    lo[0] = std::min(lo[0], x);
    hi[0] = std::max(hi[0], x);
    lo[1] = std::min(lo[1], y);
    hi[1] = std::max(hi[1], y);
    lo[2] = std::min(lo[2], z);
    hi[2] = std::max(hi[2], z);
  }
  const auto t = static_cast<float>(params_.tolerance_m);
  float extent = 0.F;  // largest coordinate magnitude: sets the rounding the cell edge must leave room for
  for (int k = 0; k < 3; ++k) extent = std::max({extent, std::fabs(lo[k]), std::fabs(hi[k])});
  const float rounding = 8.F * extent * std::numeric_limits<float>::epsilon() + kSlack;
  const float edge = (t * 0.999F - 2.F * rounding) / std::numbers::sqrt3_v<float>;
  std::size_t nx = 0, ny = 0;
  if (finite && edge > 0.F) {
    nx = static_cast<std::size_t>(static_cast<double>(hi[0] - lo[0]) / static_cast<double>(edge)) + 1;
    ny = static_cast<std::size_t>(static_cast<double>(hi[1] - lo[1]) / static_cast<double>(edge)) + 1;
  }
  const std::size_t max_cols = std::max(kMinColumns, kColumnsPerPoint * n);
  const double nz_d = finite && edge > 0.F ? static_cast<double>(hi[2] - lo[2]) / static_cast<double>(edge) : 0.0;
  if (!finite || !(edge > 0.F) || nx > max_cols || ny > max_cols || nx * ny > max_cols ||
      nz_d >= static_cast<double>(max_cols)) {
    extract_kdtree(in, out);
    return;
  }
  const float inv = 1.F / edge;
  const auto cell = [inv](float v, float origin) {
    return static_cast<std::uint32_t>(static_cast<std::int32_t>((v - origin) * inv));  // >= 0: v >= origin
  };

  // Points sorted by x-y column and, within a column, by z cell: two stable counting sorts (by z cell, then
  // by column), as an LSD radix sort.
  const std::size_t cols = nx * ny;
  const std::size_t nz = static_cast<std::size_t>(nz_d) + 1;
  col_start_.assign(std::max(cols, nz) + 1, 0U);
  cell_of_.resize(n);  // z cell of each point, then its column
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t z = std::min<std::uint32_t>(cell(in.z[i], lo[2]), static_cast<std::uint32_t>(nz - 1));
    cell_of_[i] = z;
    ++col_start_[z + 1];
  }
  for (std::size_t z = 0; z < nz; ++z) col_start_[z + 1] += col_start_[z];
  by_z_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    by_z_[col_start_[cell_of_[i]]++] = GridPoint{in.x[i], in.y[i], in.z[i], static_cast<std::uint32_t>(i), cell_of_[i]};
  }
  std::fill(col_start_.begin(), col_start_.begin() + static_cast<std::ptrdiff_t>(cols) + 1, 0U);
  for (std::size_t k = 0; k < n; ++k) {
    const GridPoint& g = by_z_[k];
    const std::size_t c =
        std::min<std::size_t>(cell(g.x, lo[0]), nx - 1) * ny + std::min<std::size_t>(cell(g.y, lo[1]), ny - 1);
    cell_of_[k] = static_cast<std::uint32_t>(c);
    ++col_start_[c + 1];
  }
  for (std::size_t c = 0; c < cols; ++c) col_start_[c + 1] += col_start_[c];
  grid_points_.resize(n);
  col_next_.assign(col_start_.begin(), col_start_.begin() + static_cast<std::ptrdiff_t>(cols));
  for (std::size_t k = 0; k < n; ++k) grid_points_[col_next_[cell_of_[k]]++] = by_z_[k];
  // Cells: runs of k z cells in a column. Far out the radii are larger than the cube's diagonal: a column whose
  // every point is at least rmin away (horizontally, so in 3D too) may stack k z cells into one taller cell
  // whose points still all join with the smallest radii at rmin (each axis's extent taken 2 * rounding long).
  // Fewer, taller cells: far walls cost fewer cell pairs.
  cells_.clear();
  col_cells_.resize(cols + 1);
  GridPoint* gp = grid_points_.data();
  const double e = static_cast<double>(edge), rho2 = 2.0 * static_cast<double>(rounding);
  const auto stack_of = [&](std::size_t c) -> std::uint32_t {
    if (!adaptive_) return 1;
    const double x0 = static_cast<double>(lo[0]) + static_cast<double>(c / ny) * e - rho2;
    const double y0 = static_cast<double>(lo[1]) + static_cast<double>(c % ny) * e - rho2;
    const double dx = std::max({0.0, x0, -(x0 + e + 2.0 * rho2)});
    const double dy = std::max({0.0, y0, -(y0 + e + 2.0 * rho2)});
    const auto rmin = static_cast<float>(std::sqrt(dx * dx + dy * dy));
    const auto v = static_cast<double>(grown(growth_, cap_, rmin));
    const double h = anisotropic_ ? static_cast<double>(grown(growth_h_, cap_h_, rmin)) : v;
    const double across = 2.0 * (e + rho2) * (e + rho2) / (h * h);
    if (!(across < 0.998)) return 1;
    const double height = std::sqrt((0.998 - across) * v * v) - rho2;  // the tallest cell allowed
    return static_cast<std::uint32_t>(std::clamp(std::floor(height / e), 1.0, 64.0));
  };
  for (std::size_t c = 0; c < cols; ++c) {
    col_cells_[c] = static_cast<std::uint32_t>(cells_.size());
    const std::uint32_t b = col_start_[c], end = col_start_[c + 1];
    if (b == end) continue;
    const std::uint32_t k = stack_of(c);
    std::uint32_t top = 0;  // the last z cell of the current cell
    for (std::uint32_t j = b; j < end; ++j) {
      if (j == b || gp[j].iz > top) {
        const std::uint32_t bottom = gp[j].iz - gp[j].iz % k;
        top = bottom + k - 1;
        cells_.push_back(Cell{j, static_cast<std::uint32_t>(c), bottom, top, 0.F, 0.F});
      }
    }
  }
  col_cells_[cols] = static_cast<std::uint32_t>(cells_.size());
  const auto ncells = static_cast<std::uint32_t>(cells_.size());
  cells_.push_back(Cell{static_cast<std::uint32_t>(n), 0, 0, 0, 0.F, 0.F});  // sentinel: the end of the last cell
  sorted_r2_.resize(n + 4);  // padded: the pair test reads four at a time
  if (anisotropic_) sorted_h2_.resize(n + 4);
  parent_.resize(ncells);
  cell_box_.resize(6 * static_cast<std::size_t>(ncells));
  for (std::uint32_t c = 0; c < ncells; ++c) {
    parent_[c] = c;
    float m = base_r2_, mh = base_r2_;
    float* box = cell_box_.data() + 6 * static_cast<std::size_t>(c);
    const GridPoint& p0 = gp[cells_[c].first];
    box[0] = box[3] = p0.x;
    box[1] = box[4] = p0.y;
    box[2] = box[5] = p0.z;
    for (std::uint32_t j = cells_[c].first; j < cells_[c + 1].first; ++j) {
      box[0] = std::min(box[0], gp[j].x);
      box[1] = std::min(box[1], gp[j].y);
      box[2] = std::min(box[2], gp[j].z);
      box[3] = std::max(box[3], gp[j].x);
      box[4] = std::max(box[4], gp[j].y);
      box[5] = std::max(box[5], gp[j].z);
      const float r2 = adaptive_ ? r2_[gp[j].index] : base_r2_;
      sorted_r2_[j] = r2;
      m = std::max(m, r2);
      if (anisotropic_) {
        sorted_h2_[j] = h2_[gp[j].index];
        mh = std::max(mh, sorted_h2_[j]);
      }
    }
    // Anisotropic: both radii grow with range, so of a joining pair the farther point has the larger of each
    // and reaches the other within its cell's largest horizontal (hreach2) and vertical (reach2) radius.
    cells_[c].reach2 = m;
    cells_[c].hreach2 = anisotropic_ ? mh : m;
  }

  // Joins. Of two cells, the one with the larger radii (both radii grow with range, so a cell's largest
  // horizontal and vertical radius are those of its farthest point: of two cells, one has both at least as
  // large as the other's; ties by cell number) looks for the other within its own reach. Its reach covers
  // every pair the other's would, so each cell pair is looked at once, from that side; of two points, the one
  // with the larger radius reaches the other, so every joining pair is tested. Dense surfaces join early and
  // most pairs end at the union-find check.
  std::uint32_t* parent = parent_.data();
  const float* r2 = sorted_r2_.data();
  const float* h2 = anisotropic_ ? sorted_h2_.data() : sorted_r2_.data();
  const bool aniso = anisotropic_;
  // The gap between two cells `d` apart on an axis (a whole cell less, taken short by kSlack), for every
  // offset a cell's reach covers: looked up per neighbour instead of computed.
  float max_reach2 = 0.F;
  for (std::uint32_t c = 0; c < ncells; ++c) max_reach2 = std::max({max_reach2, cells_[c].reach2, cells_[c].hreach2});
  const auto max_reach = static_cast<std::int64_t>(std::sqrt(max_reach2) / edge) + 1;
  gaps_.resize(static_cast<std::size_t>(2 * max_reach + 1));
  for (std::int64_t d = -max_reach; d <= max_reach; ++d) {
    const std::int64_t g = d < 0 ? -d - 1 : d - 1;
    gaps_[static_cast<std::size_t>(d + max_reach)] = g > 0 ? static_cast<float>(g) * edge - kSlack : 0.F;
  }
  const float* gap_at = gaps_.data() + max_reach;  // gap_at[d], d in [-max_reach, max_reach]
  // Points in grid order, one array per coordinate (padded: the pair test reads four at a time).
  grid_xyz_.resize(3 * (n + 4));
  float* const sx = grid_xyz_.data();
  float* const sy = sx + n + 4;
  float* const sz = sy + n + 4;
  for (std::size_t j = 0; j < n; ++j) {
    sx[j] = gp[j].x;
    sy[j] = gp[j].y;
    sz[j] = gp[j].z;
  }
  for (std::size_t j = n; j < n + 4; ++j) sx[j] = sy[j] = sz[j] = 0.F;
  for (std::size_t j = n; j < n + 4; ++j) {
    sorted_r2_[j] = 0.F;
    if (anisotropic_) sorted_h2_[j] = 0.F;
  }
  // Whether cell b's radii are below cell a's (the order above: vertical, then horizontal, then number).
  const auto below = [&](const Cell& cb, std::uint32_t b, const Cell& ca, std::uint32_t a) {
    if (cb.reach2 != ca.reach2) return cb.reach2 < ca.reach2;
    if (cb.hreach2 != ca.hreach2) return cb.hreach2 < ca.hreach2;
    return b < a;
  };
  // Per column: its lowest cell in that order (col_next_ is free until the clusters are grouped). A column whose
  // lowest cell is not below a has no cell a looks for: a passes over it whole. (Radii grow with range, so most
  // columns on a's far side.)
  std::uint32_t* const col_low = col_next_.data();
  for (std::uint32_t b = 0; b < ncells; ++b) {
    const std::uint32_t col = cells_[b].col, low = col_low[col];
    if (b == col_cells_[col] || below(cells_[b], b, cells_[low], low)) col_low[col] = b;
  }
  for (std::uint32_t a = 0; a < ncells; ++a) {
    const Cell& ca = cells_[a];
    const std::uint32_t a0 = ca.first, a1 = cells_[a + 1].first;
    const float reach2 = ca.reach2, hreach2 = ca.hreach2;  // equal unless anisotropic
    const auto reach = static_cast<std::int64_t>(std::sqrt(reach2) / edge) + 1;
    const auto hreach = static_cast<std::int64_t>(std::sqrt(hreach2) / edge) + 1;
    const auto ax = static_cast<std::int64_t>(ca.col / ny), ay = static_cast<std::int64_t>(ca.col % ny);
    const auto az = static_cast<std::int64_t>(ca.iz), az_top = static_cast<std::int64_t>(ca.iz_top);
    // Whether a cell dz z cells away in a column gxy away is within reach. It only turns false as |dz| grows
    // (the gap grows with the offset), so a column's reachable cells are one run of z cells.
    const auto within = [&](float gxy, std::int64_t dz) {
      const float gz = gap_at[dz];
      return aniso ? joins_anisotropic(gxy, gz * gz, hreach2, reach2) : gxy + gz * gz < reach2;
    };
    std::uint32_t ra = find_root(parent, a);  // kept up to date: only this loop joins a's root to another
    const float* const abox = cell_box_.data() + 6 * static_cast<std::size_t>(a);
    for (std::int64_t x = std::max<std::int64_t>(0, ax - hreach);
         x <= std::min<std::int64_t>(ax + hreach, static_cast<std::int64_t>(nx) - 1); ++x) {
      const float gx = gap_at[x - ax];
      for (std::int64_t y = std::max<std::int64_t>(0, ay - hreach);
           y <= std::min<std::int64_t>(ay + hreach, static_cast<std::int64_t>(ny) - 1); ++y) {
        const auto col = static_cast<std::size_t>(x) * ny + static_cast<std::size_t>(y);
        std::uint32_t b = col_cells_[col];
        const std::uint32_t last = col_cells_[col + 1];
        if (b == last) continue;  // an empty column (most are)
        const std::uint32_t low = col_low[col];
        if (!below(cells_[low], low, ca, a)) continue;
        const float gy = gap_at[y - ay];
        const float gxy = gx * gx + gy * gy;
        if (!(gxy < hreach2) || !within(gxy, 0)) continue;
        // The largest |dz| within reach: first guessed from the ellipse (the gap of d cells is (d - 1) * edge),
        // then settled by the test itself, so exactly the run the test allows.
        const float room2 = aniso ? reach2 * (1.F - gxy / hreach2) : reach2 - gxy;
        std::int64_t lim = room2 > 0.F ? static_cast<std::int64_t>(std::sqrt(room2) * inv) + 1 : 0;
        lim = std::min(lim, reach);
        while (lim > 0 && !within(gxy, lim)) --lim;
        while (lim < reach && within(gxy, lim + 1)) ++lim;
        const auto z_lo = az - lim, z_hi = az_top + lim;
        while (b < last && static_cast<std::int64_t>(cells_[b].iz_top) < z_lo) ++b;
        for (; b < last; ++b) {
          const Cell& cb = cells_[b];
          if (static_cast<std::int64_t>(cb.iz) > z_hi) break;  // cells of a column ascend in z
          // b looks for a (or b is a)
          if (!below(cb, b, ca, a)) continue;
          const std::uint32_t rb = find_root(parent, b);
          if (ra == rb) continue;
          // The gap between the two cells' point boxes on each axis, taken short by kSlack: no two of their
          // points are nearer. Beyond a's radii there (b's are no larger), none of their pairs joins: many cells
          // a column's z run reaches only by the lattice (a far wall's tall cells, its edge columns) end here.
          const float* const bbox = cell_box_.data() + 6 * static_cast<std::size_t>(b);
          const auto box_gap = [&](int k) {
            return std::max(0.F, std::max(bbox[k] - abox[k + 3], abox[k] - bbox[k + 3]) - kSlack);
          };
          const float bx = box_gap(0), by = box_gap(1), bz = box_gap(2);
          const float bxy2 = bx * bx + by * by;
          if (!(aniso ? joins_anisotropic(bxy2, bz * bz, hreach2, reach2) : bxy2 + bz * bz < reach2)) continue;
          if (cells_join(a0, a1, cb.first, cells_[b + 1].first, sx, sy, sz, r2, h2, aniso)) {
            parent[std::max(ra, rb)] = std::min(ra, rb);
            ra = std::min(ra, rb);
          }
        }
      }
    }
  }

  // Clusters in the order of their lowest point index, members ascending: one pass in index order.
  // A cell's parent is never after it (a join points the later root at the earlier one, and path halving
  // at an ancestor), so one pass in cell order points every cell at its root.
  cluster_of_root_.assign(ncells, kNoCluster);
  pos_of_.resize(n);  // root cell of each point
  for (std::uint32_t c = 0; c < ncells; ++c) {
    parent[c] = parent[parent[c]];
    for (std::uint32_t j = cells_[c].first; j < cells_[c + 1].first; ++j) pos_of_[gp[j].index] = parent[c];
  }
  std::uint32_t clusters = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t& id = cluster_of_root_[pos_of_[i]];
    if (id == kNoCluster) id = clusters++;
    cell_of_[i] = id;
  }
  group_points({cell_of_.data(), n}, clusters, kNoCluster, out, col_next_);
}

void group_points(std::span<const std::uint32_t> cluster_of_point, std::uint32_t count, std::uint32_t none,
                  Clusters& out, Buffer<std::uint32_t>& scratch) {
  scratch.assign(count, 0U);  // the size of each cluster, then where its next member goes
  std::size_t members = 0;
  for (const std::uint32_t c : cluster_of_point) {
    if (c == none) continue;
    ++scratch[c];
    ++members;
  }
  out.offsets.resize(count + 1);
  out.offsets[0] = 0;
  for (std::uint32_t c = 0; c < count; ++c) out.offsets[c + 1] = out.offsets[c] + scratch[c];
  out.indices.resize(members);
  for (std::uint32_t c = 0; c < count; ++c) scratch[c] = out.offsets[c];
  for (std::size_t i = 0; i < cluster_of_point.size(); ++i) {
    const std::uint32_t c = cluster_of_point[i];
    if (c != none) out.indices[scratch[c]++] = static_cast<std::uint32_t>(i);
  }
}

void merge_clusters(std::span<const std::uint32_t> target, std::size_t points, Clusters& clusters,
                    Buffer<std::uint32_t>& of_point, Buffer<std::uint32_t>& id, Buffer<std::uint32_t>& scratch) {
  constexpr std::uint32_t kNone = 0xFFFFFFFFU;
  const std::size_t nc = clusters.size();
  of_point.assign(points, kNone);
  for (std::size_t c = 0; c < nc; ++c) {
    for (const std::uint32_t i : clusters[c]) of_point[i] = target[c];
  }
  group_by_first_point(of_point, static_cast<std::uint32_t>(nc), kNone, clusters, id, scratch);
}

void group_by_first_point(Buffer<std::uint32_t>& of_point, std::uint32_t labels, std::uint32_t none, Clusters& out,
                          Buffer<std::uint32_t>& id, Buffer<std::uint32_t>& scratch) {
  id.assign(labels, none);
  std::uint32_t count = 0;
  for (std::uint32_t& label : of_point) {
    if (label == none) continue;
    std::uint32_t& k = id[label];
    if (k == none) k = count++;
    label = k;
  }
  group_points({of_point.data(), of_point.size()}, count, none, out, scratch);
}

}  // namespace fieldguard::perception
