// SpareList keeps what a steady stream takes and returns between two trims, and frees what sat unused.

#include "fieldguard/core/spare_list.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace fieldguard {
namespace {

TEST(SpareList, TrimFreesWhatSatUnusedSinceTheTrimBefore) {
  SpareList<std::vector<int>> list(4);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(list.put(std::vector<int>(8, i)));
  std::vector<int> extra(8, 9);
  EXPECT_FALSE(list.put(std::move(extra)));
  EXPECT_EQ(extra.size(), 8U) << "a refused buffer stays with the caller";
  EXPECT_EQ(list.trim(), 0U) << "the first trim only starts the watch";
  // A steady stream: one taken and returned, again and again.
  std::vector<int> b;
  for (int k = 0; k < 5; ++k) {
    ASSERT_TRUE(list.take(b));
    EXPECT_EQ(b.front(), 3) << "the most recently put";
    ASSERT_TRUE(list.put(std::move(b)));
  }
  EXPECT_EQ(list.trim(), 3U) << "three sat at the bottom the whole time";
  EXPECT_EQ(list.size(), 1U);
  ASSERT_TRUE(list.take(b));
  EXPECT_EQ(b.front(), 3) << "the one in use is kept";
  ASSERT_TRUE(list.put(std::move(b)));
  EXPECT_EQ(list.trim(), 0U) << "the one in use is not freed";
  EXPECT_EQ(list.size(), 1U);
  EXPECT_EQ(list.trim(), 1U) << "unused for a whole interval: freed";
  EXPECT_TRUE(list.empty());
  EXPECT_FALSE(list.take(b));
}

}  // namespace
}  // namespace fieldguard
