#include "fieldguard/perception/voxel_grid.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "perception/simd.hpp"

namespace fieldguard::perception {
namespace {

// Voxel coordinates are packed in 20 bits each (offset by 2^19), the range band in the top 4 bits, so no key
// is all ones: that marks an empty ring-cache entry.
constexpr std::int32_t kCoordOffset = 1 << 19;
constexpr float kCoordLimit = 524287.0F;  // 2^19 - 1: coordinates beyond are clamped (5 km at a 1 cm leaf)
constexpr std::uint32_t kMaxBands = 15;
constexpr std::uint64_t kNoKey = ~std::uint64_t{0};

// floor() to int for the voxel index, as pcl::VoxelGrid's static_cast<int>(std::floor(x * inverse_leaf)),
// without the libm call; NaN maps to the lower bound.
inline std::int32_t voxel_coord(float v) {
  v = v >= -kCoordLimit ? v : -kCoordLimit;
  v = v <= kCoordLimit ? v : kCoordLimit;
  const auto i = static_cast<std::int32_t>(v);
  return i - static_cast<std::int32_t>(v < static_cast<float>(i));
}

inline std::uint64_t pack(std::int32_t ix, std::int32_t iy, std::int32_t iz, std::uint32_t band) {
  return (static_cast<std::uint64_t>(band) << 60U) | (static_cast<std::uint64_t>(ix + kCoordOffset) << 40U) |
         (static_cast<std::uint64_t>(iy + kCoordOffset) << 20U) | static_cast<std::uint64_t>(iz + kCoordOffset);
}

constexpr std::size_t kBlock = 16;  // points whose keys are computed together

// The constants of block_keys(), splatted once per frame rather than once per block.
struct KeyLanes {
  simd::f32x4 inv_leaf, lo, hi;
  explicit KeyLanes(float s) : inv_leaf(simd::splat(s)), lo(simd::splat(-kCoordLimit)), hi(simd::splat(kCoordLimit)) {}
};

// Keys of kBlock points with one leaf, four at a time, clamped to the key's range.
inline void block_keys(const float* x, const float* y, const float* z, const KeyLanes& c, std::uint64_t* keys) {
  for (std::size_t b = 0; b < kBlock; b += 4) {
    const simd::i32x4 ix = simd::floor_clamped(simd::load(x + b) * c.inv_leaf, c.lo, c.hi);
    const simd::i32x4 iy = simd::floor_clamped(simd::load(y + b) * c.inv_leaf, c.lo, c.hi);
    const simd::i32x4 iz = simd::floor_clamped(simd::load(z + b) * c.inv_leaf, c.lo, c.hi);
    if constexpr (std::endian::native == std::endian::little) {
      // pack(x, y, z, 1) four at a time: the keys' low and high 32-bit halves, interleaved into 64 bits.
      using u32x4 = std::uint32_t __attribute__((vector_size(16)));
      const auto o = static_cast<std::uint32_t>(kCoordOffset);
      const u32x4 ux = __builtin_convertvector(ix, u32x4) + o;
      const u32x4 uy = __builtin_convertvector(iy, u32x4) + o;
      const u32x4 uz = __builtin_convertvector(iz, u32x4) + o;
      const u32x4 lo = (uy << 20U) | uz;
      const u32x4 hi = (ux << 8U) | (uy >> 12U) | (1U << 28U);  // band 1 in the top 4 bits
      const u32x4 k01 = __builtin_shufflevector(lo, hi, 0, 4, 1, 5);
      const u32x4 k23 = __builtin_shufflevector(lo, hi, 2, 6, 3, 7);
      std::memcpy(keys + b, &k01, sizeof k01);
      std::memcpy(keys + b + 2, &k23, sizeof k23);
    } else {
      std::int32_t vx[4], vy[4], vz[4];
      std::memcpy(vx, &ix, sizeof vx);
      std::memcpy(vy, &iy, sizeof vy);
      std::memcpy(vz, &iz, sizeof vz);
      for (std::size_t k = 0; k < 4; ++k) keys[b + k] = pack(vx[k], vy[k], vz[k], 1);
    }
  }
}

inline std::uint32_t slot_of(std::uint64_t key, std::uint32_t shift) {
  return static_cast<std::uint32_t>((key * 0x9E3779B97F4A7C15ULL) >> shift);
}

std::uint32_t log2_ceil(std::size_t n) {
  std::uint32_t b = 0;
  while ((std::size_t{1} << b) < n) ++b;
  return b;
}

}  // namespace

VoxelGrid::VoxelGrid(const VoxelParams& params) : params_(params) {
  if (!(params_.leaf_m > 0.0) || !std::isfinite(params_.leaf_m)) {
    throw std::invalid_argument("VoxelGrid: leaf_m must be positive");
  }
  coarse_ = params_.coarse_from_m > 0.0;
  if (coarse_ && !(params_.max_leaf_m >= params_.leaf_m)) {
    throw std::invalid_argument("VoxelGrid: max_leaf_m must not be less than leaf_m");
  }
  // Leaf per range band: band b (1-based) uses leaf * b, capped; without coarsening, one band.
  if (coarse_) {
    bands_ = static_cast<std::uint32_t>(
        std::clamp(std::ceil(params_.max_leaf_m / params_.leaf_m - 1e-9), 1.0, static_cast<double>(kMaxBands)));
    inv_band_range_ = static_cast<float>(1.0 / params_.coarse_from_m);
  }
  for (std::uint32_t b = 1; b <= bands_; ++b) {
    const double leaf = std::min(params_.leaf_m * b, coarse_ ? params_.max_leaf_m : params_.leaf_m);
    inv_[b] = 1.0F / static_cast<float>(leaf);  // as pcl::VoxelGrid: the inverse leaf in float
  }
}

std::uint64_t VoxelGrid::coarse_key(float x, float y, float z) const {
  const float r = std::sqrt(x * x + y * y) * inv_band_range_;
  const std::uint32_t band = r >= static_cast<float>(bands_) ? bands_ : std::max(1U, static_cast<std::uint32_t>(r));
  const float s = inv_[band];
  return pack(voxel_coord(x * s), voxel_coord(y * s), voxel_coord(z * s), band);
}

// The table holds voxel ids offset by this frame's base: a slot is taken when its id minus the base is below
// the voxel count, so a new frame (a new base) empties it without touching it.
__attribute__((noinline, cold)) void VoxelGrid::grow_table() {
  const std::size_t size = std::max<std::size_t>(1024, table_.size() * 2);
  table_.assign(size, 0U);
  mask_ = static_cast<std::uint32_t>(size - 1);
  shift_ = 64U - log2_ceil(size);
  base_ = 1;  // table entries are 0: none is in [1, 1 + voxels)
  for (std::uint32_t id = 0; id < voxels_; ++id) {
    std::uint32_t h = slot_of(keys_[id], shift_);
    while (table_[h] - base_ < voxels_) h = (h + 1) & mask_;
    table_[h] = base_ + id;
  }
}

void VoxelGrid::begin(std::size_t max_points) {
  // Ids of this frame start after the last frame's; when they would run out of 32 bits, the table is cleared.
  const std::uint64_t next = static_cast<std::uint64_t>(base_) + voxels_ + max_points + 1;
  voxels_ = 0;
  if (sums_.size() < max_points) {
    sums_.resize(max_points);
    keys_.resize(max_points);
  }
  if (table_.empty()) grow_table();
  if (next > 0xFFFFFFFFULL) {
    std::fill(table_.begin(), table_.end(), 0U);
    base_ = 1;
  } else {
    base_ = static_cast<std::uint32_t>(next - max_points);
  }
  for (auto& c : cache_) {
    c.sum = simd::splat(0.F);
    c.key = kNoKey;
    c.n = 0;
  }
  queued_ = 0;
}

// One point into the voxel `key`: into its ring's cache entry `c` while the ring stays in one voxel. When it
// moves on, the finished run (key, sums, count) is queued; queued runs meet the table in batches.
// `queued` is the caller's copy of queued_, in a register: as a member, every point would load and store it
// (the runs' 32-bit stores may alias it), a store-to-load chain through memory from one point to the next.
inline void VoxelGrid::add(std::uint64_t key, CacheEntry& c, simd::f32x4 p, std::uint32_t& queued) {
  // Branching on whether the ring stays in its voxel (72 % of the points of BM_Voxel's "shed 5Hz") measured
  // 3-7 % faster than writing the entry's run to the queue on every point (BM_Voxel, g++ -O2, x86-64, busy
  // machine; twice, in two sessions), mispredictions and all. The new run starts from +0 + p, as a sum from
  // zero does (a -0 coordinate becomes +0).
  if (c.key == key) {
    c.sum = c.sum + p;  // lanes x, y, z (the fourth is not used)
    ++c.n;
    return;
  }
  if (c.key != kNoKey) {
    Run& r = runs_[queued++];
    r.sum = c.sum;
    r.key = c.key;
    r.n = c.n;
  }
  c.sum = simd::splat(0.F) + p;
  c.n = 1U;
  c.key = key;
  if (queued == kRunBatch) [[unlikely]] {
    queued_ = queued;
    drain_runs();
    queued = 0;
  }
}

// The queued runs into their voxels, in queue order (so the voxel ids, and the output order, depend only on
// the input). First every run's table slot, fetched ahead: the lookups below then rarely wait on memory. One
// pass after that: a new voxel (half the runs of BM_Voxel's "shed 5Hz") takes its run's sums as they are,
// without a second pass that adds them to zeros. Measured slower on this machine (BM_Voxel, busy): telling new
// from known voxels without a branch (masked sums), and fetching a known voxel's key and sums ahead.
// The table's state is read into locals once: as members, each would be loaded again after every 32-bit store
// to the table or a sum (may alias).
void VoxelGrid::drain_runs() {
  const std::uint32_t queued = queued_;
  Run* const runs = runs_.data();
  std::uint32_t* table = table_.data();
  std::uint32_t mask = mask_;
  std::uint32_t shift = shift_;
  std::uint32_t base = base_;
  std::uint32_t voxels = voxels_;
  // At most a quarter of the table taken: a third of the lookups met another voxel's slot at half full;
  // measured 5 % faster (BM_Voxel "shed 5Hz") for a table of 256 kB there.
  auto limit = static_cast<std::uint32_t>(table_.size() / 4);
  std::uint64_t* const keys = keys_.data();
  Sum* const sums = sums_.data();
  for (std::uint32_t j = 0; j < queued; ++j) {
    runs[j].id = slot_of(runs[j].key, shift);
    __builtin_prefetch(&table[runs[j].id]);
  }
  for (std::uint32_t j = 0; j < queued; ++j) {
    const Run& r = runs[j];
    const std::uint64_t key = r.key;
    std::uint32_t h = r.id;  // the slot, from above
    for (;;) {
      const std::uint32_t id = table[h] - base;
      if (id >= voxels) {  // empty in this frame: a new voxel
        // Its sums are the run's: the same bits as adding them to zero, since a run's sum is never -0 (it
        // starts from +0 + p, and x + y is -0 only when both are).
        const std::uint32_t v = voxels++;
        keys[v] = key;
        static_assert(sizeof(Sum) == sizeof(Vec4));
        std::memcpy(&sums[v], &r.sum, sizeof(Sum));
        sums[v].n = r.n;
        if (voxels > limit) [[unlikely]] {
          voxels_ = voxels;
          grow_table();  // re-inserts every key, this one included
          table = table_.data();
          mask = mask_;
          shift = shift_;
          base = base_;
          limit = static_cast<std::uint32_t>(table_.size() / 4);
          for (std::uint32_t k = j + 1; k < queued; ++k) runs[k].id = slot_of(runs[k].key, shift);  // new size
        } else {
          table[h] = base + v;
        }
        break;
      }
      if (keys[id] == key) {
        Sum& a = sums[id];
        a.x += r.sum[0];
        a.y += r.sum[1];
        a.z += r.sum[2];
        a.n += r.n;
        break;
      }
      h = (h + 1) & mask;
    }
  }
  voxels_ = voxels;
  queued_ = 0;
}

void VoxelGrid::finish(Cloud& out) {
  for (const auto& c : cache_) {
    if (c.key == kNoKey) continue;
    runs_[queued_++] = Run{c.sum, c.key, c.n, 0};
    if (queued_ == kRunBatch) drain_runs();
  }
  drain_runs();
  out.resize_xyz(voxels_);
  float* ox = out.x.data();
  float* oy = out.y.data();
  float* oz = out.z.data();
  for (std::uint32_t v = 0; v < voxels_; ++v) {
    const Sum& a = sums_[v];
    const auto cnt = static_cast<float>(a.n);
    ox[v] = a.x / cnt;
    oy[v] = a.y / cnt;
    oz[v] = a.z / cnt;
  }
}

// Points [0, n) of x, y, z (with a ring each when kRings, else all in ring 0) into their voxels, kBlock keys
// at a time. A template rather than a test of `ring` per point.
template <bool kRings>
void VoxelGrid::add_points(const float* px, const float* py, const float* pz, const std::uint16_t* ring,
                           std::size_t n) {
  std::uint64_t keys[kBlock];
  simd::f32x4 points[kBlock];  // (x, y, z, 0) of each point of the block
  float tx[kBlock] = {}, ty[kBlock] = {}, tz[kBlock] = {};
  const KeyLanes lanes(inv_[1]);
  CacheEntry* const cache = cache_.data();
  std::uint32_t queued = queued_;
  for (std::size_t base = 0; base < n; base += kBlock) {
    const std::size_t m = std::min(kBlock, n - base);
    const float* bx = px + base;
    const float* by = py + base;
    const float* bz = pz + base;
    if (m < kBlock) {  // the tail, through a padded copy
      std::copy_n(bx, m, tx);
      std::copy_n(by, m, ty);
      std::copy_n(bz, m, tz);
      bx = tx;
      by = ty;
      bz = tz;
    }
    if (coarse_) {
      for (std::size_t j = 0; j < m; ++j) keys[j] = coarse_key(bx[j], by[j], bz[j]);
    } else {
      block_keys(bx, by, bz, lanes, keys);
    }
    // Four points' coordinates at a time into one vector each, by a transpose rather than point by point.
    for (std::size_t b = 0; b < kBlock; b += 4) {
      simd::f32x4 x = simd::load(bx + b), y = simd::load(by + b), z = simd::load(bz + b), w = simd::splat(0.F);
      simd::transpose4(x, y, z, w);
      points[b] = x;
      points[b + 1] = y;
      points[b + 2] = z;
      points[b + 3] = w;
    }
    for (std::size_t j = 0; j < m; ++j) {
      CacheEntry& c = cache[kRings ? ring[base + j] & (kRingCache - 1) : 0U];
      add(keys[j], c, points[j], queued);
    }
  }
  queued_ = queued;
}

void VoxelGrid::filter(const Cloud& in, Cloud& out) {
  const std::size_t n = in.size();
  begin(n);
  if (in.ring.size() == n) {
    add_points<true>(in.x.data(), in.y.data(), in.z.data(), in.ring.data(), n);
  } else {
    add_points<false>(in.x.data(), in.y.data(), in.z.data(), nullptr, n);
  }
  finish(out);
}

}  // namespace fieldguard::perception
