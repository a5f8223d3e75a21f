#pragma once
// The named scenes of fieldguard-sim. Each is fiction built to be hard in the ways real fields are: uneven
// ground, furrows, clods and banks below the detector's height filter, a tractor that rolls and pitches,
// range noise and lost returns, and objects at every distance the detector must cover.

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "sim/scene.hpp"

namespace fieldguard::sim {

struct SceneInfo {
  std::string_view name;
  std::string_view summary;  // one paragraph for --help
  int default_rotations = 100;
};

struct SceneSetup {
  std::uint64_t seed = 1;
  int rotations = 100;
  double period_s = 0.1;  // the real rotation period, Simulator::period_for(rate): the pedestrian's crossings
                          // change at rotation boundaries computed from it
};

[[nodiscard]] std::span<const SceneInfo> scene_catalog();
[[nodiscard]] const SceneInfo* find_scene(std::string_view name);
// Builds the named scene; nullopt for an unknown name.
[[nodiscard]] std::optional<Scene> build_scene(std::string_view name, const SceneSetup& setup);

// Pedestrian crossing lines of the pedestrian scenes: the body's nearest face 0.2 m beyond each of these
// distances (m), so the whole crossing stays in the 5 m band that starts there.
inline constexpr std::array<double, 6> kCrossingDistancesM{5.0, 10.0, 15.0, 20.0, 25.0, 30.0};

}  // namespace fieldguard::sim
