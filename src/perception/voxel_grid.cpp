#include "fieldguard/perception/voxel_grid.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "perception/simd.hpp"

namespace fieldguard::perception {
namespace {

// Voxel coordinates are packed in 20 bits each (offset by 2^19), the range band (1-based) in the top 4 bits
// (coarse_key(); block_keys() packs differently). kNoKey, which marks an empty ring-cache entry, is neither.
constexpr std::int32_t kCoordOffset = 1 << 19;
constexpr float kCoordLimit = 524287.0F;  // 2^19 - 1: coordinates beyond are clamped (5 km at a 1 cm leaf)
constexpr std::uint32_t kMaxBands = 15;
constexpr std::uint64_t kNoKey = std::uint64_t{1} << 59U;  // high half 2^27: see block_keys()

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

// f(0), f(1), ..., f(N - 1) for std::make_index_sequence<N>, unrolled: g++ -O2 does not unroll the block's
// short loops, whose counters and indexing were about 2 of the ~45 instructions of a point (callgrind,
// BM_Voxel "shed 5Hz").
template <typename F, std::size_t... I>
__attribute__((always_inline)) inline void unrolled(F&& f, std::index_sequence<I...> /*steps*/) {
  (f(I), ...);
}

// The constants of block_keys(), splatted once per frame rather than once per block.
struct KeyLanes {
  simd::f32x4 inv_leaf, lo, hi;
  explicit KeyLanes(float s) : inv_leaf(simd::splat(s)), lo(simd::splat(-kCoordLimit)), hi(simd::splat(kCoordLimit)) {}
};

// Keys of kBlock points with one leaf, four at a time, clamped to the key's range.
// Inlined: as a call, each block reloaded the lanes' constants.
__attribute__((always_inline)) inline void block_keys(const float* x, const float* y, const float* z, const KeyLanes& c,
                                                      std::uint64_t* keys) {
  const auto four = [&](std::size_t q) __attribute__((always_inline)) {
    const std::size_t b = q * 4;
    const simd::i32x4 ix = simd::floor_clamped(simd::load(x + b) * c.inv_leaf, c.lo, c.hi);
    const simd::i32x4 iy = simd::floor_clamped(simd::load(y + b) * c.inv_leaf, c.lo, c.hi);
    const simd::i32x4 iz = simd::floor_clamped(simd::load(z + b) * c.inv_leaf, c.lo, c.hi);
    if constexpr (std::endian::native == std::endian::little) {
      // An injective key cheaper than pack(): low half (iy << 20) + iz, high half (ix << 8) + (iy >> 12)
      // (arithmetic), both modulo 2^32. The low half's 20 low bits give iz (|iz| < 2^19), then its top 12
      // bits iy's low 12; the high half's low 8 bits give iy >> 12 (in [-128, 127]), the rest ix. Its high
      // half lies in [-2^27, 2^27), which keeps kNoKey and every coarse key (band >= 1 in the top 4 bits)
      // out of its reach. Only key equality reaches the output, never the key's value.
      using u32x4 = std::uint32_t __attribute__((vector_size(16)));
      const u32x4 uy = __builtin_convertvector(iy, u32x4);
      const u32x4 lo = (uy << 20U) + __builtin_convertvector(iz, u32x4);
      const u32x4 hi = (__builtin_convertvector(ix, u32x4) << 8U) + __builtin_convertvector(iy >> 12, u32x4);
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
  };
  unrolled(four, std::make_index_sequence<kBlock / 4>{});
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

VoxelGrid::VoxelGrid(const VoxelParams& params, std::size_t exact_points)
    : params_(params), exact_points_(std::clamp<std::size_t>(exact_points, 1, kExactPoints)) {
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
    counts_.resize(max_points);
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
  }
  queued_ = 0;
  counted_ = 0;
}

// The queued runs into their voxels, in queue order (so the voxel ids, and the output order, depend only on
// the input). Every run's table slot was computed, and fetched ahead, when it was queued: the lookups below
// then rarely wait on memory. A new voxel (half the runs of BM_Voxel's "shed 5Hz") takes its run's sums as
// they are, without a second pass that adds them to zeros. Measured slower on this machine (BM_Voxel, busy): telling
// new from known voxels without a branch (masked sums), and fetching a known voxel's key and sums ahead. The table's
// state is read into locals once: as members, each would be loaded again after every 32-bit store to the table or a sum
// (may alias).
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
  Vec4* const sums = sums_.data();
  for (std::uint32_t j = 0; j < queued; ++j) {
    const Run& r = runs[j];
    const std::uint64_t key = r.key;
    std::uint32_t h = r.id;  // the slot, from add_points() or finish()
    for (;;) {
      const std::uint32_t id = table[h] - base;
      if (id >= voxels) {  // empty in this frame: a new voxel
        // Its sums are the run's: the same bits as adding them to zero, since a run's sum is never -0 (it
        // starts from +0 + p, and x + y is -0 only when both are).
        const std::uint32_t v = voxels++;
        keys[v] = key;
        sums[v] = r.sum;
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
        sums[id] = sums[id] + r.sum;  // x, y, z lane by lane, as three scalar sums; and the counts
        break;
      }
      h = (h + 1) & mask;
    }
  }
  voxels_ = voxels;
  queued_ = 0;
}

// Every open run to the table; the cache is empty after.
void VoxelGrid::end_runs() {
  for (auto& c : cache_) {
    if (c.key == kNoKey) continue;
    if (queued_ == kRunBatch) drain_runs();  // add_points() may leave the queue full
    runs_[queued_++] = Run{c.sum, c.key, slot_of(c.key, shift_)};
    c.key = kNoKey;
  }
  drain_runs();
}

// The voxels' counts out of their float lanes into counts_, for a frame of more than exact_points_.
void VoxelGrid::fold_counts() {
  for (std::uint32_t v = 0; v < voxels_; ++v) {
    const auto n = static_cast<std::uint32_t>(sums_[v][3]);
    counts_[v] = (v < counted_ ? counts_[v] : 0U) + n;
    sums_[v][3] = 0.F;
  }
  counted_ = voxels_;
}

void VoxelGrid::finish(Cloud& out) {
  end_runs();
  const bool folded = counted_ > 0;
  if (folded) fold_counts();
  out.resize_xyz(voxels_);
  float* ox = out.x.data();
  float* oy = out.y.data();
  float* oz = out.z.data();
  const Vec4* sums = sums_.data();
  std::uint32_t v = 0;
  // Four voxels at a time: their sums transposed into x, y, z and count vectors. The same divisions as one
  // at a time (IEEE, lane by lane), by the count as a float: exact, and static_cast<float>(n) (below 2^24).
  for (; !folded && v + 4 <= voxels_; v += 4) {
    Vec4 x = sums[v], y = sums[v + 1], z = sums[v + 2], n = sums[v + 3];
    simd::transpose4(x, y, z, n);
    x = x / n;
    y = y / n;
    z = z / n;
    std::memcpy(ox + v, &x, sizeof x);
    std::memcpy(oy + v, &y, sizeof y);
    std::memcpy(oz + v, &z, sizeof z);
  }
  for (; v < voxels_; ++v) {
    const float n = folded ? static_cast<float>(counts_[v]) : sums[v][3];
    ox[v] = sums[v][0] / n;
    oy[v] = sums[v][1] / n;
    oz[v] = sums[v][2] / n;
  }
}

// Points [0, n) of x, y, z (with a ring each when kRings, else all in ring 0) into their voxels, kBlock keys
// at a time. A template rather than a test of `ring` per point.
//
// A point goes into its ring's cache entry while the ring stays in one voxel. When it moves on, the finished
// run (key, sums, count) is queued with its table slot, whose memory is fetched ahead; queued runs meet the
// table in batches (drain_runs()). Branching on whether the ring stays in its voxel (72 % of the points of
// BM_Voxel's "shed 5Hz") measured 3-7 % faster than writing the entry's run to the queue on every point
// (BM_Voxel, g++ -O2, x86-64, busy machine; twice, in two sessions), mispredictions and all. A new run starts
// from +0 + p, as a sum from zero does (a -0 coordinate becomes +0).
// The queue's length, the table's pointer and shift are locals, in registers: as members, every point would
// load and store them again (the 32-bit stores of the runs may alias them). A full block's points are
// unrolled, each with its cache entry's byte offset and key at a fixed place in the block's arrays: a loop
// spent about 7 of the 17 instructions of a point that stays in its voxel on its counter and indexing.
template <bool kRings>
void VoxelGrid::add_points(const float* px, const float* py, const float* pz, const std::uint16_t* ring,
                           std::size_t n) {
  std::uint64_t keys[kBlock];
  simd::f32x4 points[kBlock];        // (x, y, z, 1) of each point of the block
  std::uint16_t entry[kBlock] = {};  // byte offset of each point's cache entry
  float tx[kBlock] = {}, ty[kBlock] = {}, tz[kBlock] = {};
  std::uint16_t tr[kBlock] = {};
  static_assert(sizeof(CacheEntry) * kRingCache <= 0x10000U, "cache entry offsets must fit 16 bits");
  static_assert(kRunBatch >= kBlock);
  const KeyLanes lanes(inv_[1]);
  auto* const cache = reinterpret_cast<unsigned char*>(cache_.data());
  Run* const runs = runs_.data();
  Run* next = runs + queued_;  // the queue's end
  std::uint32_t shift = shift_;
  const std::uint32_t* table = table_.data();
  const auto add = [&](std::size_t j) __attribute__((always_inline)) {
    auto& c = *reinterpret_cast<CacheEntry*>(cache + entry[j]);
    const std::uint64_t key = keys[j];
    if (c.key == key) [[likely]] {  // else g++ puts the miss inline and jumps to the hit and back
      c.sum = c.sum + points[j];    // x, y, z and the count
      return;
    }
    if (c.key != kNoKey) {
      Run& r = *next++;
      r.sum = c.sum;
      r.key = c.key;
      r.id = slot_of(c.key, shift);
      __builtin_prefetch(&table[r.id]);
    }
    c.sum = simd::splat(0.F) + points[j];  // count 1
    c.key = key;
  };
  for (std::size_t base = 0; base < n; base += kBlock) {
    const std::size_t m = std::min(kBlock, n - base);
    // A block queues at most a run a point: the queue is drained before it could overflow, not point by point.
    // (Where the batches end changes no sum and no voxel id: the runs meet the table in queue order.)
    if (next > runs + (kRunBatch - kBlock)) {
      queued_ = static_cast<std::uint32_t>(next - runs);
      drain_runs();  // may grow the table
      next = runs;
      shift = shift_;
      table = table_.data();
    }
    const float* bx = px + base;
    const float* by = py + base;
    const float* bz = pz + base;
    const std::uint16_t* br = kRings ? ring + base : nullptr;
    if (m < kBlock) {  // the tail, through a padded copy
      std::copy_n(bx, m, tx);
      std::copy_n(by, m, ty);
      std::copy_n(bz, m, tz);
      bx = tx;
      by = ty;
      bz = tz;
      if constexpr (kRings) {
        std::copy_n(br, m, tr);
        br = tr;
      }
    }
    if (coarse_) {
      for (std::size_t j = 0; j < m; ++j) keys[j] = coarse_key(bx[j], by[j], bz[j]);
    } else {
      block_keys(bx, by, bz, lanes, keys);
    }
    // Four points' coordinates at a time into one vector each, by a transpose rather than point by point.
    const auto transpose = [&](std::size_t q) __attribute__((always_inline)) {
      const std::size_t b = q * 4;
      simd::f32x4 x = simd::load(bx + b), y = simd::load(by + b), z = simd::load(bz + b), w = simd::splat(1.F);
      simd::transpose4(x, y, z, w);
      points[b] = x;
      points[b + 1] = y;
      points[b + 2] = z;
      points[b + 3] = w;
    };
    unrolled(transpose, std::make_index_sequence<kBlock / 4>{});
    if constexpr (kRings) {  // eight rings at a time into their entries' offsets (without rings, all 0)
      using u16x8 = std::uint16_t __attribute__((vector_size(16)));
      const auto eight = [&](std::size_t q) __attribute__((always_inline)) {
        u16x8 r;
        std::memcpy(&r, br + q * 8, sizeof r);
        r = (r & static_cast<std::uint16_t>(kRingCache - 1)) * static_cast<std::uint16_t>(sizeof(CacheEntry));
        std::memcpy(entry + q * 8, &r, sizeof r);
      };
      unrolled(eight, std::make_index_sequence<kBlock / 8>{});
    }
    if (m == kBlock) {
      unrolled(add, std::make_index_sequence<kBlock>{});
    } else {
      for (std::size_t j = 0; j < m; ++j) add(j);
    }
  }
  queued_ = static_cast<std::uint32_t>(next - runs);
}

void VoxelGrid::filter(const Cloud& in, Cloud& out) {
  const std::size_t n = in.size();
  begin(n);
  const bool rings = in.ring.size() == n;
  for (std::size_t start = 0;;) {
    const std::size_t m = std::min(exact_points_, n - start);
    if (rings) {
      add_points<true>(in.x.data() + start, in.y.data() + start, in.z.data() + start, in.ring.data() + start, m);
    } else {
      add_points<false>(in.x.data() + start, in.y.data() + start, in.z.data() + start, nullptr, m);
    }
    start += m;
    if (start == n) break;
    // Counts in float lanes are exact below 2^24: before more points could take one beyond, every open run
    // ends (runs restart, so this changes sums' order, only for such a frame) and the counts move to integers.
    end_runs();
    fold_counts();
  }
  finish(out);
}

}  // namespace fieldguard::perception
