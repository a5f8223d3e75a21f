#pragma once
// The middle of a set of Pipeline::process() times, as replay's summary and the daemon's status report them.

#include <algorithm>
#include <cstddef>
#include <vector>

namespace fieldguard::app {

// The median of `v` (of an even count, the upper of the two middle values), reordering `v`. `v` is not empty.
inline float median_of(std::vector<float>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace fieldguard::app
