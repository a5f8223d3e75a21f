#pragma once
// Durations (latencies, stalls) kept for median / p99 / max without allocating: a fixed histogram of 10 us
// buckets up to 100 ms, the exact maximum, and the count. Cheap enough to feed once per frame for a whole run.
// Thread-compatible.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>

namespace fieldguard {

class LatencyStats {
 public:
  static constexpr std::int64_t kBucketNs = 10'000;
  static constexpr std::size_t kBuckets = 10'000;  // up to 100 ms; longer ones count in the last bucket

  void add(std::int64_t ns) {
    ns = std::max<std::int64_t>(ns, 0);
    const auto b = static_cast<std::size_t>(ns / kBucketNs);
    ++buckets_[std::min(b, kBuckets - 1)];
    max_ns_ = std::max(max_ns_, ns);
    ++count_;
  }
  [[nodiscard]] std::uint64_t count() const { return count_; }
  [[nodiscard]] std::int64_t max_ns() const { return max_ns_; }
  // The q-quantile (0 < q <= 1): the upper edge of the bucket that holds it, never more than the maximum (the
  // maximum itself when it lies past 100 ms); 0 when empty.
  [[nodiscard]] std::int64_t quantile_ns(double q) const {
    if (count_ == 0) return 0;
    const auto rank = static_cast<std::uint64_t>(q * static_cast<double>(count_) + 0.999999);
    std::uint64_t seen = 0;
    for (std::size_t b = 0; b < kBuckets; ++b) {
      seen += buckets_[b];
      if (seen >= std::max<std::uint64_t>(rank, 1)) {
        // The last bucket also holds everything longer: there only the maximum is known.
        if (b == kBuckets - 1) return max_ns_;
        return std::min(static_cast<std::int64_t>(b + 1) * kBucketNs, max_ns_);
      }
    }
    return max_ns_;
  }

 private:
  std::array<std::uint32_t, kBuckets> buckets_{};
  std::int64_t max_ns_ = 0;
  std::uint64_t count_ = 0;
};

}  // namespace fieldguard
