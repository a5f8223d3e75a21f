// The allocation counts by path (core/alloc_count.hpp): scopes nest per thread, and only a scope's allocations
// count. The operator new that calls note_allocation() is the fieldguard binary's; here it is called directly.

#include "fieldguard/core/alloc_count.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace fieldguard::alloc {
namespace {

TEST(AllocCount, OnlyAllocationsInsideAScopeCountAndScopesNest) {
  const std::uint64_t frame0 = count(Path::Frame);
  const std::uint64_t samples0 = count(Path::Samples);
  note_allocation();  // outside any scope
  EXPECT_EQ(count(Path::Frame), frame0);
  EXPECT_EQ(count(Path::Samples), samples0);
  {
    const Scope samples(Path::Samples);
    note_allocation();
    {
      const Scope frame(Path::Frame);
      note_allocation();
      note_allocation();
      {
        const Scope none(Path::None);  // periodic work inside the frame path: not counted
        note_allocation();
      }
      note_allocation();
    }
    note_allocation();  // back on the samples path
  }
  note_allocation();
  EXPECT_EQ(count(Path::Frame) - frame0, 3U);
  EXPECT_EQ(count(Path::Samples) - samples0, 2U);
}

TEST(AllocCount, TheScopeIsPerThread) {
  const std::uint64_t frame0 = count(Path::Frame);
  const Scope frame(Path::Frame);
  std::thread other([] { note_allocation(); });  // a thread of its own: in no scope
  other.join();
  EXPECT_EQ(count(Path::Frame), frame0);
  note_allocation();
  EXPECT_EQ(count(Path::Frame), frame0 + 1);
}

}  // namespace
}  // namespace fieldguard::alloc
