#pragma once
// The daemon's threads, set up in one place: name, scheduling policy and priority, CPU affinity, and locked
// memory for the process. Each setting is best effort: what the system refuses is returned as text for the
// caller to log once, and the thread runs on without it.

#include <cstddef>
#include <string>
#include <vector>

namespace fieldguard::sync {

enum class SchedPolicy : unsigned char { Other, Fifo, RoundRobin };

struct ThreadSettings {
  std::string name;  // at most 15 characters are kept (pthread_setname_np)
  SchedPolicy policy = SchedPolicy::Other;
  int priority = 0;       // 1..99 under Fifo / RoundRobin; ignored under Other
  std::vector<int> cpus;  // affinity; empty: any CPU
};

// Applies `s` to the calling thread. Returns what was refused, "; "-separated ("SCHED_FIFO priority 50:
// Operation not permitted"); empty when everything took.
[[nodiscard]] std::string apply_to_this_thread(const ThreadSettings& s);

// mlockall(MCL_CURRENT | MCL_FUTURE): no page of the process is paged out or faulted in later. The refusal, or
// empty.
[[nodiscard]] std::string lock_all_memory();

// Whether malloc is glibc's (not a sanitizer runtime's, nor another C library's).
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define FIELDGUARD_SANITIZER_MALLOC 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define FIELDGUARD_SANITIZER_MALLOC 1
#endif
#endif
#if defined(__GLIBC__) && !defined(FIELDGUARD_SANITIZER_MALLOC)
inline constexpr bool kGlibcMalloc = true;
#else
inline constexpr bool kGlibcMalloc = false;
#endif
inline constexpr std::size_t kLargeBlockBytes = std::size_t{128} * 1024;  // glibc's own starting threshold
// Large blocks (`threshold_bytes` and up) each get their own mapping, handed back to the system when freed,
// whatever was freed before. glibc otherwise raises that threshold to the largest block freed so far (up to
// 32 MiB), after which the point buffers a sensor outage made the daemon hold come from the heap and stay
// resident, and locked, after the outage. Empty when it took; what the allocator refused otherwise (other C
// libraries and sanitizer runtimes: their own allocators).
[[nodiscard]] std::string give_large_blocks_back(std::size_t threshold_bytes = kLargeBlockBytes);

// "fifo 50", "rr 10", "other": for logs.
[[nodiscard]] std::string describe(const ThreadSettings& s);

}  // namespace fieldguard::sync
