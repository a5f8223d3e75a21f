#include "fieldguard/perception/obstacle.hpp"

#include <algorithm>

namespace fieldguard::perception {

std::string_view to_string(SizeClass c) { return c == SizeClass::Small ? "small" : "large"; }

void sort_obstacles(std::vector<Obstacle>& obstacles) {
  std::sort(obstacles.begin(), obstacles.end(), [](const Obstacle& a, const Obstacle& b) {
    if (a.distance_m != b.distance_m) return a.distance_m < b.distance_m;
    if (a.bearing_deg != b.bearing_deg) return a.bearing_deg < b.bearing_deg;
    return a.min < b.min;
  });
}

}  // namespace fieldguard::perception
