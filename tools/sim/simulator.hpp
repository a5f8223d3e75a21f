#pragma once
// Runs a LiDAR (sensor.hpp: HDL-32E, VLP-16 or RS-LiDAR-32, strongest or dual return) over a scene, rotation by
// rotation, and produces its packets (with their pcap times and UDP ports) and the ground truth of each rotation.
//
// Timing: the sensor spins at the requested rate rounded so that one rotation is a whole number of packets
// (HDL-32E strongest: 10 Hz -> 181 packets = 100.09 ms; 5 Hz -> 362 packets), and the first firing of the first
// packet is at azimuth 0.00 deg: every rotation starts exactly at the 0-degree cut with block 0 of a packet. Firing
// times follow the sensor's schedule (protocols.md §1.7, §1.10, §2.2; HDL-32E: block b, laser j fires
// 46.08 b + 1.152 j us after the packet's first firing); the ray azimuth is interpolated at that time. A packet is
// recorded at the time of its LAST firing, truncated to microseconds; a Velodyne's timestamp (us past the hour)
// marks that firing too, an RS-32's header time its first firing. The RS-32 also sends a DIFOP every second from
// time 0, the first before its first data packet.
// Echoes: a ray gives the first surface it meets. In dual return, a ray that stopped in a porous volume (a crop
// canopy, a tree crown) goes on, and what it meets next is a second echo when kMinEchoSeparationM or more behind.
// Deterministic: noise, dropouts and porous-volume depths come from a random stream per packet derived
// from (seed, packet index), so the output is the same whatever the number of threads.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "sim/raycaster.hpp"
#include "sim/scene.hpp"
#include "sim/sensor.hpp"

namespace fieldguard::sim {

struct SimSettings {
  double rate_hz = 10.0;
  std::uint64_t seed = 1;
  std::int64_t start_time_ns = 0;  // Unix time of the first firing
  unsigned threads = 1;            // packets of a rotation cast on this many threads; the output does not
                                   // depend on it (0 = one per hardware thread, at most 8)
  SensorModel sensor = SensorModel::Hdl32e;
  ReturnMode returns = ReturnMode::Strongest;
  bool keep_cast_points = false;  // fill TimedPacket::cast (for tests)
};

// Two echoes of one firing nearer together than this merge into one: the sensor cannot tell them apart (an
// assumption of the simulator's; the manuals give no figure).
inline constexpr double kMinEchoSeparationM = 0.5;

// A return this high above the field surface under it is obstacle evidence; lower ones stand where clods,
// ridges and furrows stand, which the height rule (0.5 m) calls terrain. The truth counts them
// apart so that the scorer can ask whether an object showed enough of itself above that height.
inline constexpr double kRaisedM = 0.5;

// Where an encoded return lies: sensor frame, at the measured range (noise included, before the distance unit).
struct CastPoint {
  Vec3 position;
  std::size_t slot = 0;      // in its data block
  std::int64_t time_ns = 0;  // firing time after the packet's first firing
  double range_m = 0.0;      // the measured range, from the ray's start
};

struct TimedPacket {
  PacketBytes bytes;
  std::int64_t pcap_time_ns = 0;  // whole microseconds
  std::uint16_t port = 0;         // UDP source and destination port
  std::vector<CastPoint> cast;    // with SimSettings::keep_cast_points: the packet's returns, in no set order
};

struct ObjectTruth {
  std::string id;
  ObjectClass cls = ObjectClass::Implement;
  Aabb box;                       // sensor frame, when the sensor's beam swept the object's centre; for an object
                                  // across azimuth 0, the union of where it was at the rotation's start and end
  std::uint32_t hits = 0;         // firings that returned from it in this rotation (after dropouts), each once
                                  // even when both its echoes came from it
  std::uint32_t raised_hits = 0;  // of those, the ones kRaisedM or more above the field surface under them
  double distance_m = 0.0;        // horizontal, sensor origin -> nearest point of `box`
};

struct FrameTruth {
  std::uint64_t frame = 0;
  std::int64_t stamp_ns = 0;  // pcap time of the rotation's first data packet
  std::string_view sensor;    // Sensor::name
  double period_s = 0.0;
  double roll_deg = 0.0;  // attitude at mid-rotation (R = Ry(pitch) Rx(roll), sensor -> level world)
  double pitch_deg = 0.0;
  Vec3 sensor_world;                 // sensor position at mid-rotation (world frame)
  std::vector<ObjectTruth> objects;  // real objects within the sensor's range, also those with no hits
  std::vector<ObjectTruth> terrain;  // clods, ridge segments, crops and the body that have hits
  std::uint64_t returns = 0;         // points in the rotation
};

class Simulator {
 public:
  Simulator(Scene scene, const SimSettings& settings);
  Simulator(const Simulator&) = delete;  // the ray caster refers to the scene it owns
  Simulator& operator=(const Simulator&) = delete;
  Simulator(Simulator&&) = delete;
  Simulator& operator=(Simulator&&) = delete;
  ~Simulator() = default;

