#include "sim/raycaster.hpp"

#include <algorithm>
#include <cmath>

namespace fieldguard::sim {

namespace {

constexpr double kTerrainReflectivity = 25.0;  // dry soil
constexpr double kPorousCosine = 0.7;          // foliage: no single surface orientation

int bin_of(double angle_rad, int bins) {
  double a = angle_rad / (2.0 * kPi);
  a -= std::floor(a);
  const int b = static_cast<int>(a * bins);
  return std::min(b, bins - 1);
}

}  // namespace

void RayCaster::prepare(Vec3 sensor, double margin_m, std::span<const Aabb> swept) {
  for (auto& b : bins_) b.clear();
  const double reach = scene_.noise.max_range_m + margin_m;
  for (std::size_t i = 0; i < swept.size(); ++i) {
    const Aabb& box = swept[i];
    if (box.empty()) continue;
    const double x0 = box.min.x - margin_m - sensor.x;
    const double x1 = box.max.x + margin_m - sensor.x;
    const double y0 = box.min.y - margin_m - sensor.y;
    const double y1 = box.max.y + margin_m - sensor.y;
    const double dx = std::max({x0, 0.0, -x1});
    const double dy = std::max({y0, 0.0, -y1});
    const double near = std::hypot(dx, dy);
    if (near > reach) continue;
    const Candidate cand{near, static_cast<std::uint32_t>(i)};
    if (dx == 0.0 && dy == 0.0) {  // around the sensor: every direction
      for (auto& b : bins_) b.push_back(cand);
      continue;
    }
    // The sensor is outside the rectangle: its corners span less than half a turn around the centre's bearing.
    const double ref = std::atan2(0.5 * (y0 + y1), 0.5 * (x0 + x1));
    double lo = 0.0;
    double hi = 0.0;
    for (const double cx : {x0, x1}) {
      for (const double cy : {y0, y1}) {
        double d = std::atan2(cy, cx) - ref;
        d -= 2.0 * kPi * std::floor((d + kPi) / (2.0 * kPi));
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
    }
    const int b0 = bin_of(ref + lo, kBins);
    const int b1 = bin_of(ref + hi, kBins);
    for (int b = b0;; b = (b + 1) % kBins) {
      bins_[static_cast<std::size_t>(b)].push_back(cand);
      if (b == b1) break;
    }
  }
  for (auto& b : bins_) {
    std::sort(b.begin(), b.end(), [](const Candidate& l, const Candidate& r) {
      return l.near_m < r.near_m || (l.near_m == r.near_m && l.index < r.index);
    });
  }
}

CastHit RayCaster::cast_body(Vec3 origin_sensor, Vec3 dir_sensor) const {
  CastHit hit;
  double best = scene_.noise.max_range_m;
  Span span;
  const Ray local{origin_sensor, dir_sensor};
  for (const Primitive& p : scene_.body) {
    if (intersect(p, local, best, span) && span.t_in > 0.0) {
      best = span.t_in;
      hit.target = body_target();
      hit.cos_incidence = std::abs(dot(span.normal, dir_sensor));
      hit.reflectivity = p.reflectivity;
    }
  }
  hit.range_m = best;
  return hit;
}

CastHit RayCaster::cast(const SensorPose& pose, Vec3 dir_sensor, const CastHit& body, Rng& rng,
                        const SceneObject* moving, double from_m) const {
  CastHit hit = body;
  double best = body.range_m;
  Span span;
  const Ray ray{pose.position, pose.rot * dir_sensor};
  double t = 0.0;
  if (scene_.terrain.intersect(ray, best, t)) {
    best = t;
    hit.target = kTerrain;
    hit.reflectivity = kTerrainReflectivity;
    const Vec3 p = ray.origin + ray.dir * t;
    hit.cos_incidence = std::abs(dot(scene_.terrain.normal(p.x, p.y), ray.dir));
  }
  for (std::size_t c = 0; c < scene_.crops.size(); ++c) {
    if (scene_.crops[c].intersect(ray, scene_.terrain, from_m, best, rng, t)) {
      best = t;
      hit.target = crop_target(c);
      hit.reflectivity = scene_.crops[c].params().reflectivity;
      hit.cos_incidence = kPorousCosine;
      hit.porous = true;
    }
  }
  const Vec3 inv{1.0 / ray.dir.x, 1.0 / ray.dir.y, 1.0 / ray.dir.z};
  const auto& candidates = bins_[static_cast<std::size_t>(bin_of(std::atan2(ray.dir.y, ray.dir.x), kBins))];
  const double dxy = std::sqrt(ray.dir.x * ray.dir.x + ray.dir.y * ray.dir.y);
  for (const Candidate& cand : candidates) {
    // Nothing in this bin from here on can be nearer than what the ray already hit.
    if (cand.near_m > best * dxy) break;
    const std::uint32_t i = cand.index;
    const SceneObject& o =
        moving != nullptr && scene_.pedestrian && i == scene_.pedestrian_index ? *moving : scene_.objects[i];
    double entry = 0.0;
    if (!ray_hits_aabb(ray, inv, o.bounds, best, entry)) continue;
    for (const Primitive& p : o.parts) {
      if (!intersect(p, ray, best, span)) continue;
      if (p.mean_free_path_m > 0.0) {
        const double stop = std::max(span.t_in, from_m) + rng.exponential(p.mean_free_path_m);
        if (stop >= span.t_out || stop >= best) continue;
        best = stop;
        hit.cos_incidence = kPorousCosine;
        hit.porous = true;
      } else {
        if (span.t_in <= std::max(1e-6, from_m)) continue;
        best = span.t_in;
        hit.cos_incidence = std::abs(dot(span.normal, ray.dir));
        hit.porous = false;
      }
      hit.target = static_cast<std::int64_t>(i);
      hit.reflectivity = p.reflectivity;
    }
  }
  hit.range_m = best;
  return hit;
}

}  // namespace fieldguard::sim
