#pragma once
// What the scorer reads: the detector's obstacles (fieldguard replay --obstacles-out) and the simulator's
// ground truth (fieldguard-sim --truth), one JSON line per rotation each. Boxes in the sensor frame.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace fieldguard::score {

struct Box {
  std::array<double, 3> min{};
  std::array<double, 3> max{};
};

// Horizontal distance from the sensor origin to the nearest point of the box.
[[nodiscard]] double horizontal_distance(const Box& b);
// The scorer's matching rule between an obstacle box and a truth box, with the truth box grown by `margin`
// on every side: the boxes overlap on z (touching counts), and on x and on y the overlap is no sliver: it is
// at least `min_fraction` of the shorter of the two extents on that axis (both lengths + 5 cm, so points
// and thin boxes work). The second part keeps an obstacle on one tree crown from also matching a crown
// 0.3 m away, while an obstacle that merges two crowns matches both.
[[nodiscard]] bool matches(const Box& obstacle, const Box& truth, double margin, double min_fraction);

struct Obstacle {
  Box box;
  long points = 0;  // 0 if the line does not say
};

// {"frame": i, "stamp": s, "points_in": n, "partial": bool (optional), "obstacles": [{"min", "max", "points"}]}
struct DetectionFrame {
  long frame = 0;
  double stamp = 0.0;
  bool partial = false;
  std::vector<Obstacle> obstacles;
  std::size_t line = 0;  // 1-based line in its file
};

struct TruthItem {
  std::string id;
  std::string cls;  // pedestrian implement haystack house tree crown | clod ridge crop body
  Box box;
  long hits = 0;
  long raised_hits = -1;    // returns 0.5 m or more above the surface; -1: the line does not say
  double distance_m = 0.0;  // from the line, or computed from the box if absent
};

struct TruthFrame {
  long frame = 0;
  double stamp = 0.0;
  double period_s = 0.0;  // 0 if the line does not say
  std::vector<TruthItem> objects;
  std::vector<TruthItem> terrain;
  std::size_t line = 0;
};

// Both return false and set `error` ("FILE:LINE: what is wrong") for a missing file or a bad line.
// Blank lines are skipped.
[[nodiscard]] bool read_detections(const std::string& path, std::vector<DetectionFrame>& out, std::string& error);
[[nodiscard]] bool read_truth(const std::string& path, std::vector<TruthFrame>& out, std::string& error);

}  // namespace fieldguard::score
