#include "sim/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

#include "sim/hdl32e.hpp"

namespace fieldguard::sim {

namespace {
constexpr std::uint64_t kNoiseStream = 0x5e45;
constexpr std::int64_t kUsPerHour = 3600LL * 1000 * 1000;
constexpr double kListRangeM = 120.0;  // real objects farther than this from the sensor are left out
}  // namespace

int packets_per_rotation_for(double rate_hz) {
  const double packet_s = static_cast<double>(hdl32e::kPacketNs) * 1e-9;
  return std::max(1, static_cast<int>(std::lround(1.0 / (rate_hz * packet_s))));
}

Simulator::Simulator(Scene scene, const SimSettings& settings)
    : scene_(std::move(scene)),
      settings_(settings),
      caster_(scene_),
      packets_per_rotation_(packets_per_rotation_for(settings.rate_hz)) {
  threads_ = settings.threads != 0 ? settings.threads : std::min(8U, std::max(1U, std::thread::hardware_concurrency()));
  const std::size_t blocks = hdl32e::kBlocksPerPacket * static_cast<std::size_t>(packets_per_rotation_);
  directions_.resize(blocks * hdl32e::kLasers);
  const double firing_fraction = static_cast<double>(hdl32e::kFiringNs) / static_cast<double>(hdl32e::kBlockNs);
  for (std::size_t b = 0; b < blocks; ++b) {
    for (std::size_t j = 0; j < hdl32e::kLasers; ++j) {
      const double turn =
          (static_cast<double>(b) + static_cast<double>(j) * firing_fraction) / static_cast<double>(blocks);
      const double az = 2.0 * kPi * turn;  // clockwise from x
      const double el = hdl32e::kVerticalDeg[j] * kDegToRad;
      directions_[b * hdl32e::kLasers + j] = {std::cos(el) * std::cos(az), -std::cos(el) * std::sin(az), std::sin(el)};
    }
  }
  body_.reserve(directions_.size());
  for (const Vec3& d : directions_) body_.push_back(caster_.cast_body(d));
}

double Simulator::period_for(double rate_hz) {
  return static_cast<double>(packets_per_rotation_for(rate_hz) * hdl32e::kPacketNs) * 1e-9;
}

double Simulator::period_s() const { return static_cast<double>(packets_per_rotation_ * hdl32e::kPacketNs) * 1e-9; }

void Simulator::prepare_bins(std::int64_t t0_ns, std::int64_t t1_ns) {
  swept_.resize(scene_.objects.size());
  for (std::size_t i = 0; i < scene_.objects.size(); ++i) swept_[i] = scene_.objects[i].bounds;
  if (scene_.pedestrian) {
    // Where it is during the first and the last packet (it walks in a straight line in between).
    Aabb& s = swept_[scene_.pedestrian_index];
    scene_.animate(static_cast<double>(t0_ns + hdl32e::kPacketNs / 2) * 1e-9);
    s = scene_.objects[scene_.pedestrian_index].bounds;
    scene_.animate(static_cast<double>(t1_ns - hdl32e::kPacketNs / 2) * 1e-9);
    s.add(scene_.objects[scene_.pedestrian_index].bounds);
  }
  const double period = static_cast<double>(t1_ns - t0_ns) * 1e-9;
  const SensorPose mid = scene_.pose_at(static_cast<double>(t0_ns + t1_ns) * 0.5e-9);
  caster_.prepare(mid.position, std::abs(scene_.motion.speed_mps) * period * 0.5 + 0.1, swept_);
}

ObjectTruth Simulator::truth_of(const Aabb& world_box, std::int64_t t0_ns, const SensorPose& mid, bool moving,
                                std::size_t index) {
  const auto box_at = [&](double t_s) {
    Aabb box = world_box;
    if (moving) {
      scene_.animate(t_s);
      box = scene_.objects[index].bounds;
    }
    const SensorPose pose = scene_.pose_at(t_s);
    return transform_box(box, pose.rot.transposed(), pose.position);
  };
  // When did the beam sweep the object's centre? (The sensor and the object may move during the rotation.)
  const Vec3 c = mid.rot.transpose_times(world_box.center() - mid.position);
  double az = std::atan2(-c.y, c.x);
  if (az < 0.0) az += 2.0 * kPi;
  const double period_ns = static_cast<double>(packets_per_rotation_ * hdl32e::kPacketNs);
  ObjectTruth t;
  t.box = box_at((static_cast<double>(t0_ns) + az / (2.0 * kPi) * period_ns) * 1e-9);
  if (t.box.max.x > 0.0 && t.box.min.y <= 0.0 && t.box.max.y >= 0.0) {
    // Across the cut angle (straight ahead): its right side was swept at the start of the rotation and its
    // left side at the end, so the rotation holds it where it was at both times.
    const double first = (static_cast<double>(t0_ns) + 0.5 * static_cast<double>(hdl32e::kPacketNs)) * 1e-9;
    const double last = (static_cast<double>(t0_ns) + period_ns - 0.5 * static_cast<double>(hdl32e::kPacketNs)) * 1e-9;
    t.box = box_at(first);
    t.box.add(box_at(last));
  }
  t.distance_m = horizontal_distance(t.box);
  return t;
}

void Simulator::simulate_packet(std::uint64_t packet, std::uint64_t in_rotation, TimedPacket& out, Tally& tally) const {
  const std::uint64_t blocks_per_rotation =
      static_cast<std::uint64_t>(packets_per_rotation_) * hdl32e::kBlocksPerPacket;
  const std::int64_t tp_ns = static_cast<std::int64_t>(packet) * hdl32e::kPacketNs;
  const double t_mid = static_cast<double>(tp_ns + hdl32e::kPacketNs / 2) * 1e-9;
  const SceneObject* moving = nullptr;
  if (scene_.pedestrian) {
    scene_.pedestrian->parts_at(t_mid, scene_.terrain, tally.moving.parts);
    tally.moving.bounds = Aabb{};
    for (const Primitive& p : tally.moving.parts) tally.moving.bounds.add(bounds(p));
    moving = &tally.moving;
  }
  const SensorPose pose = scene_.pose_at(t_mid);
  Rng rng(settings_.seed, kNoiseStream, packet);
  std::array<EncodedBlock, hdl32e::kBlocksPerPacket> blocks{};
  for (std::size_t b = 0; b < hdl32e::kBlocksPerPacket; ++b) {
    const std::uint64_t block = in_rotation * hdl32e::kBlocksPerPacket + b;
    blocks[b].azimuth_cdeg =
        static_cast<std::uint16_t>(((72000 * block + blocks_per_rotation) / (2 * blocks_per_rotation)) % 36000);
    for (std::size_t j = 0; j < hdl32e::kLasers; ++j) {
      const std::size_t firing = block * hdl32e::kLasers + j;
      const CastHit hit = caster_.cast(pose, directions_[firing], body_[firing], rng, moving);
      const double u_drop = rng.uniform();
      const double noise = rng.normal();
      const double u_int = rng.uniform(-1.0, 1.0);
      if (hit.target == RayCaster::kNone) continue;
      const double rel = hit.range_m / scene_.noise.max_range_m;
      double p_drop = scene_.noise.dropout + rel * rel * rel * rel;
      if (hit.cos_incidence < 0.03) p_drop += 0.5;  // grazing: too little light comes back
      if (u_drop < p_drop) continue;
      const std::uint16_t d = encode_distance(hit.range_m + scene_.noise.range_sigma_m * noise);
      if (d == 0) continue;
      const double intensity = hit.reflectivity * (0.35 + 0.65 * hit.cos_incidence) * (1.0 + 0.1 * u_int);
      blocks[b].returns[j] = {d, static_cast<std::uint8_t>(std::clamp(std::lround(intensity), 1L, 255L))};
      ++tally.returns;
      if (hit.target >= 0) {
        const auto target = static_cast<std::size_t>(hit.target);
        ++tally.hits[target];
        // Where the ray really met it (the noise only moves the encoded range), against the surface there.
        const Vec3 p = pose.position + (pose.rot * directions_[firing]) * hit.range_m;
        if (p.z - scene_.terrain.height(p.x, p.y) >= kRaisedM) ++tally.raised[target];
      }
    }
  }
  const std::int64_t abs_us = absolute_ns(tp_ns + hdl32e::kLastFiringNs) / 1000;
  out = {encode_packet(blocks, static_cast<std::uint32_t>(abs_us % kUsPerHour)), abs_us * 1000};
}

FrameTruth Simulator::rotation(std::uint64_t k, std::vector<TimedPacket>& out) {
  const auto ppr = static_cast<std::uint64_t>(packets_per_rotation_);
  const std::int64_t period_ns = packets_per_rotation_ * hdl32e::kPacketNs;
  const std::int64_t t0_ns = static_cast<std::int64_t>(k) * period_ns;
  prepare_bins(t0_ns, t0_ns + period_ns);
  FrameTruth truth;

  // Packets go round-robin to the threads (neighbouring sectors cost about the same); each packet depends only
  // on its time and its own random stream, and the tallies are sums, so the result is the same on any count.
  const std::size_t first = out.size();
  out.resize(first + ppr);
  std::vector<Tally> tallies(threads_);
  for (Tally& t : tallies) {
    t.hits.assign(caster_.target_count(), 0);
    t.raised.assign(caster_.target_count(), 0);
  }
  auto work = [&](unsigned w) {
    for (std::uint64_t i = w; i < ppr; i += threads_) simulate_packet(k * ppr + i, i, out[first + i], tallies[w]);
  };
  if (threads_ == 1) {
    work(0);
  } else {
    std::vector<std::thread> pool;
    for (unsigned w = 1; w < threads_; ++w) pool.emplace_back(work, w);
    work(0);
    for (std::thread& t : pool) t.join();
  }
  hits_.assign(caster_.target_count(), 0);
  raised_.assign(caster_.target_count(), 0);
  for (const Tally& t : tallies) {
    truth.returns += t.returns;
    for (std::size_t i = 0; i < hits_.size(); ++i) {
      hits_[i] += t.hits[i];
      raised_[i] += t.raised[i];
    }
  }

  truth.frame = k;
  truth.stamp_ns = absolute_ns(t0_ns + hdl32e::kLastFiringNs) / 1000 * 1000;
  truth.period_s = period_s();
  const SensorPose mid = scene_.pose_at(static_cast<double>(t0_ns + period_ns / 2) * 1e-9);
  truth.roll_deg = mid.roll_deg;
  truth.pitch_deg = mid.pitch_deg;
  truth.sensor_world = mid.position;
  for (std::size_t i = 0; i < scene_.objects.size(); ++i) {
    const SceneObject& o = scene_.objects[i];
    const bool terrain = is_terrain(o.cls);
    if (hits_[i] == 0) {
      if (terrain) continue;
      const Aabb rel = transform_box(swept_[i], Mat3{}, mid.position);
      if (horizontal_distance(rel) > kListRangeM) continue;
    }
    const bool moving = scene_.pedestrian && i == scene_.pedestrian_index;
    ObjectTruth t = truth_of(moving ? swept_[i] : o.bounds, t0_ns, mid, moving, i);
    t.id = o.id;
    t.cls = o.cls;
    t.hits = hits_[i];
    t.raised_hits = raised_[i];
    (terrain ? truth.terrain : truth.objects).push_back(std::move(t));
  }
  for (std::size_t c = 0; c < scene_.crops.size(); ++c) {
    const std::uint32_t h = hits_[static_cast<std::size_t>(caster_.crop_target(c))];
    if (h == 0) continue;
    ObjectTruth t = truth_of(scene_.crops[c].bounds(), t0_ns, mid, false, 0);
    t.id = "crop-" + std::to_string(c + 1);
    t.cls = ObjectClass::Crop;
    t.hits = h;
    t.raised_hits = raised_[static_cast<std::size_t>(caster_.crop_target(c))];
    truth.terrain.push_back(std::move(t));
  }
  if (const std::uint32_t h = hits_[static_cast<std::size_t>(caster_.body_target())]; h > 0) {
    ObjectTruth t;
    t.id = "body";
    t.cls = ObjectClass::Body;
    for (const Primitive& p : scene_.body) t.box.add(bounds(p));
    t.hits = h;
    t.raised_hits = raised_[static_cast<std::size_t>(caster_.body_target())];
    t.distance_m = horizontal_distance(t.box);
    truth.terrain.push_back(std::move(t));
  }
  return truth;
}

}  // namespace fieldguard::sim
