#pragma once
// Spare buffers kept for reuse, at most a given number, that give back what sat unused: trim() frees as many as
// were never taken since the trim before (the list's low-water mark), the ones at the bottom, unused longest. What a
// steady stream takes and returns between two trims stays; what a burst left behind (frames held while a sensor was
// out, then released together) goes back to the system at the next trim. Thread-compatible.

#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

namespace fieldguard {

template <typename T>
class SpareList {
 public:
  explicit SpareList(std::size_t max) : max_(max) { items_.reserve(max); }

  // Keeps `v` unless the list is full (then `v` is left as it was, for the caller to drop).
  bool put(T&& v) {
    if (items_.size() >= max_) return false;
    items_.push_back(std::move(v));
    return true;
  }
  // The most recently put, or false when empty.
  bool take(T& out) {
    if (items_.empty()) return false;
    out = std::move(items_.back());
    items_.pop_back();
    low_ = std::min(low_, items_.size());
    return true;
  }
  // Frees the spares not taken since the last trim; returns how many.
  std::size_t trim() {
    const std::size_t n = std::min(low_, items_.size());
    items_.erase(items_.begin(), items_.begin() + static_cast<std::ptrdiff_t>(n));
    low_ = items_.size();
    return n;
  }
  [[nodiscard]] std::size_t size() const { return items_.size(); }
  [[nodiscard]] bool empty() const { return items_.empty(); }

 private:
  std::vector<T> items_;
  std::size_t max_;
  std::size_t low_ = 0;  // the fewest items held since the last trim (0 before the first: nothing is freed then)
};

}  // namespace fieldguard
