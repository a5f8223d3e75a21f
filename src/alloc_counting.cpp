// The fieldguard binary's global operator new and delete: malloc and free, as the library's are, plus a count of
// the allocations made inside an alloc::Scope (core/alloc_count.hpp), so that the daemon can say how many its
// frame path made once warm. Every form of new is replaced, so that no allocation escapes the count.
#include <cstdlib>
#include <new>

#include "fieldguard/core/alloc_count.hpp"

// ThreadSanitizer and MemorySanitizer link their own operator new and delete statically: a second definition does
// not link. Their builds count nothing (alloc::enabled() stays false and the summary leaves the line out).
#if defined(__SANITIZE_THREAD__)
#define FIELDGUARD_OWN_NEW 0
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define FIELDGUARD_OWN_NEW 0
#endif
#endif
#ifndef FIELDGUARD_OWN_NEW
#define FIELDGUARD_OWN_NEW 1
#endif

#if FIELDGUARD_OWN_NEW
namespace {

// Enabled before main(): the daemon's summary prints the counts only where this file is linked.
[[maybe_unused]] const bool kEnabled = [] {
  fieldguard::alloc::enable();
  return true;
}();

// Counts the allocation, then tries `get` until it gives memory, calling the new-handler between tries as the
// standard operator new does; std::bad_alloc without one.
template <typename Get>
void* allocate_with(Get get) {
  fieldguard::alloc::note_allocation();
  for (;;) {
    if (void* p = get()) return p;
    const std::new_handler h = std::get_new_handler();
    if (h == nullptr) throw std::bad_alloc();
    h();
  }
}

void* allocate(std::size_t n) {
  return allocate_with([n] { return std::malloc(n == 0 ? 1 : n); });
}

void* allocate_aligned(std::size_t n, std::align_val_t al) {
  const auto a = static_cast<std::size_t>(al);
  const std::size_t size = ((n == 0 ? 1 : n) + a - 1) / a * a;  // aligned_alloc wants a multiple of the alignment
  return allocate_with([a, size] { return std::aligned_alloc(a, size); });
}

// The nothrow forms: nullptr where the throwing form throws.
template <typename Allocate>
void* or_null(Allocate allocate_or_throw) noexcept {
  try {
    return allocate_or_throw();
  } catch (...) {
    return nullptr;
  }
}

}  // namespace

void* operator new(std::size_t n) { return allocate(n); }
void* operator new[](std::size_t n) { return allocate(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  return or_null([n] { return allocate(n); });
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  return or_null([n] { return allocate(n); });
}
void* operator new(std::size_t n, std::align_val_t al) { return allocate_aligned(n, al); }
void* operator new[](std::size_t n, std::align_val_t al) { return allocate_aligned(n, al); }
void* operator new(std::size_t n, std::align_val_t al, const std::nothrow_t&) noexcept {
  return or_null([n, al] { return allocate_aligned(n, al); });
}
void* operator new[](std::size_t n, std::align_val_t al, const std::nothrow_t&) noexcept {
  return or_null([n, al] { return allocate_aligned(n, al); });
}

void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
#endif  // FIELDGUARD_OWN_NEW
