#pragma once
// Heap allocations counted by the path that made them, for the daemon's promise of no allocation per frame once
// warm. A thread marks the work it does with a Scope (the frame path: a LiDAR packet through sync, a worker's
// compensation and detection, the decision; or the decoding of another sensor's samples); allocations made
// outside any scope are not counted.
//
// Counting needs the executable to replace the global operator new with one that calls note_allocation(): the
// fieldguard binary does (src/alloc_counting.cpp) and says so with enable(). Elsewhere enabled() is false and every
// count stays 0, which says nothing: callers print the counts only when enabled().
//
// Thread-safe: the current path is per thread, the counts are relaxed atomics (about a nanosecond a count).

#include <atomic>
#include <cstddef>
#include <cstdint>

namespace fieldguard::alloc {

enum class Path : std::uint8_t { None = 0, Frame = 1, Samples = 2 };
inline constexpr std::size_t kPathCount = 3;

namespace detail {
inline thread_local Path current = Path::None;
inline std::atomic<std::uint64_t> counts[kPathCount] = {};
inline std::atomic<bool> counting{false};
}  // namespace detail

// The calling thread works on `path` until the scope ends (then on what it worked on before).
class Scope {
 public:
  explicit Scope(Path p) noexcept : previous_(detail::current) { detail::current = p; }
  ~Scope() { detail::current = previous_; }
  Scope(const Scope&) = delete;
  Scope& operator=(const Scope&) = delete;

 private:
  Path previous_;
};

// From the replacement operator new: one allocation by the calling thread.
inline void note_allocation() noexcept {
  const Path p = detail::current;
  if (p != Path::None) detail::counts[static_cast<std::size_t>(p)].fetch_add(1, std::memory_order_relaxed);
}
inline void enable() noexcept { detail::counting.store(true, std::memory_order_relaxed); }
[[nodiscard]] inline bool enabled() noexcept { return detail::counting.load(std::memory_order_relaxed); }
[[nodiscard]] inline std::uint64_t count(Path p) noexcept {
  return detail::counts[static_cast<std::size_t>(p)].load(std::memory_order_relaxed);
}

}  // namespace fieldguard::alloc
