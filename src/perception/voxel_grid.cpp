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
  for (auto& r : open_) {
    r.sum = simd::splat(0.F);
    r.key = kNoKey;
  }
  if (points_.empty()) {
    points_.resize(kChunk);
    point_keys_.resize(kChunk);
    point_slots_.resize(kChunk);
    positions_.resize(kChunk);
    ended_.resize(kChunk);
    by_ring_.resize(kPositions);
    run_sums_.resize(kPositions);
    run_keys_.resize(kPositions);
    queue_.resize(kPositions);
    queue_slots_.resize(kPositions);
  }
  counted_ = 0;
}

// The queued runs into their voxels, in queue order (so the voxel ids, and the output order, depend only on
// the input): queue_[j] is the position in run_sums_ / run_keys_ of the j-th run's sum and key. Every run's
// table slot is computed, and its memory fetched ahead, before the first lookup: the lookups below then rarely
// wait on memory. A new voxel (half the runs of BM_Voxel's "shed 5Hz") takes its run's sums as they are,
// without a second pass that adds them to zeros. Measured slower on this machine: telling new from known
// voxels without a branch (masked sums; BM_Voxel), or with the batch's new ids' sums zeroed ahead so that both
// add ("shed 5Hz" after the other frames: 540 to 590 us); fetching a known voxel's key and sums ahead. The
// table's state is read into locals once: as members, each would be loaded again after every 32-bit store to
// the table or a sum (may alias).
void VoxelGrid::drain_runs(std::uint32_t queued) {
  const std::uint32_t* const queue = queue_.data();
  const Vec4* const run_sums = run_sums_.data();
  const std::uint64_t* const run_keys = run_keys_.data();
  std::uint32_t* const slots = queue_slots_.data();
  std::uint32_t* table = table_.data();
  std::uint32_t mask = mask_;
  std::uint32_t shift = shift_;
  std::uint32_t base = base_;
  std::uint32_t voxels = voxels_;
  for (std::uint32_t j = 0; j < queued; ++j) {
    slots[j] = slot_of(run_keys[queue[j]], shift);
    __builtin_prefetch(&table[slots[j]]);
  }
  // At most a quarter of the table taken: a third of the lookups met another voxel's slot at half full;
  // measured 5 % faster (BM_Voxel "shed 5Hz") for a table of 256 kB there.
  auto limit = static_cast<std::uint32_t>(table_.size() / 4);
  std::uint64_t* const keys = keys_.data();
  Vec4* const sums = sums_.data();
  for (std::uint32_t j = 0; j < queued; ++j) {
    const std::uint32_t r = queue[j];
    const std::uint64_t key = run_keys[r];
    std::uint32_t h = slots[j];
    for (;;) {
      const std::uint32_t id = table[h] - base;
      if (id >= voxels) {  // empty in this frame: a new voxel
        // Its sums are the run's: the same bits as adding them to zero, since a run's sum is never -0 (it
        // starts from +0 + p, and x + y is -0 only when both are).
        const std::uint32_t v = voxels++;
        keys[v] = key;
        sums[v] = run_sums[r];
        if (voxels > limit) [[unlikely]] {
          voxels_ = voxels;
          grow_table();  // re-inserts every key, this one included
          table = table_.data();
          mask = mask_;
          shift = shift_;
          base = base_;
          limit = static_cast<std::uint32_t>(table_.size() / 4);
          for (std::uint32_t k = j + 1; k < queued; ++k) slots[k] = slot_of(run_keys[queue[k]], shift);  // new size
        } else {
          table[h] = base + v;
        }
        break;
      }
      if (keys[id] == key) {
        sums[id] = sums[id] + run_sums[r];  // x, y, z lane by lane, as three scalar sums; and the counts
        break;
      }
      h = (h + 1) & mask;
    }
  }
  voxels_ = voxels;
}

