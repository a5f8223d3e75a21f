#pragma once
// The point cloud the pipeline's stages pass along: structure of arrays (x, y, z and the laser ring), so
// that stages stream through the coordinates they need and vectorise. Reused across frames: clear() and
// resize() keep the capacity, and resize() does not zero what it adds (every stage writes what it sizes).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace fieldguard::perception {

// An allocator whose value-less construct() default-initialises: a std::vector of floats grows without
// writing zeros first. Scratch buffers only; everything else uses std::allocator.
template <class T>
struct DefaultInitAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() noexcept = default;
  template <class U>
  explicit DefaultInitAllocator(const DefaultInitAllocator<U>& /*other*/) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <class T>
using Buffer = std::vector<T, DefaultInitAllocator<T>>;

struct Cloud {
  Buffer<float> x;  // m, sensor frame (x forward, y left, z up)
  Buffer<float> y;
  Buffer<float> z;
  Buffer<std::uint16_t> ring;  // laser ring (0 = lowest beam), one per point; empty when not known

  [[nodiscard]] std::size_t size() const { return x.size(); }
  [[nodiscard]] bool empty() const { return x.empty(); }
  void clear() {
    x.clear();
    y.clear();
    z.clear();
    ring.clear();
  }
  void reserve(std::size_t n) {
    x.reserve(n);
    y.reserve(n);
    z.reserve(n);
    ring.reserve(n);
  }
  // Points only (ring emptied).
  void resize_xyz(std::size_t n) {
    x.resize(n);
    y.resize(n);
    z.resize(n);
    ring.clear();
  }
  void push_back(float px, float py, float pz) {
    x.push_back(px);
    y.push_back(py);
    z.push_back(pz);
  }
  void push_back(float px, float py, float pz, std::uint16_t r) {
    push_back(px, py, pz);
    ring.push_back(r);
  }
};

}  // namespace fieldguard::perception
