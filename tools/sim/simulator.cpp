#include "sim/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <thread>
#include <tuple>

namespace fieldguard::sim {

namespace {
constexpr std::uint64_t kNoiseStream = 0x5e45;
constexpr double kListRangeM = 120.0;  // real objects farther than this from the sensor are left out
}  // namespace

Simulator::Simulator(Scene scene, const SimSettings& settings)
    : scene_(std::move(scene)),
      settings_(settings),
      sensor_(make_sensor(settings.sensor, settings.returns)),
      caster_(scene_),
      packets_per_rotation_(sensor_.packets_per_rotation(settings.rate_hz)) {
  threads_ = settings.threads != 0 ? settings.threads : std::min(8U, std::max(1U, std::thread::hardware_concurrency()));
  const std::size_t groups = sensor_.groups_per_packet() * static_cast<std::size_t>(packets_per_rotation_);
  origins_.resize(groups * kSlots);
  directions_.resize(groups * kSlots);
  for (std::size_t g = 0; g < groups; ++g) {
    for (std::size_t s = 0; s < kSlots; ++s) {
      const double turn = (static_cast<double>(g) + sensor_.slot_fraction[s]) / static_cast<double>(groups);
      const double a0 = 2.0 * kPi * turn;  // the firing azimuth, clockwise from x
      const double az = a0 + sensor_.horizontal_deg[s] * kDegToRad;
      const double el = sensor_.vertical_deg[s] * kDegToRad;
      const double r = sensor_.optical_centre_m;
      origins_[g * kSlots + s] = {r * std::cos(a0), -r * std::sin(a0), 0.0};
      directions_[g * kSlots + s] = {std::cos(el) * std::cos(az), -std::cos(el) * std::sin(az), std::sin(el)};
    }
  }
  body_.reserve(directions_.size());
  for (std::size_t i = 0; i < directions_.size(); ++i) body_.push_back(caster_.cast_body(origins_[i], directions_[i]));
}

double Simulator::period_for(double rate_hz, SensorModel sensor, ReturnMode returns) {
  const Sensor s = make_sensor(sensor, returns);
  return static_cast<double>(s.packets_per_rotation(rate_hz) * s.packet_ns()) * 1e-9;
}

double Simulator::period_s() const { return static_cast<double>(packets_per_rotation_ * sensor_.packet_ns()) * 1e-9; }

void Simulator::prepare_bins(std::int64_t t0_ns, std::int64_t t1_ns) {
  swept_.resize(scene_.objects.size());
  for (std::size_t i = 0; i < scene_.objects.size(); ++i) swept_[i] = scene_.objects[i].bounds;
  if (scene_.pedestrian) {
    // Where it is during the first and the last packet (it walks in a straight line in between).
    Aabb& s = swept_[scene_.pedestrian_index];
    scene_.animate(static_cast<double>(t0_ns + sensor_.packet_ns() / 2) * 1e-9);
    s = scene_.objects[scene_.pedestrian_index].bounds;
    scene_.animate(static_cast<double>(t1_ns - sensor_.packet_ns() / 2) * 1e-9);
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
  const double period_ns = static_cast<double>(packets_per_rotation_ * sensor_.packet_ns());
  const auto packet_ns = static_cast<double>(sensor_.packet_ns());
  ObjectTruth t;
  t.box = box_at((static_cast<double>(t0_ns) + az / (2.0 * kPi) * period_ns) * 1e-9);
  if (t.box.max.x > 0.0 && t.box.min.y <= 0.0 && t.box.max.y >= 0.0) {
    // Across the cut angle (straight ahead): its right side was swept at the start of the rotation and its
    // left side at the end, so the rotation holds it where it was at both times.
    const double first = (static_cast<double>(t0_ns) + 0.5 * packet_ns) * 1e-9;
    const double last = (static_cast<double>(t0_ns) + period_ns - 0.5 * packet_ns) * 1e-9;
    t.box = box_at(first);
    t.box.add(box_at(last));
  }
  t.distance_m = horizontal_distance(t.box);
  return t;
}

Simulator::Echo Simulator::echo_of(const CastHit& hit, Rng& rng) const {
  // The same three draws whether or not the ray met anything.
  const double u_drop = rng.uniform();
  const double noise = rng.normal();
  const double u_int = rng.uniform(-1.0, 1.0);
  if (hit.target == RayCaster::kNone) return {};
  const double rel = hit.range_m / scene_.noise.max_range_m;
  double p_drop = scene_.noise.dropout + rel * rel * rel * rel;
  if (hit.cos_incidence < 0.03) p_drop += 0.5;  // grazing: too little light comes back
  if (u_drop < p_drop) return {};
  const double measured = hit.range_m + scene_.noise.range_sigma_m * noise;
  const std::uint16_t d = measured >= sensor_.min_range_m ? sensor_.encode_distance(measured) : 0;
  if (d == 0) return {};
  const double intensity = hit.reflectivity * (0.35 + 0.65 * hit.cos_incidence) * (1.0 + 0.1 * u_int);
  const auto encoded_intensity = static_cast<std::uint8_t>(std::clamp(std::lround(intensity), 1L, 255L));
  return {{d, encoded_intensity}, hit.target, hit.range_m, measured};
}

Simulator::Firing Simulator::fire(const SensorPose& pose, std::size_t firing, Rng& rng,
                                  const SceneObject* moving) const {
  SensorPose from = pose;
  from.position = pose.position + pose.rot * origins_[firing];
  Firing f;
  f.origin = from.position;
  const CastHit hit = caster_.cast(from, directions_[firing], body_[firing], rng, moving);
  f.echoes[0] = echo_of(hit, rng);
  if (!sensor_.dual() || !hit.porous) return f;
  // Part of the beam went on through the porous volume: what it meets next echoes too.
  const CastHit behind = caster_.cast(from, directions_[firing], body_[firing], rng, moving, hit.range_m);
  const Echo second = echo_of(behind, rng);
  if (behind.range_m - hit.range_m >= kMinEchoSeparationM) f.echoes[1] = second;
  return f;
}

void Simulator::count(const Firing& f, const SensorPose& pose, std::size_t firing, TimedPacket& out,
                      Tally& tally) const {
  // Every echo is a point; a target counts one hit per firing, however many of its echoes came from it.
  std::int64_t counted = RayCaster::kNone;
  for (const Echo& e : f.echoes) {
    if (e.encoded.distance == 0) continue;
    ++tally.returns;
    if (settings_.keep_cast_points) {
      const std::size_t slot = firing % kSlots;
      const auto group = static_cast<std::int64_t>(firing / kSlots % sensor_.groups_per_packet());
      out.cast.push_back({origins_[firing] + directions_[firing] * e.measured_m, slot,
                          group * sensor_.group_ns + sensor_.slot_ns[slot], e.measured_m});
    }
    if (e.target < 0 || e.target == counted) continue;
    counted = e.target;
    const auto target = static_cast<std::size_t>(e.target);
    ++tally.hits[target];
    // Where the ray really met it (the noise only moves the encoded range), against the surface there.
    const Vec3 p = f.origin + (pose.rot * directions_[firing]) * e.range_m;
    if (p.z - scene_.terrain.height(p.x, p.y) >= kRaisedM) ++tally.raised[target];
  }
}

void Simulator::simulate_packet(std::uint64_t packet, std::uint64_t in_rotation, TimedPacket& out, Tally& tally) const {
  const std::size_t groups = sensor_.groups_per_packet();
  const std::uint64_t groups_per_rotation = static_cast<std::uint64_t>(packets_per_rotation_) * groups;
  const std::int64_t tp_ns = static_cast<std::int64_t>(packet) * sensor_.packet_ns();
  const double t_mid = static_cast<double>(tp_ns + sensor_.packet_ns() / 2) * 1e-9;
  const SceneObject* moving = nullptr;
  if (scene_.pedestrian) {
    scene_.pedestrian->parts_at(t_mid, scene_.terrain, tally.moving.parts);
    tally.moving.bounds = Aabb{};
    for (const Primitive& p : tally.moving.parts) tally.moving.bounds.add(bounds(p));
    moving = &tally.moving;
  }
  const SensorPose pose = scene_.pose_at(t_mid);
  Rng rng(settings_.seed, kNoiseStream, packet);
  PacketBlocks blocks{};
  out.cast.clear();
  for (std::size_t g = 0; g < groups; ++g) {
    const std::uint64_t group = in_rotation * groups + g;
    // In dual return the group fills a pair of blocks, both with its azimuth.
    EncodedBlock& first = blocks[sensor_.dual() ? 2 * g : g];
    EncodedBlock& second = blocks[sensor_.dual() ? 2 * g + 1 : g];
    first.azimuth_cdeg =
        static_cast<std::uint16_t>(((72000 * group + groups_per_rotation) / (2 * groups_per_rotation)) % 36000);
    second.azimuth_cdeg = first.azimuth_cdeg;
    for (std::size_t s = 0; s < kSlots; ++s) {
      const std::size_t firing = group * kSlots + s;
      const Firing f = fire(pose, firing, rng, moving);
      count(f, pose, firing, out, tally);
      if (sensor_.dual()) {
        std::tie(first.returns[s], second.returns[s]) = sensor_.dual_pair(f.echoes[0].encoded, f.echoes[1].encoded);
      } else {
        first.returns[s] = f.echoes[0].encoded;
      }
    }
  }
  const std::int64_t first_ns = absolute_ns(tp_ns);
  out.bytes = sensor_.encode(blocks, first_ns);
  out.pcap_time_ns = (first_ns + sensor_.last_firing_ns()) / 1000 * 1000;
  out.port = sensor_.data_port;
}

void Simulator::add_info_packets(std::int64_t t0_ns, std::int64_t t1_ns, std::size_t first,
                                 std::vector<TimedPacket>& out) const {
  if (sensor_.info_port == 0) return;
  // Those due in [t0_ns, t1_ns), each before the first data packet recorded after it: the one at time 0 before any.
  const std::int64_t period = sensor_.info_period_ns;
  for (std::int64_t t = (t0_ns + period - 1) / period * period; t < t1_ns; t += period) {
    TimedPacket p;
    p.bytes = sensor_.encode_info(settings_.rate_hz, absolute_ns(t));
    p.pcap_time_ns = absolute_ns(t) / 1000 * 1000;
    p.port = sensor_.info_port;
    const auto later = std::find_if(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(),
                                    [&](const TimedPacket& q) { return q.pcap_time_ns > p.pcap_time_ns; });
    out.insert(later, std::move(p));
  }
}

FrameTruth Simulator::rotation(std::uint64_t k, std::vector<TimedPacket>& out) {
  const auto ppr = static_cast<std::uint64_t>(packets_per_rotation_);
  const std::int64_t period_ns = packets_per_rotation_ * sensor_.packet_ns();
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
  add_info_packets(t0_ns, t0_ns + period_ns, first, out);
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
  truth.stamp_ns = absolute_ns(t0_ns + sensor_.last_firing_ns()) / 1000 * 1000;
  truth.sensor = sensor_.name;
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
