// EuclideanClusterer over a grid of cells (ClusterStructure::Grid): the same clusters as the k-d tree.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>

#include "fieldguard/perception/euclidean_cluster.hpp"
#include "perception/euclidean_cluster_radius.hpp"
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

using u32x4 = std::uint32_t __attribute__((vector_size(16)));

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

// Cells: cubes of edge a bit under tolerance / sqrt(3), so that any two points of one cell are nearer than the
// smallest radius and join. A cell is therefore a piece of one cluster, and clustering is union-find over
// cells: two neighbouring cells join when any pair of their points is within the pair's radius (the test
// stops at the first such pair, and is skipped when the two are already joined or the boxes of their points lie
// beyond reach). A dense surface (a wall, a shed's roof) thus costs a few tests per cell instead of a radius
// search per point. The connected components are those of the point graph, so the clusters are exactly the
// k-d tree's.
void EuclideanClusterer::extract_grid(const Cloud& in, Clusters& out) {
  const std::size_t n = in.size();
  // Bounds, four points at a time. x - x is 0 for a finite x and NaN for anything else, so one running sum
  // per axis tells whether every coordinate is finite (the min and max pass over a NaN; the sum does not).
  float lo[3] = {in.x[0], in.y[0], in.z[0]};
  float hi[3] = {lo[0], lo[1], lo[2]};
  bool finite = true;
  {
    const float* axis[3] = {in.x.data(), in.y.data(), in.z.data()};
    const std::size_t n4 = n & ~std::size_t{3};
    for (int k = 0; k < 3; ++k) {
      const float* v = axis[k];
      simd::f32x4 mn = simd::splat(lo[k]), mx = mn, bad = simd::splat(0.F);
      for (std::size_t i = 0; i < n4; i += 4) {
        const simd::f32x4 q = simd::load(v + i);
        mn = q < mn ? q : mn;
        mx = q > mx ? q : mx;
        bad += q - q;
      }
      float b = 0.F;
      for (int l = 0; l < 4; ++l) {
        lo[k] = std::min(lo[k], mn[l]);
        hi[k] = std::max(hi[k], mx[l]);
        b += bad[l];
      }
      for (std::size_t i = n4; i < n; ++i) {
        lo[k] = std::min(lo[k], v[i]);
        hi[k] = std::max(hi[k], v[i]);
        b += v[i] - v[i];
      }
      finite = finite && b == 0.F;
    }
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
    prepare(in);
    extract_kdtree(in, out);
    return;
  }
  const float inv = 1.F / edge;
  const auto cell = [inv](float v, float origin) {
    return static_cast<std::uint32_t>(static_cast<std::int32_t>((v - origin) * inv));  // >= 0: v >= origin
  };

  // Points in grid order (by x-y column, and within a column by z cell): two stable counting sorts of point
  // indices, by z cell and then by column, as an LSD radix sort. The column histogram goes two places up, so
  // that after the scatter (which moves each column's cursor from its start to its end) col_start_[c] is
  // column c's start.
  const std::size_t cols = nx * ny;
  const auto nz_top = static_cast<std::uint32_t>(nz_d);
  col_start_.assign(cols + 2, 0U);
  z_start_.assign(std::size_t{nz_top} + 2, 0U);
  cell_of_.resize(n);  // column of each point
  z_of_.resize(n);     // z cell of each point
  using simd::f32x4;
  const f32x4 vinv = simd::splat(inv), lx = simd::splat(lo[0]), ly = simd::splat(lo[1]), lz = simd::splat(lo[2]);
  const auto top_x = static_cast<std::uint32_t>(nx - 1), top_y = static_cast<std::uint32_t>(ny - 1);
  const auto vtop_x = simd::splat(static_cast<std::int32_t>(top_x));
  const auto vtop_y = simd::splat(static_cast<std::int32_t>(top_y));
  const auto vtop_z = simd::splat(static_cast<std::int32_t>(nz_top));
  // Four points at a time: lane by lane the operations of the scalar `cell`, so the same cells to the bit. Every
  // value is finite here, and a cell index is below max_cols, far from the top bit: the conversions see nothing
  // out of range, and the signed minimum (SSE2 has a signed compare, not an unsigned one) is the unsigned one.
  const auto cells = [&](f32x4 v, f32x4 origin, simd::i32x4 top) {
    const auto c = __builtin_convertvector((v - origin) * vinv, simd::i32x4);
    return __builtin_convertvector(c < top ? c : top, u32x4);
  };
  std::size_t i4 = 0;
  {
    const auto ny32 = static_cast<std::uint32_t>(ny);
    const u32x4 vny = {ny32, ny32, ny32, ny32};
    for (; i4 + 4 <= n; i4 += 4) {
      const f32x4 x = simd::load(in.x.data() + i4), y = simd::load(in.y.data() + i4), z = simd::load(in.z.data() + i4);
      const u32x4 c = cells(x, lx, vtop_x) * vny + cells(y, ly, vtop_y);
      const u32x4 iz = cells(z, lz, vtop_z);
      std::memcpy(cell_of_.data() + i4, &c, sizeof c);
      std::memcpy(z_of_.data() + i4, &iz, sizeof iz);
    }
  }
  for (std::size_t i = i4; i < n; ++i) {
    const std::size_t c =
        std::min<std::size_t>(cell(in.x[i], lo[0]), nx - 1) * ny + std::min<std::size_t>(cell(in.y[i], lo[1]), ny - 1);
    cell_of_[i] = static_cast<std::uint32_t>(c);
    z_of_[i] = std::min(cell(in.z[i], lo[2]), nz_top);
  }
  for (std::size_t i = 0; i < n; ++i) {
    ++col_start_[std::size_t{cell_of_[i]} + 2];
    ++z_start_[std::size_t{z_of_[i]} + 1];
  }
  for (std::size_t c = 2; c < cols + 2; ++c) col_start_[c] += col_start_[c - 1];
  for (std::size_t z = 1; z <= nz_top; ++z) z_start_[z] += z_start_[z - 1];
  by_z_.resize(n);
  for (std::size_t i = 0; i < n; ++i) by_z_[z_start_[z_of_[i]]++] = static_cast<std::uint32_t>(i);
  grid_index_.resize(n);
  for (const std::uint32_t i : by_z_) grid_index_[col_start_[cell_of_[i] + 1]++] = i;

  // The points in grid order, one array each, padded by four (the pair test and the loops below read four at a
  // time): coordinates gathered, then four at a time their z cells again and their radii squared, in the same
  // operations as the scalar RadiusModel and std::sqrt, so the same cells and radii to the bit; and each point's
  // x, y, z and 3D range (0 unless adaptive) side by side, for the cell boxes.
  grid_xyz_.resize(5 * (n + 4));
  float* const sx = grid_xyz_.data();
  float* const sy = sx + n + 4;
  float* const sz = sy + n + 4;
  float* const r2 = sz + n + 4;  // vertical radius squared (the only one unless anisotropic)
  float* const h2 = anisotropic_ ? r2 + n + 4 : r2;
  grid_z_.resize(n + 4);
  std::uint32_t* const gz = grid_z_.data();
  grid_point_.resize(4 * (n + 4));
  float* const gp = grid_point_.data();
  {
    const std::uint32_t* const gi = grid_index_.data();
    const float* const px = in.x.data();
    const float* const py = in.y.data();
    const float* const pz = in.z.data();
    for (std::size_t j = 0; j < n; ++j) {
      const std::uint32_t i = gi[j];
      sx[j] = px[i];
      sy[j] = py[i];
      sz[j] = pz[i];
    }
  }
  for (std::size_t j = n; j < n + 4; ++j) {  // the padding at the lowest corner: its z cell is in range below
    sx[j] = lo[0];
    sy[j] = lo[1];
    sz[j] = lo[2];
  }
  const RadiusModel rm = radius_model();
  {
    const f32x4 vt = simd::splat(rm.t), base_r2 = simd::splat(rm.base_r2);
    const f32x4 gv = simd::splat(rm.gv), cap_v = simd::splat(rm.cap_v), gh = simd::splat(rm.gh);
    const f32x4 cap_h = simd::splat(rm.cap_h);
    const auto grow4 = [&](f32x4 g, f32x4 cap, f32x4 range) {
      const f32x4 gr = g * range;
      const f32x4 m = vt < gr ? gr : vt;  // std::max(t, g * range)
      return m < cap ? m : cap;           // std::min(cap, that)
    };
    const auto squared4 = [&](f32x4 radius) { return radius == vt ? base_r2 : radius * radius; };
    const bool adaptive = adaptive_;
    const auto fv = static_cast<float>(params_.beam_factor);
    for (std::size_t j = 0; j < n; j += 4) {  // the last four may run into the padding: n + 4 long
      f32x4 x = simd::load(sx + j), y = simd::load(sy + j), z = simd::load(sz + j);
      const u32x4 iz = cells(z, lz, vtop_z);
      std::memcpy(gz + j, &iz, sizeof iz);
      f32x4 range = simd::splat(0.F);
      if (adaptive) {
        const f32x4 sq = x * x + y * y + z * z;
#if defined(__SSE2__)
        range = _mm_sqrt_ps(sq);  // correctly rounded, as std::sqrt
#else
        range = f32x4{std::sqrt(sq[0]), std::sqrt(sq[1]), std::sqrt(sq[2]), std::sqrt(sq[3])};
#endif
        f32x4 lane_gv = gv;
        if (per_point_) {  // each point's vertical growth from its elevation (uneven rings)
          for (int k = 0; k < 4; ++k) lane_gv[k] = growth_at(fv, range[k] > 0.F ? z[k] / range[k] : 0.F);
        }
        const f32x4 v2 = squared4(grow4(lane_gv, cap_v, range));
        const f32x4 hv2 = rm.aniso ? squared4(grow4(gh, cap_h, range)) : v2;
        std::memcpy(r2 + j, &v2, sizeof v2);
        std::memcpy(h2 + j, &hv2, sizeof hv2);
      } else {
        std::memcpy(r2 + j, &base_r2, sizeof base_r2);
      }
      simd::transpose4(x, y, z, range);
      std::memcpy(gp + 4 * j, &x, sizeof x);
      std::memcpy(gp + 4 * j + 4, &y, sizeof y);
      std::memcpy(gp + 4 * j + 8, &z, sizeof z);
      std::memcpy(gp + 4 * j + 12, &range, sizeof range);
    }
    for (std::size_t j = n; j < n + 4; ++j) r2[j] = h2[j] = 0.F;
  }

  // Cells: runs of k z cells in a column. Far out the radii are larger than the cube's diagonal: a column whose
  // every point is at least rmin away (horizontally, so in 3D too) may stack k z cells into one taller cell
  // whose points still all join with the smallest radii at rmin (each axis's extent taken 2 * rounding long).
  // Fewer, taller cells: far walls cost fewer cell pairs. One pass over the columns makes their cells with their
  // point boxes and farthest range.
  // With uneven rings the smallest growths: what every point of a column is sure to have.
  RadiusModel rm_min = rm;
  rm_min.gv = min_growth_;
  rm_min.gh = min_growth_h_;
  const double e = static_cast<double>(edge), rho2 = 2.0 * static_cast<double>(rounding);
  const auto stack_of = [&](std::size_t c) -> std::uint32_t {
    if (!adaptive_) return 1;
    const std::size_t column_x = c / ny;  // the column's x and y cells
    const std::size_t column_y = c % ny;
    const double x0 = static_cast<double>(lo[0]) + static_cast<double>(column_x) * e - rho2;
    const double y0 = static_cast<double>(lo[1]) + static_cast<double>(column_y) * e - rho2;
    const double dx = std::max({0.0, x0, -(x0 + e + 2.0 * rho2)});
    const double dy = std::max({0.0, y0, -(y0 + e + 2.0 * rho2)});
    const auto rmin = static_cast<float>(std::sqrt(dx * dx + dy * dy));
    const auto v = static_cast<double>(rm_min.v(rmin));
    const auto h = static_cast<double>(rm_min.h(rmin));
    const double across = 2.0 * (e + rho2) * (e + rho2) / (h * h);
    if (!(across < 0.998)) return 1;
    const double height = std::sqrt((0.998 - across) * v * v) - rho2;  // the tallest cell allowed
    return static_cast<std::uint32_t>(std::clamp(std::floor(height / e), 1.0, 64.0));
  };
  cells_.resize(n + 1);   // at most a cell a point, and the end sentinel
  cell_z_.resize(n + 4);  // and room for the row scan's four-wide reads past the last cell (see below)
  cell_box_.resize(8 * n);
  col_cells_.resize(cols + 1);
  Cell* const cl = cells_.data();
  ZSpan* const zspan = cell_z_.data();
  float* const boxes = cell_box_.data();  // per cell: min x, y, z, (unused), max x, y, z, range
  pos_of_.resize(n);                      // the cell of each point (by cloud index), and at the end its root cell
  std::uint32_t ncells = 0;
  {
    const std::uint32_t* const gi = grid_index_.data();
    std::uint32_t* const pos = pos_of_.data();
    // A column's cells, without a branch on where a cell begins (about every fifth point, unpredictably): each
    // point writes the next cell's slot as if it opened one, and moves the count on only if it does (a later
    // opener or the sentinel below overwrites what the others left there), and its cell's box so far.
    // `bottom_of`: the lowest z cell of a z cell's stack of k.
    const auto column = [&](std::uint32_t c, std::uint32_t b, std::uint32_t end, std::uint32_t k, auto bottom_of)
        __attribute__((always_inline)) {
      std::uint32_t next = 0;  // the z cell after the current cell's last: each column's first point opens one
      f32x4 mn = simd::splat(0.F), mx = mn;
      std::uint32_t nc = ncells;
      float* box = boxes + 8 * std::size_t{nc} - 8;  // the current cell's
      for (std::uint32_t j = b; j < end; ++j) {
        const std::uint32_t iz = gz[j];
        const std::uint32_t bottom = bottom_of(iz);
        // Whether this point opens a cell, 1 or 0, and all that follows in arithmetic: g++ makes a conditional
        // of it a branch, mispredicted at most cells' first point.
        const std::uint32_t opens = iz >= next ? 1U : 0U;
        next ^= (next ^ (bottom + k)) & (0U - opens);
        cl[nc].first = j;
        cl[nc].col = c;
        zspan[nc] = ZSpan{bottom, bottom + k - 1};
        nc += opens;
        box += 8 * std::size_t{opens};
        // std::min(box, p) and std::max(box, p) lane by lane, or p itself for a new cell: minps and maxps give
        // their second operand where the first is NaN, which all bits set is.
        const f32x4 p = simd::load(gp + 4 * std::size_t{j});
        const simd::i32x4 fresh = simd::splat(-static_cast<std::int32_t>(opens));
        mn = simd::min_or_bound(std::bit_cast<f32x4>(std::bit_cast<simd::i32x4>(mn) | fresh), p);
        mx = simd::max_or_bound(std::bit_cast<f32x4>(std::bit_cast<simd::i32x4>(mx) | fresh), p);
        std::memcpy(box, &mn, sizeof mn);
        std::memcpy(box + 4, &mx, sizeof mx);
        pos[gi[j]] = nc - 1;
      }
      ncells = nc;
    };
    for (std::size_t c = 0; c < cols; ++c) {
      // Most columns are empty: four at a time where all four are (their starts all equal the next one's).
      while (c + 5 <= cols + 1) {
        u32x4 starts, nexts;
        std::memcpy(&starts, col_start_.data() + c, sizeof starts);
        std::memcpy(&nexts, col_start_.data() + c + 1, sizeof nexts);
        if (simd::mask_bits(starts == nexts) != 0xFU) break;
        const u32x4 here = {ncells, ncells, ncells, ncells};
        std::memcpy(col_cells_.data() + c, &here, sizeof here);
        c += 4;
      }
      if (c == cols) break;
      col_cells_[c] = ncells;
      const std::uint32_t b = col_start_[c], end = col_start_[c + 1];
      if (b == end) continue;
      const std::uint32_t k = stack_of(c);
      const auto c32 = static_cast<std::uint32_t>(c);
      if (k == 1) {
        column(c32, b, end, 1U, [](std::uint32_t iz) { return iz; });
      } else {
        column(c32, b, end, k, [k](std::uint32_t iz) { return iz - iz % k; });
      }
    }
  }
  col_cells_[cols] = ncells;
  cl[ncells].first = static_cast<std::uint32_t>(n);  // sentinel: the end of the last cell
  // Each cell's largest radii: those of its farthest point (the radii only grow with range).
  for (std::uint32_t c = 0; c < ncells; ++c) {
    const float range = boxes[8 * std::size_t{c} + 7];
    cl[c].reach2 = adaptive_ ? rm.squared(rm.v(range)) : base_r2_;
    cl[c].hreach2 = adaptive_ ? rm.squared(rm.h(range)) : base_r2_;
  }
  if (per_point_) {  // uneven rings: each point has its own growth, so the largest of the cell's own radii
    for (std::uint32_t c = 0; c < ncells; ++c) {
      float v2 = 0.F, hv2 = 0.F;
      for (std::uint32_t j = cl[c].first; j < cl[c + 1].first; ++j) {
        v2 = std::max(v2, r2[j]);
        hv2 = std::max(hv2, h2[j]);
      }
      cl[c].reach2 = v2;
      cl[c].hreach2 = hv2;
    }
  }

  // Joins. Each cell looks back at the cells before it in cell order (x column, y column, z) within its
  // stencil: a half-space, so each cell pair is looked at once. The other cell's radii may be the larger, so
  // the stencil holds every cell a point of this one may join at all: a point at range R joins only points
  // within D = max(its own radii, min(cap, g R / (1 - g))) (as the k-d tree's search radius, see prepare), so
  // the pair's radii are at most those at R + D, R the cell's farthest point. The box pretest and the point
  // test then take each pair's own radii. Dense surfaces join early and most pairs end at the union-find check.
  parent_.resize(ncells);
  std::uint32_t* const parent = parent_.data();
  for (std::uint32_t c = 0; c < ncells; ++c) parent[c] = c;
  const bool aniso = anisotropic_;
  const float gq = anisotropic_ ? std::max(growth_, growth_h_) : growth_;
  const float capq = anisotropic_ ? std::max(cap_, cap_h_) : cap_;
  const float gq_reach = gq / (1.F - gq);
  const ZSpan* const zs = cell_z_.data();
  // Each cell's stencil: cells up to hreach columns apart on x and on y, and z cells [z_lo, z_hi] (the gap
  // between two cells d apart is (d - 1) edges, less rounding, under kSlack).
  stencil_.resize(ncells);
  Stencil* const st = stencil_.data();
  for (std::uint32_t a = 0; a < ncells; ++a) {
    float hs = t, vs = t;  // the stencil's horizontal and vertical radius
    if (adaptive_) {
      const float r = boxes[8 * std::size_t{a} + 7];  // the cell's farthest point's range
      const float far = r + std::max(std::max(rm.v(r), rm.h(r)), std::min(capq, gq_reach * r));
      hs = rm.h(far);
      vs = rm.v(far);
    }
    const auto hreach = static_cast<std::uint32_t>((hs + kSlack) * inv) + 1;
    const auto reach = static_cast<std::uint32_t>((vs + kSlack) * inv) + 1;
    st[a] = Stencil{hreach, zs[a].iz > reach ? zs[a].iz - reach : 0U, zs[a].iz_top + reach};
  }
  // Whether cell a joins cell b (b before a, in a's stencil), and if so the join: ra is a's root, kept up to date.
  const auto visit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t & ra) __attribute__((always_inline)) {
    // Many cells that get here are in a's cluster already, pointing straight at its root: that ends here without
    // the walk. (Skipping the walk's path halving changes which ancestor a cell points at, never its root: the
    // clusters are the same.)
    if (parent[b] == ra) return;
    const std::uint32_t rb = find_root(parent, b);
    if (ra == rb) return;
    // The gap between the two cells' point boxes on each axis, taken short by kSlack: no two of their points
    // are nearer. Beyond the two cells' largest radii there, none of their pairs joins: many cells the
    // stencil's corners reach end here.
    const Cell& ca = cl[a];
    const Cell& cb = cl[b];
    const float* const abox = boxes + 8 * static_cast<std::size_t>(a);
    const float* const bbox = boxes + 8 * static_cast<std::size_t>(b);
    // std::max(0, std::max(b_lo - a_hi, a_lo - b_hi) - kSlack) on the three axes at once.
    const f32x4 gap = simd::max_or_bound(
        simd::max_or_bound(simd::load(abox) - simd::load(bbox + 4), simd::load(bbox) - simd::load(abox + 4)) -
            simd::splat(kSlack),
        simd::splat(0.F));
    const float bx = gap[0], by = gap[1], bz = gap[2];
    const float bxy2 = bx * bx + by * by;
    const float v2 = std::max(ca.reach2, cb.reach2);
    if (!(aniso ? joins_anisotropic(bxy2, bz * bz, std::max(ca.hreach2, cb.hreach2), v2) : bxy2 + bz * bz < v2)) {
      return;
    }
    if (cells_join(ca.first, cl[a + 1].first, cb.first, cl[b + 1].first, sx, sy, sz, r2, h2, aniso)) {
      parent[std::max(ra, rb)] = std::min(ra, rb);
      ra = std::min(ra, rb);
    }
  };
  // Column by column. Within a column, each cell looks at the cells below it, nearest first. Then each column
  // before it in the stencil of any of its cells, nearest first: a pair of columns each in one cluster (a column
  // never leaves a cluster it is in whole: joins only merge) and in the same one is passed over whole, most of
  // them on a dense surface; else each of the column's cells looks at that column's cells in its stencil.
  col_rep_.resize(cols);  // per column, once done: a cell of it if all its cells are in one cluster, else kNoCluster
  std::uint32_t* const rep = col_rep_.data();
  const auto ny32 = static_cast<std::uint32_t>(ny);
  for (std::uint32_t a_begin = 0; a_begin < ncells;) {
    const std::uint32_t col = cl[a_begin].col;
    const std::uint32_t a_end = col_cells_[std::size_t{col} + 1];
    const std::uint32_t ax = col / ny32, ay = col % ny32;
    std::uint32_t hmax = 0;
    // The column's own joins, each cell with those below it. While the cells so far are in one cluster, a cell
    // that joins the one below it is in that cluster with all of them: nothing more to look at.
    bool one = true;  // cells [a_begin, a) are in one cluster
    for (std::uint32_t a = a_begin; a < a_end; ++a) {
      hmax = std::max(hmax, st[a].hreach);
      std::uint32_t ra = a;  // a is alone until it looks (only later cells look at it)
      std::uint32_t b = a;
      if (b > a_begin && zs[b - 1].iz_top >= st[a].z_lo) {
        visit(a, --b, ra);
        if (one && ra != a) continue;
      }
      for (; b > a_begin && zs[b - 1].iz_top >= st[a].z_lo;) visit(a, --b, ra);
      one = a == a_begin || (one && ra != a && ra == find_root(parent, a_begin));
    }
    // Whether all of this column's cells are in one cluster: its root, else kNoCluster.
    const auto column_root = [&]() {
      const std::uint32_t r = find_root(parent, a_begin);
      for (std::uint32_t a = a_begin + 1; a < a_end; ++a) {
        if (parent[a] != r && find_root(parent, a) != r) return kNoCluster;
      }
      return r;
    };
    std::uint32_t a_root = one ? find_root(parent, a_begin) : column_root();
    // The column's cells with those of column bcol's [b_begin, b_end) in their stencils (dx, dy columns apart).
    const auto with = [&](std::uint32_t bcol, std::uint32_t b_begin, std::uint32_t b_end, std::uint32_t dx,
                          std::uint32_t dy) __attribute__((always_inline)) {
      const std::uint32_t b_rep = rep[bcol];
      std::uint32_t b_root = b_rep == kNoCluster ? kNoCluster : find_root(parent, b_rep);
      if (a_root != kNoCluster && a_root == b_root) return;
      bool joined = false;
      for (std::uint32_t a = a_begin; a < a_end; ++a) {
        const Stencil s = st[a];
        if (dx > s.hreach || dy > s.hreach) continue;
        std::uint32_t ra = find_root(parent, a);
        if (ra == b_root) continue;
        const std::uint32_t before = ra;
        for (std::uint32_t b = b_begin; b < b_end && zs[b].iz <= s.z_hi; ++b) {
          if (zs[b].iz_top < s.z_lo) continue;
          visit(a, b, ra);
          if (ra != before && b_root != kNoCluster) break;  // all of column bcol is in a's cluster now
        }
        if (ra == before) continue;
        joined = true;
        if (b_root != kNoCluster) {
          b_root = ra;                 // the joined cluster's root: a's and b's, whichever is lower
          if (a_root != kNoCluster) {  // both columns whole in one cluster
            a_root = ra;
            return;
          }
        }
      }
      if (joined) a_root = column_root();
    };
    // The columns before it within the stencils, nearest first: its row's (backwards), then the rows before, in
    // order; only the columns with cells, found through the cells (each column's cells follow the last's).
    const std::uint32_t y0 = ay > hmax ? ay - hmax : 0U, y1 = std::min(ay + hmax, ny32 - 1);
    {
      const std::uint32_t row = ax * ny32;
      const std::uint32_t first = col_cells_[std::size_t{row} + y0];
      for (std::uint32_t b = a_begin; b > first;) {
        const std::uint32_t bcol = cl[b - 1].col;
        const std::uint32_t b_begin = col_cells_[bcol];
        with(bcol, b_begin, b, 0U, col - bcol);
        b = b_begin;
      }
    }
    for (std::uint32_t x = ax > hmax ? ax - hmax : 0U; x < ax; ++x) {
      const std::uint32_t row = x * ny32;
      const std::uint32_t last = col_cells_[std::size_t{row} + y1 + 1];
      for (std::uint32_t b = col_cells_[std::size_t{row} + y0]; b < last;) {
        const std::uint32_t bcol = cl[b].col;
        const std::uint32_t b_end = col_cells_[std::size_t{bcol} + 1];
        const std::uint32_t by = bcol - row;
        with(bcol, b, b_end, ax - x, ay > by ? ay - by : by - ay);
        b = b_end;
      }
    }
    rep[col] = a_root == kNoCluster ? kNoCluster : a_begin;
    a_begin = a_end;
  }

  // Clusters in the order of their lowest point index, members ascending. A cell's parent is never after it
  // (a join points the later root at the earlier one, and path halving at an ancestor), so one pass in cell
  // order points every cell at its root and adds its size to the root's. Then one pass over the points in
  // index order: a root first met (the root of the point's cell) opens the next cluster (its offset known from
  // the size), and each point goes to its root's next slot.
  root_size_.assign(ncells, 0U);
  for (std::uint32_t c = 0; c < ncells; ++c) {
    parent[c] = parent[parent[c]];
    root_size_[parent[c]] += cl[c + 1].first - cl[c].first;
  }
  cluster_of_root_.assign(ncells, kNoCluster);  // then the root's next slot in out.indices
  out.indices.resize(n);
  std::uint32_t opened = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t r = parent[pos_of_[i]];
    std::uint32_t& slot = cluster_of_root_[r];
    if (slot == kNoCluster) {
      slot = opened;
      opened += root_size_[r];
      out.offsets.push_back(opened);
    }
    out.indices[slot++] = static_cast<std::uint32_t>(i);
  }
}

}  // namespace fieldguard::perception
