#pragma once
// Voxel grid downsampling: every occupied voxel becomes the centroid of its points (as pcl::VoxelGrid,
// whose grid is anchored at the origin: voxel i spans [i*leaf, (i+1)*leaf) on each axis). Optionally a
// coarser leaf with range (VoxelParams::coarse_from_m).
//
// Fast: voxel keys packed in 64 bits, in a flat open-addressing hash table of 4-byte voxel ids (linear
// probing, at most a quarter full; ids offset per frame, so nothing is cleared between frames; small, so that
// it stays in cache while the rotation streams past). A ring's consecutive returns usually share a voxel
// (72-85 % of an HDL-32E rotation's points, by scene): the points are taken a chunk at a time, sorted by ring,
// and each ring's runs of points in one voxel summed without a branch per point (a sensor's rings interleave
// point by point, and whether a ring stays in its voxel is guessed wrong about a third of the time); only the
// runs meet the table, in the order they ended in the input. Output in the order the voxels' first runs ended,
// which, as every sum's order, depends only on the input: deterministic.
// Thread-compatible: one VoxelGrid per thread (it owns its scratch).

#include <array>
#include <cstdint>

#include "fieldguard/core/vec4.hpp"
#include "fieldguard/perception/cloud.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

class VoxelGrid {
 public:
  // Counts are summed in float lanes, exact below 2^24 = kExactPoints + 1: a frame of more points is taken in
  // pieces of `exact_points` (at most kExactPoints; fewer only for tests), its counts moved to integers
  // between pieces. Throws std::invalid_argument for a leaf that is not positive.
  static constexpr std::size_t kExactPoints = (std::size_t{1} << 24) - 1;
  explicit VoxelGrid(const VoxelParams& params, std::size_t exact_points = kExactPoints);

  // `out` gets the centroids (no rings). `in` and `out` must be different clouds.
  void filter(const Cloud& in, Cloud& out);

  [[nodiscard]] const VoxelParams& params() const { return params_; }

 private:
  using Vec4 = vec4::f32x4;
  struct OpenRun {  // a ring's points in one voxel since the ring's last move, not yet ended
    Vec4 sum;       // x, y, z, count
    std::uint64_t key;
  };
  static constexpr std::size_t kRingCache = 128;  // rings are told apart modulo this
  static constexpr std::size_t kChunk = 1024;     // points sorted by ring at a time
  static constexpr std::size_t kPositions = kChunk + kRingCache;

  void begin(std::size_t max_points);
  template <bool kRings>
  void add_points(const float* x, const float* y, const float* z, const std::uint16_t* ring, std::size_t n);
  template <bool kRings>
  void add_chunk(const float* x, const float* y, const float* z, const std::uint16_t* ring, std::size_t n);
  void drain_runs(std::uint32_t queued);
  void end_runs();
  void fold_counts();
  void finish(Cloud& out);
  void grow_table();
  [[nodiscard]] std::uint64_t coarse_key(float x, float y, float z) const;

  VoxelParams params_;
  std::size_t exact_points_;
  bool coarse_ = false;
  std::uint32_t bands_ = 1;
  std::array<float, 16> inv_{};  // inverse leaf per band (1-based)
  float inv_band_range_ = 0.F;

  Buffer<std::uint32_t> table_;  // voxel id + base_, or anything else when empty
  std::uint32_t mask_ = 0;
  std::uint32_t shift_ = 0;
  std::uint32_t base_ = 1;
  Buffer<Vec4> sums_;             // x, y, z, count of each voxel id (the count since the last fold_counts())
  Buffer<std::uint32_t> counts_;  // of voxel ids below counted_: the counts fold_counts() took out of sums_
  std::uint32_t counted_ = 0;
  Buffer<std::uint64_t> keys_;  // key of each voxel id, for growing the table
  std::uint32_t voxels_ = 0;
  std::array<OpenRun, kRingCache> open_{};  // by ring & (kRingCache - 1)
  // Scratch of one chunk. By point: (x, y, z, 1), key, ring slot, position in by_ring_, and whether the point
  // ended its ring's run. By position (each slot's points in point order, after one position for the run the
  // slot had open): the point, and the running sum and key of its run. The ended runs (their last positions) in
  // the order they ended, with their table slots.
  Buffer<Vec4> points_;
  Buffer<std::uint64_t> point_keys_;
  Buffer<std::uint16_t> point_slots_;
  Buffer<std::uint16_t> positions_;
  Buffer<std::uint8_t> ended_;
  Buffer<std::uint16_t> by_ring_;
  Buffer<Vec4> run_sums_;
  Buffer<std::uint64_t> run_keys_;
  Buffer<std::uint32_t> queue_;
  Buffer<std::uint32_t> queue_slots_;
};

}  // namespace fieldguard::perception
