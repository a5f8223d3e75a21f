#pragma once
// The middle of a set of Pipeline::process() times, as replay's summary and the daemon's status and summary
// report them.

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

#include "fieldguard/perception/obstacle.hpp"

namespace fieldguard::app {

// The median of `v` (of an even count, the upper of the two middle values), reordering `v`. `v` is not empty.
inline float median_of(std::vector<float>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// "median X ms a frame: crop X, voxel X, ..." over `times` (not empty): the whole pipeline's median and each
// stage's (each median on its own: they need not add up), in ms.
inline std::string stage_times_line(const std::vector<perception::StageTimes>& times) {
  std::vector<float> v(times.size());
  const auto median_ms = [&](float perception::StageTimes::*field) {
    for (std::size_t i = 0; i < times.size(); ++i) v[i] = times[i].*field;
    return static_cast<double>(median_of(v)) * 1e-3;
  };
  using T = perception::StageTimes;
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "median %.3f ms a frame: crop %.3f, voxel %.3f, ground %.3f, clusters %.3f, merge %.3f, boxes %.3f, "
                "near field %.3f",
                median_ms(&T::total_us), median_ms(&T::crop_us), median_ms(&T::voxel_us), median_ms(&T::ground_us),
                median_ms(&T::cluster_us), median_ms(&T::merge_us), median_ms(&T::boxes_us), median_ms(&T::near_us));
  return buf;
}

}  // namespace fieldguard::app