// Every open run to the table, in slot order; none is open after.
void VoxelGrid::end_runs() {
  std::uint32_t m = 0;
  for (auto& r : open_) {
    if (r.key == kNoKey) continue;
    run_sums_[m] = r.sum;
    run_keys_[m] = r.key;
    queue_[m] = m;
    ++m;
    r.key = kNoKey;
  }
  drain_runs(m);
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

// Points [0, n) of x, y, z (with a ring each when kRings, else all in ring 0) into their voxels, kChunk at a
// time. A template rather than a test of `ring` per point.
template <bool kRings>
void VoxelGrid::add_points(const float* px, const float* py, const float* pz, const std::uint16_t* ring,
                           std::size_t n) {
  for (std::size_t start = 0; start < n; start += kChunk) {
    add_chunk<kRings>(px + start, py + start, pz + start, kRings ? ring + start : nullptr, std::min(kChunk, n - start));
  }
}

// A chunk of at most kChunk points. A ring's run of points in one voxel ends at the ring's next point in
// another voxel (or at end_runs()); the runs meet the table in the order they ended, each summed from +0 in
// point order, as the plain loop over the points with a running sum per ring would. That loop's test "is
// this point in its ring's voxel" is guessed wrong about a third of the time (rings interleave point by
// point); here the chunk's points are sorted by ring, and each ring's points summed in a register without a
// branch, every point storing its run's running sum at its position. Then the ended runs are put back in
// input order (each noted at the point that ended it) and drained. Measured (thread CPU time, each frame after
// the other frames, so that the branch predictor cannot learn one: BM_VoxelAlternated): "shed 5Hz" 670 to
// 560 us, "shed 10Hz" 350 to 300 us, "field 5Hz" (rings stay longer in a voxel) unchanged, with 65 % more
// instructions. Before, with the branch: writing each point's ring entry to the queue in input order instead
// (no branch, through memory) measured 3-7 % slower; two rings' sums interleaved here, no faster.
template <bool kRings>
void VoxelGrid::add_chunk(const float* px, const float* py, const float* pz, const std::uint16_t* ring, std::size_t n) {
  static_assert(kChunk % kBlock == 0 && kPositions <= 0xFFFFU, "positions and point indices must fit 16 bits");
  std::uint64_t* const keys = point_keys_.data();
  Vec4* const points = points_.data();
  std::uint16_t* const slot = point_slots_.data();
  float tx[kBlock] = {}, ty[kBlock] = {}, tz[kBlock] = {};
  std::uint16_t tr[kBlock] = {};
  const KeyLanes lanes(inv_[1]);
  using u16x8 = std::uint16_t __attribute__((vector_size(16)));
  u16x8 slot_bits = {};  // every slot's bits: 1 + this is at least 1 + the highest slot
  std::uint32_t count[kRingCache] = {};
  for (std::size_t base = 0; base < n; base += kBlock) {
    const std::size_t m = std::min(kBlock, n - base);
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
      for (std::size_t j = 0; j < m; ++j) keys[base + j] = coarse_key(bx[j], by[j], bz[j]);
    } else {
      block_keys(bx, by, bz, lanes, keys + base);
    }
    // Four points' coordinates at a time into one vector each, by a transpose rather than point by point.
    const auto transpose = [&](std::size_t q) __attribute__((always_inline)) {
      const std::size_t b = q * 4;
      simd::f32x4 x = simd::load(bx + b), y = simd::load(by + b), z = simd::load(bz + b), w = simd::splat(1.F);
      simd::transpose4(x, y, z, w);
      points[base + b] = x;
      points[base + b + 1] = y;
      points[base + b + 2] = z;
      points[base + b + 3] = w;
    };
    unrolled(transpose, std::make_index_sequence<kBlock / 4>{});
    if constexpr (kRings) {  // eight slots at a time
      const auto eight = [&](std::size_t q) __attribute__((always_inline)) {
        u16x8 r;
        std::memcpy(&r, br + q * 8, sizeof r);
        r &= static_cast<std::uint16_t>(kRingCache - 1);
        std::memcpy(slot + base + q * 8, &r, sizeof r);
        slot_bits |= r;
      };
      unrolled(eight, std::make_index_sequence<kBlock / 8>{});
      if (m == kBlock) {
        unrolled(
            [&](std::size_t j) __attribute__((always_inline)) { ++count[slot[base + j]]; },
            std::make_index_sequence<kBlock>{});
      } else {
        for (std::size_t j = 0; j < m; ++j) ++count[slot[base + j]];
      }
    }
  }
  std::uint32_t slots = 1;
  if constexpr (kRings) {
    std::uint32_t bits = 0;
    for (std::size_t k = 0; k < 8; ++k) bits |= slot_bits[k];
    slots = bits + 1;
  } else {
    count[0] = static_cast<std::uint32_t>(n);
  }
  // Positions: slot by slot, one for the run the slot has open, then its points in point order.
  std::uint32_t first[kRingCache];
  std::uint32_t next[kRingCache];
  std::uint32_t used = 0;
  for (std::size_t s = 0; s < slots; ++s) {
    first[s] = used;
    next[s] = used + 1;
    used += count[s] + 1;
  }
  std::uint16_t* const by_ring = by_ring_.data();
  std::uint16_t* const position = positions_.data();
  if constexpr (kRings) {
    std::size_t i = 0;
    const auto place = [&](std::size_t j) __attribute__((always_inline)) {
      const std::uint32_t t = next[slot[i + j]]++;
      by_ring[t] = static_cast<std::uint16_t>(i + j);
      position[i + j] = static_cast<std::uint16_t>(t);
    };
    for (; i + 4 <= n; i += 4) unrolled(place, std::make_index_sequence<4>{});
    for (; i < n; ++i) place(0);
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      by_ring[i + 1] = static_cast<std::uint16_t>(i);
      position[i] = static_cast<std::uint16_t>(i + 1);
    }
  }
  // Each slot's runs: every position stores its run's running sum and key; a point in another voxel than the
  // one before it ends the run at the position before its own, and restarts the sum from +0 (the lanes masked
  // to +0, then + p: as a sum from zero, a -0 coordinate becomes +0).
  Vec4* const run_sums = run_sums_.data();
  std::uint64_t* const run_keys = run_keys_.data();
  std::uint8_t* const ended = ended_.data();
  using I = simd::i32x4;
  static constexpr I kKeep[2] = {I{-1, -1, -1, -1}, I{0, 0, 0, 0}};  // by "moved on"
  for (std::size_t s = 0; s < slots; ++s) {
    const std::uint32_t c = count[s];
    if (c == 0) continue;
    std::uint32_t t = first[s];
    Vec4 sum = open_[s].sum;
    std::uint64_t prev = open_[s].key;
    run_sums[t] = sum;
    run_keys[t] = prev;
    const std::uint32_t end = t + 1 + c;
    for (++t; t < end; ++t) {
      const std::uint32_t i = by_ring[t];
      const std::uint64_t key = keys[i];
      const bool moved = key != prev;
      ended[i] = static_cast<std::uint8_t>(moved);
      sum = std::bit_cast<Vec4>(std::bit_cast<I>(sum) & kKeep[moved]) + points[i];
      run_sums[t] = sum;
      run_keys[t] = key;
      prev = key;
    }
    if (open_[s].key == kNoKey) ended[by_ring[first[s] + 1]] = 0;  // the slot's first run ended none
    open_[s].sum = sum;
    open_[s].key = prev;
  }
  // The ended runs in the order they ended (point order), then into their voxels.
  std::uint32_t* const queue = queue_.data();
  std::uint32_t queued = 0;
  std::size_t i = 0;
  const auto note = [&](std::size_t j) __attribute__((always_inline)) {
    queue[queued] = position[i + j] - 1U;
    queued += ended[i + j];
  };
  for (; i + 4 <= n; i += 4) unrolled(note, std::make_index_sequence<4>{});
  for (; i < n; ++i) note(0);
  drain_runs(queued);
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
