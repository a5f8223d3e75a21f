// The catalog of named scenes; the builders are in scenes_field.cpp and scenes_objects.cpp.
#include "sim/scenes.hpp"

#include <array>

#include "sim/scene_builders.hpp"

namespace fieldguard::sim {

namespace {

constexpr std::array<SceneInfo, 8> kScenes{{
    {"flat",
     "flat bare ground (no furrows, no slope), the tractor's body, a parked implement at 11-14 m "
     "ahead and a round bale at 8 m front-left; stationary, level; 1 cm noise, 1% dropouts. For "
     "checking the decoder against the simulator.",
     20},
    {"pedestrian",
     "a person walking across the path at 5, 10, 15, 20, 25 and 30 m (nearest face 0.2 m beyond "
     "each), one crossing per sixth of the rotations, y from -8 to +8 m (slower when rotations are "
     "many, shorter when few); furrowed field (3 cm) with clods up to 25 cm, 1-2% grade and a "
     "climb of +5% from 22 m on; stationary tractor standing on the slope (about 0.2 deg roll, "
     "2.5 deg nose up) with a little vibration; 1.5 cm noise, 2% dropouts.",
     720},
    {"rough",
     "bare rough field for ground false detections: furrows 4.5 cm at 30 deg to the path, clods up "
     "to 40 cm (0.08/m2 small, 0.01/m2 large), a 35 cm field ridge 5.5 m left of the path all along, "
     "a 30 cm bank on the right from 30 to 90 m, a ridge crossing the path near the end of the run, "
     "undulating ground (0.25 m over 70 m, 0.1 m over 31 m) with a +4% climb from 90 m; the tractor "
     "drives at 1.6 m/s rocking 3.5 deg in roll and 3 deg in pitch (periods 5.3 s and 3.7 s, rms "
     "about 3 deg; with the ground's own slope up to 6 and 8 deg) plus vibration; 2 cm noise, 3% "
     "dropouts.",
     1000},
    {"rough-pedestrian",
     "the pedestrian crossings of 'pedestrian' on the rough field of 'rough' (clods to 40 "
     "cm, a ridge 9.5 m left), the tractor standing on it at 3.5 deg roll and -3 deg pitch "
     "(nose up) with slow rocking and vibration; 2 cm noise, 3% dropouts.",
     720},
    {"farmyard",
     "driving at 1.5 m/s along a stubble field past a parked implement (22 m, right), a round "
     "bale (14 m, left), a stack of five bales (48 m, right), a farm house (75 m, 6.5 m left), "
     "roadside trees every ~11 m on the right from 30 m, and a crop block (0.5-0.8 m, from 95 m "
     "on the left, 2.5 m from the path); 1.5 cm noise, 2% dropouts.",
     600},
    {"orchard",
     "driving at 0.8 m/s up the middle alley of an orchard: four rows (y = -8.2, -3.7, 3.7, 8.2 m) "
     "of porous crowns 1.5-3.5 m across on trunks from 8 m ahead, 45% of neighbours only 0.3-0.5 m "
     "apart; grass tracks, few clods; 1.5 cm noise, 2% dropouts.",
     400},
    {"shed",
     "the tractor parked in a machine shed (walls 12 m behind to 18 m ahead, 9 m to either side, "
     "roof at 5.5 m) with an implement, bales and a person standing: nearly every ray returns (about "
     "69,000 points per rotation at 10 Hz, 138,000 at 5 Hz), for benchmarks; 1 cm noise, 0.3% "
     "dropouts. The walls and roof are objects of class house.",
     50},
    {"uneven-drive",
     "the sensor-fusion scene (use --session): the LiDAR on a mast 1.8 m up at the front, the "
     "tractor driving 1.5 m/s across an uneven field (swells up to 0.45 m, rocking with the "
     "speed: roll and pitch up to 8 deg), past a pole (0.1 x 0.1 x 2 m, 3 m left of the path, "
     "halfway), then braking to stand for the last quarter of the run (at most 6 s) with a low "
     "box (0.4 m tall, 0.6 m wide, 0.4 m deep) 1 m in front of its bumper: below the LiDAR's "
     "lowest beam, in the bumper 2D LiDAR's plane; 1.5 cm noise, 2% dropouts.",
     600},
}};

}  // namespace

std::span<const SceneInfo> scene_catalog() { return kScenes; }

const SceneInfo* find_scene(std::string_view name) {
  for (const SceneInfo& s : kScenes) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

std::optional<Scene> build_scene(std::string_view name, const SceneSetup& setup) {
  if (name == "flat") return detail::flat(setup);
  if (name == "pedestrian") return detail::pedestrian(setup);
  if (name == "rough") return detail::rough(setup);
  if (name == "rough-pedestrian") return detail::rough_pedestrian(setup);
  if (name == "farmyard") return detail::farmyard(setup);
  if (name == "orchard") return detail::orchard(setup);
  if (name == "shed") return detail::shed(setup);
  if (name == "uneven-drive") return detail::uneven_drive(setup);
  return std::nullopt;
}

}  // namespace fieldguard::sim
