#include "fieldguard/sync/threads.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <climits>
#include <cstring>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace fieldguard::sync {
namespace {

int native(SchedPolicy p) {
  switch (p) {
    case SchedPolicy::Fifo: return SCHED_FIFO;
    case SchedPolicy::RoundRobin: return SCHED_RR;
    case SchedPolicy::Other: break;
  }
  return SCHED_OTHER;
}

const char* policy_name(SchedPolicy p) {
  switch (p) {
    case SchedPolicy::Fifo: return "SCHED_FIFO";
    case SchedPolicy::RoundRobin: return "SCHED_RR";
    case SchedPolicy::Other: break;
  }
  return "SCHED_OTHER";
}

void add(std::string& out, const std::string& what, int err) {
  if (!out.empty()) out += "; ";
  out += what + ": " + std::strerror(err);
}

}  // namespace

std::string apply_to_this_thread(const ThreadSettings& s) {
  std::string refused;
  if (!s.name.empty()) {
    const std::string name = s.name.substr(0, 15);
    if (const int e = pthread_setname_np(pthread_self(), name.c_str()); e != 0) add(refused, "name " + name, e);
  }
  if (s.policy != SchedPolicy::Other) {
    sched_param p{};
    p.sched_priority = s.priority;
    if (const int e = pthread_setschedparam(pthread_self(), native(s.policy), &p); e != 0) {
      add(refused, std::string(policy_name(s.policy)) + " priority " + std::to_string(s.priority), e);
    }
  }
  if (!s.cpus.empty()) {
    cpu_set_t set;
    CPU_ZERO(&set);
    std::string list;
    for (const int c : s.cpus) {
      if (c >= 0 && c < CPU_SETSIZE) CPU_SET(static_cast<unsigned>(c), &set);
      list += (list.empty() ? "" : ",") + std::to_string(c);
    }
    if (const int e = pthread_setaffinity_np(pthread_self(), sizeof set, &set); e != 0) add(refused, "CPUs " + list, e);
  }
  return refused;
}

std::string lock_all_memory() {
  if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return {};
  return std::string("mlockall: ") + std::strerror(errno);
}

std::string give_large_blocks_back(std::size_t threshold_bytes) {
#if defined(__GLIBC__)
  if (!kGlibcMalloc) return "a sanitizer's allocator: its own rules for giving memory back";
  if (threshold_bytes > static_cast<std::size_t>(INT_MAX)) return "large-block threshold beyond the allocator's range";
  const int t = static_cast<int>(threshold_bytes);
  // Setting either one by hand ends glibc's adjustment of both; the trim threshold hands back the heap's free
  // top too.
  if (::mallopt(M_MMAP_THRESHOLD, t) == 1 && ::mallopt(M_TRIM_THRESHOLD, t) == 1) return {};
  return "mallopt refused the large-block threshold";
#else
  (void)threshold_bytes;
  return "not glibc's allocator: its own rules for giving memory back";
#endif
}

std::string describe(const ThreadSettings& s) {
  switch (s.policy) {
    case SchedPolicy::Fifo: return "fifo " + std::to_string(s.priority);
    case SchedPolicy::RoundRobin: return "rr " + std::to_string(s.priority);
    case SchedPolicy::Other: break;
  }
  return "other";
}

}  // namespace fieldguard::sync
