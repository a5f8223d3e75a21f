#pragma once
// Benchmark frames from the scene simulator (tools/sim, linked in): the UDP payloads of one rotation of a
// named scene, and that rotation decoded by our own velodyne::Stream, as replay and the daemon decode it.
// Made in memory at benchmark start: the same scene, rate and seed give the same packets on any machine
// (the simulator's output is byte-identical for a seed), so the figures need no data files.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/drivers/velodyne_stream.hpp"
#include "sim/scenes.hpp"
#include "sim/simulator.hpp"

namespace fieldguard::bench {

struct SimRotation {
  std::string scene;
  double rate_hz = 10.0;
  std::vector<sim::TimedPacket> packets;  // the rotation's data packets (UDP payloads), in order
  std::vector<LidarPoint> points;         // the rotation as velodyne::Stream emits it
};

inline velodyne::StreamOptions sim_stream_options() {
  velodyne::StreamOptions o;
  o.model = velodyne::Model::HDL32E;  // the simulator's sensor: no detection hold-back
  return o;
}

// Rotation `k` (>= 1: the stream flags rotation 0 as partial) of `scene` at `rate_hz`, seed `seed`, simulated
// as a capture of `scene_rotations` rotations (the pedestrian scenes spread their crossings over those).
inline SimRotation simulate_rotation(const std::string& scene, double rate_hz, std::uint64_t k, int scene_rotations,
                                     std::uint64_t seed = 1) {
  sim::SceneSetup setup;
  setup.seed = seed;
  setup.rotations = scene_rotations;
  setup.period_s = sim::Simulator::period_for(rate_hz);
  auto built = sim::build_scene(scene, setup);
  if (!built) throw std::invalid_argument("no simulator scene '" + scene + "'");
  sim::SimSettings settings;
  settings.rate_hz = rate_hz;
  settings.seed = seed;
  settings.start_time_ns = 1718449170LL * 1000000000LL;  // fieldguard-sim's default --start-time
  sim::Simulator simulator(std::move(*built), settings);

  SimRotation out;
  out.scene = scene;
  out.rate_hz = rate_hz;
  velodyne::Stream stream(sim_stream_options());
  std::vector<LidarFrame> frames;
  std::vector<sim::TimedPacket> packets;
  // Rotation k ends when the first packet of rotation k + 1 crosses the cut.
  for (std::uint64_t r = 0; r <= k + 1; ++r) {
    packets.clear();
    (void)simulator.rotation(r, packets);
    if (r == k) out.packets = packets;
    for (const auto& p : packets) stream.push(ByteSpan(p.bytes.data(), p.bytes.size()), Stamp{p.pcap_time_ns}, frames);
  }
  for (auto& f : frames) {
    if (f.index == k) {
      if (f.partial) throw std::runtime_error("simulated rotation came out partial");
      out.points = std::move(f.points);
      return out;
    }
  }
  throw std::runtime_error("simulated rotation not emitted by velodyne::Stream");
}

}  // namespace fieldguard::bench