  // The rotation period the sensor really has at a requested rate (SceneSetup::period_s wants it).
  [[nodiscard]] static double period_for(double rate_hz, SensorModel sensor = SensorModel::Hdl32e,
                                         ReturnMode returns = ReturnMode::Strongest);
  [[nodiscard]] int packets_per_rotation() const { return packets_per_rotation_; }
  [[nodiscard]] double period_s() const;
  // Simulates rotation `k` (call with k = 0, 1, 2, ... in order): appends its packets to `out`.
  [[nodiscard]] FrameTruth rotation(std::uint64_t k, std::vector<TimedPacket>& out);
  [[nodiscard]] const Scene& scene() const { return scene_; }
  [[nodiscard]] const Sensor& sensor() const { return sensor_; }

 private:
  // What one firing returned: up to two echoes, nearer first (distance 0: none).
  struct Echo {
    EncodedReturn encoded;
    std::int64_t target = RayCaster::kNone;
    double range_m = 0.0;     // where the ray met the target
    double measured_m = 0.0;  // with the range noise
  };
  struct Firing {
    std::array<Echo, 2> echoes;
    Vec3 origin;  // of the ray, world
  };
  // What one thread gathers over its packets of a rotation.
  struct Tally {
    std::vector<std::uint32_t> hits;    // by ray-caster target
    std::vector<std::uint32_t> raised;  // by ray-caster target: hits kRaisedM or more above the surface
    std::uint64_t returns = 0;
    SceneObject moving;  // this thread's copy of the pedestrian
  };
  void prepare_bins(std::int64_t t0_ns, std::int64_t t1_ns);
  void simulate_packet(std::uint64_t packet, std::uint64_t in_rotation, TimedPacket& out, Tally& tally) const;
  [[nodiscard]] Firing fire(const SensorPose& pose, std::size_t firing, Rng& rng, const SceneObject* moving) const;
  [[nodiscard]] Echo echo_of(const CastHit& hit, Rng& rng) const;
  void count(const Firing& f, const SensorPose& pose, std::size_t firing, TimedPacket& out, Tally& tally) const;
  void add_info_packets(std::int64_t t0_ns, std::int64_t t1_ns, std::size_t first, std::vector<TimedPacket>& out) const;
  ObjectTruth truth_of(const Aabb& world_box, std::int64_t t0_ns, const SensorPose& mid, bool moving,
                       std::size_t index);
  [[nodiscard]] std::int64_t absolute_ns(std::int64_t sim_ns) const { return settings_.start_time_ns + sim_ns; }

  Scene scene_;
  SimSettings settings_;
  Sensor sensor_;
  RayCaster caster_;
  int packets_per_rotation_ = 181;
  std::vector<Vec3> origins_;     // sensor-frame ray start of every firing of a rotation, [group * 32 + slot]
  std::vector<Vec3> directions_;  // and its direction
  std::vector<CastHit> body_;     // the tractor's body along each of them
  std::vector<std::uint32_t> hits_;
  std::vector<std::uint32_t> raised_;
  std::vector<Aabb> swept_;
  unsigned threads_ = 1;
};

}  // namespace fieldguard::sim
