#pragma once
// Small time helpers of the live sources. Private to the io module.

#include <chrono>
#include <cstdint>

#include "fieldguard/core/time.hpp"

namespace fieldguard::io::detail {

// Seconds from the configuration as a steady-clock duration, for timers.
[[nodiscard]] inline std::chrono::steady_clock::duration seconds(double s) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(s));
}

// Wall-clock receive time, in the project's Stamp unit (ns since the epoch).
[[nodiscard]] inline std::int64_t now_ns() { return wall_clock_now().ns; }

}  // namespace fieldguard::io::detail
