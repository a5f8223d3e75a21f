#pragma once
// The daemon's threads, set up in one place: name, scheduling policy and priority, CPU affinity, and locked
// memory for the process. Each setting is best effort: what the system refuses is returned as text for the
// caller to log once, and the thread runs on without it.

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

// "fifo 50", "rr 10", "other": for logs.
[[nodiscard]] std::string describe(const ThreadSettings& s);

}  // namespace fieldguard::sync
