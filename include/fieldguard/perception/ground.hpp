#pragma once
// What a ground segmentation gives every point, and the local ground surface it leaves behind.

#include <cstdint>

#include "fieldguard/perception/cloud.hpp"

namespace fieldguard::perception {

// A ground plane as a height field: z = a x + b y + c (sensor frame, m).
struct GroundPlane {
  float a = 0.F;
  float b = 0.F;
  float c = 0.F;
  [[nodiscard]] float z_at(float x, float y) const { return a * x + b * y + c; }
};

// Per point of the segmented cloud: 1 = ground, 0 = not; the height above the local ground (m, vertical,
// negative below it); and 1 where that ground is extrapolated far from any measured ground (so the height is
// a guess), else 0.
struct GroundLabels {
  Buffer<std::uint8_t> ground;
  Buffer<float> height_m;
  Buffer<std::uint8_t> guessed;
  void resize(std::size_t n) {
    ground.resize(n);
    height_m.resize(n);
    guessed.resize(n);
  }
};

}  // namespace fieldguard::perception
