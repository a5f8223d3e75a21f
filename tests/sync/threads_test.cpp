// Thread settings applied in one place: what takes is visible on the thread, what is refused is said.

#include "fieldguard/sync/threads.hpp"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <cstdlib>
#include <string>
#include <thread>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace fieldguard::sync {
namespace {

TEST(Threads, NameAndAffinityTakeOnTheCallingThread) {
  std::string refused;
  std::string name;
  cpu_set_t set;
  CPU_ZERO(&set);
  std::thread t([&] {
    refused = apply_to_this_thread({"fg-test-worker-long-name", SchedPolicy::Other, 0, {0}});
    char buf[32] = {};
    pthread_getname_np(pthread_self(), buf, sizeof buf);
    name = buf;
    pthread_getaffinity_np(pthread_self(), sizeof set, &set);
  });
  t.join();
  EXPECT_EQ(refused, "");
  EXPECT_EQ(name, "fg-test-worker-");  // the kernel keeps 15 characters
  EXPECT_TRUE(CPU_ISSET(0, &set));
  EXPECT_EQ(CPU_COUNT(&set), 1);
}

TEST(Threads, ARefusedSettingIsSaidAndTheThreadRunsOn) {
  // Priority 0 is never valid under SCHED_FIFO (1..99): refused whatever the privileges.
  std::string refused;
  int policy = -1;
  std::thread t([&] {
    refused = apply_to_this_thread({"fg-test", SchedPolicy::Fifo, 0, {}});
    sched_param p{};
    pthread_getschedparam(pthread_self(), &policy, &p);
  });
  t.join();
  EXPECT_NE(refused.find("SCHED_FIFO priority 0"), std::string::npos) << refused;
  EXPECT_EQ(policy, SCHED_OTHER);
  // A CPU that does not exist.
  std::thread u([&] { refused = apply_to_this_thread({"", SchedPolicy::Other, 0, {1000}}); });
  u.join();
  EXPECT_NE(refused.find("CPUs 1000"), std::string::npos) << refused;
}

TEST(Threads, Describe) {
  EXPECT_EQ(describe({"", SchedPolicy::Fifo, 50, {}}), "fifo 50");
  EXPECT_EQ(describe({"", SchedPolicy::RoundRobin, 7, {}}), "rr 7");
  EXPECT_EQ(describe({}), "other");
}

// A large block freed goes back to the system, and so does the next one, smaller: without the fixed threshold
// glibc raises it to the 4 MiB block freed first, and the 1 MiB block after it comes from the heap.
TEST(Threads, LargeBlocksAreGivenBackWhateverWasFreedBefore) {
#if defined(__GLIBC__)
  if (!kGlibcMalloc) GTEST_SKIP() << "a sanitizer's allocator: mallopt and mallinfo2 say nothing of it";
  ASSERT_EQ(give_large_blocks_back(), "");
  const auto mapped = [] { return mallinfo2().hblks; };
  const auto touch = [](void* p) { asm volatile("" : : "g"(p) : "memory"); };  // the blocks must exist
  const std::size_t before = mapped();
  void* big = std::malloc(std::size_t{4} << 20);
  touch(big);
  EXPECT_EQ(mapped(), before + 1);
  std::free(big);
  EXPECT_EQ(mapped(), before);
  void* smaller = std::malloc(std::size_t{1} << 20);
  touch(smaller);
  EXPECT_EQ(mapped(), before + 1) << "the 1 MiB block came from the heap: it would stay resident once freed";
  std::free(smaller);
  EXPECT_EQ(mapped(), before);
#else
  GTEST_SKIP() << "not glibc";
#endif
}

}  // namespace
}  // namespace fieldguard::sync
