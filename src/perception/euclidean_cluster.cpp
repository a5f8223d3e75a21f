#include "fieldguard/perception/euclidean_cluster.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "perception/euclidean_cluster_radius.hpp"

namespace fieldguard::perception {

EuclideanClusterer::EuclideanClusterer(const ClusterParams& params) : params_(params) {
  if (!(params_.tolerance_m > 0.0) || !std::isfinite(params_.tolerance_m)) {
    throw std::invalid_argument("EuclideanClusterer: tolerance_m must be positive");
  }
  // As pcl::EuclideanClusterExtraction: the tolerance goes to float, its square is taken in double and
  // handed to FLANN as float.
  const auto t = static_cast<float>(params_.tolerance_m);
  base_r2_ = static_cast<float>(static_cast<double>(t) * static_cast<double>(t));
  anisotropic_ = params_.method == ClusterMethod::Anisotropic;
  adaptive_ = params_.method == ClusterMethod::Adaptive || anisotropic_;
  apply_beams(params_.beam_spacing_deg > 0.0 ? BeamGeometry::uniform(params_.beam_spacing_deg) : BeamGeometry{}, true);
}

void EuclideanClusterer::set_beams(const BeamGeometry& beams) { apply_beams(beams, false); }

void EuclideanClusterer::apply_beams(const BeamGeometry& beams, bool configured) {
  beams_ = beams;
  per_point_ = adaptive_ && !beams_.is_uniform();
  if (!adaptive_) return;
  if (!(params_.beam_factor >= 0.0) || !(params_.horizontal_beam_factor >= 0.0)) {
    throw std::invalid_argument("EuclideanClusterer: the beam factors must not be negative");
  }
  if (!std::isfinite(params_.horizontal_max_tolerance_m)) {
    throw std::invalid_argument("EuclideanClusterer: horizontal_max_tolerance_m must be finite");
  }
  constexpr double kRadPerDeg = std::numbers::pi / 180.0;
  // Vertical: the rings' spacing (per point on uneven rings: these are its extremes). Horizontal: the configured
  // spacing, else the HDL-32E's whatever the sensor: along a ring the gaps the radius bridges are a surface's own
  // (a porous crown's), not the distance between rings.
  const double v_hi = params_.beam_factor * std::tan(beams_.max_spacing_deg() * kRadPerDeg);
  const double v_lo = params_.beam_factor * std::tan(beams_.min_spacing_deg() * kRadPerDeg);
  const double h_spacing = configured ? beams_.min_spacing_deg() : BeamGeometry{}.min_spacing_deg();
  const double h = params_.horizontal_beam_factor * std::tan(h_spacing * kRadPerDeg);
  if (configured && !(v_hi < 0.5)) {
    throw std::invalid_argument("EuclideanClusterer: beam_factor * tan(beam_spacing_deg) must be in [0, 0.5)");
  }
  if (configured && anisotropic_ && !(h < 0.5)) {
    throw std::invalid_argument(
        "EuclideanClusterer: horizontal_beam_factor * tan(beam_spacing_deg) must be in [0, 0.5)");
  }
  // A sensor's spacing held at kMaxGrowth (on a configured one that would have been an error above).
  const auto held = [](double g) { return static_cast<float>(std::min(g, static_cast<double>(kMaxGrowth))); };
  growth_ = held(v_hi);
  min_growth_ = held(v_lo);
  growth_h_ = anisotropic_ ? held(h) : 0.F;
  min_growth_h_ = growth_h_;
  cap_ = static_cast<float>(std::max(params_.max_tolerance_m, params_.tolerance_m));
  cap_h_ = anisotropic_ ? static_cast<float>(std::max(params_.horizontal_max_tolerance_m, params_.tolerance_m)) : 0.F;
}

// A radius that grows with range: tolerance_m up close, `growth` per metre of range farther out, at most `cap`.
float EuclideanClusterer::grown(float growth, float cap, float range_m) const {
  return grow(static_cast<float>(params_.tolerance_m), growth, cap, range_m);
}

EuclideanClusterer::RadiusModel EuclideanClusterer::radius_model() const {
  return {static_cast<float>(params_.tolerance_m), base_r2_, growth_, cap_, growth_h_, cap_h_, anisotropic_};
}

float EuclideanClusterer::horizontal_radius_at(float range_m) const {
  return anisotropic_ ? grown(growth_h_, cap_h_, range_m) : radius_at(range_m);
}

float EuclideanClusterer::horizontal_radius_at(float range_m, float sin_elevation) const {
  if (!per_point_) return horizontal_radius_at(range_m);
  return anisotropic_
             ? grown(growth_at(static_cast<float>(params_.horizontal_beam_factor), sin_elevation), cap_h_, range_m)
             : grown(growth_at(static_cast<float>(params_.beam_factor), sin_elevation), cap_, range_m);
}

float EuclideanClusterer::radius_at(float range_m) const {
  return adaptive_ ? grown(growth_, cap_, range_m) : static_cast<float>(params_.tolerance_m);
}

void EuclideanClusterer::extract(const Cloud& in, Clusters& out) {
  out.indices.clear();
  out.offsets.clear();
  out.offsets.push_back(0);
  if (in.empty()) return;
  if (params_.structure == ClusterStructure::KdTree) {
    prepare(in);
    extract_kdtree(in, out);
  } else {
    extract_grid(in, out);  // its own radii, in its own order (prepare only if it falls back to the k-d tree)
  }
}

// Per point: the search radius that reaches every point it may join. With the adaptive radius a farther point
// may have a larger radius than the query's; its range is at most range + d, so d < growth * (range + d)
// bounds d by growth * range / (1 - growth), and by the cap.
void EuclideanClusterer::prepare(const Cloud& in) {
  const std::size_t n = in.size();
  done_.assign(n, 0U);
  pos_of_.resize(n);
  if (!adaptive_) return;
  r2_.resize(n);
  query_.resize(n);
  if (anisotropic_) h2_.resize(n);
  // Anisotropic: each radius is at most max(t, g * range) capped, with g the larger growth and the larger cap,
  // so the same bound holds with those.
  const float g = anisotropic_ ? std::max(growth_, growth_h_) : growth_;
  const float cap = anisotropic_ ? std::max(cap_, cap_h_) : cap_;
  const float reach = g / (1.F - g);
  const RadiusModel rm = radius_model();
  const auto fv = static_cast<float>(params_.beam_factor);
  for (std::size_t i = 0; i < n; ++i) {
    const float range = std::sqrt(in.x[i] * in.x[i] + in.y[i] * in.y[i] + in.z[i] * in.z[i]);
    float v = rm.v(range), h = rm.h(range);
    if (per_point_) {  // this point's elevation's growths
      const float s = range > 0.F ? in.z[i] / range : 0.F;
      v = grow(rm.t, growth_at(fv, s), rm.cap_v, range);
      if (!anisotropic_) h = v;
    }
    r2_[i] = rm.squared(v);
    if (anisotropic_) h2_[i] = rm.squared(h);
    query_[i] = std::max(std::max(v, h), std::min(cap, reach * range));
  }
}

void EuclideanClusterer::finish_cluster(Clusters& out) {
  const std::size_t first = out.indices.size();
  out.indices.insert(out.indices.end(), queue_.begin(), queue_.end());
  std::uint32_t* b = out.indices.data() + first;
  std::uint32_t* e = out.indices.data() + out.indices.size();
  const std::size_t count = static_cast<std::size_t>(e - b);
  if (count > 64 && count * 8 > done_.size()) {
    // A large share of the cloud (a wall, a building): in order by one pass over a bitmap of the cloud.
    mark_.assign(done_.size(), 0U);
    for (const std::uint32_t* it = b; it < e; ++it) mark_[*it] = 1U;
    std::uint32_t* w = b;
    for (std::size_t i = 0; i < mark_.size(); ++i) {
      if (mark_[i] != 0U) *w++ = static_cast<std::uint32_t>(i);
    }
  } else if (e - b <= 16) {  // most clusters are a few points: insertion sort
    for (std::uint32_t* it = b + 1; it < e; ++it) {
      const std::uint32_t v = *it;
      std::uint32_t* j = it;
      for (; j > b && v < *(j - 1); --j) *j = *(j - 1);
      *j = v;
    }
  } else {
    std::sort(b, e);
  }
  out.offsets.push_back(static_cast<std::uint32_t>(out.indices.size()));
}

void EuclideanClusterer::extract_kdtree(const Cloud& in, Clusters& out) {
  const std::size_t n = in.size();
  tree_.build(in);
  const auto& pts = tree_.points();
  for (std::uint32_t p = 0; p < n; ++p) pos_of_[pts[p].index] = p;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t seed = pos_of_[i];
    if (done_[seed] != 0U) continue;
    queue_.clear();
    queue_.push_back(seed);
    done_[seed] = 1U;
    for (std::size_t qi = 0; qi < queue_.size(); ++qi) {
      const KdTree::Point& p = pts[queue_[qi]];
      if (!adaptive_) {
        tree_.radius_visit(p.x, p.y, p.z, base_r2_, [&](std::uint32_t pos, float /*d2*/) {
          if (done_[pos] != 0U) return;
          done_[pos] = 1U;
          queue_.push_back(pos);
        });
      } else if (!anisotropic_) {
        const float own = r2_[p.index];
        const float q = query_[p.index];
        tree_.radius_visit(p.x, p.y, p.z, q * q, [&](std::uint32_t pos, float d2) {
          if (done_[pos] != 0U || !(d2 < std::max(own, r2_[pts[pos].index]))) return;
          done_[pos] = 1U;
          queue_.push_back(pos);
        });
      } else {
        const float own_v = r2_[p.index], own_h = h2_[p.index];
        const float q = query_[p.index];
        tree_.radius_visit(p.x, p.y, p.z, q * q, [&](std::uint32_t pos, float /*d2*/) {
          if (done_[pos] != 0U) return;
          const KdTree::Point& o = pts[pos];
          const float dx = o.x - p.x, dy = o.y - p.y, dz = o.z - p.z;
          if (!joins_anisotropic(dx * dx + dy * dy, dz * dz, std::max(own_h, h2_[o.index]),
                                 std::max(own_v, r2_[o.index]))) {
            return;
          }
          done_[pos] = 1U;
          queue_.push_back(pos);
        });
      }
    }
    for (auto& v : queue_) v = pts[v].index;
    finish_cluster(out);
  }
}

}  // namespace fieldguard::perception
