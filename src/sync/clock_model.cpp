// Counter unwrapping and the lower-envelope clock fit (clock_model.hpp).

#include "fieldguard/sync/clock_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace fieldguard::sync {

std::int64_t WrapUnwrapper::unwrap(std::uint64_t raw) {
  const std::uint64_t m = kind_.modulus;
  if (m != 0 && raw >= m) {
    ++out_of_range_;
    raw %= m;
  }
  if (!last_) {
    last_raw_ = raw;
    last_ = base_.value_or(0) + static_cast<std::int64_t>(raw);
    return *last_;
  }
  std::int64_t delta = 0;
  if (m == 0) {
    delta = static_cast<std::int64_t>(raw - last_raw_);
  } else {
    // Forward distance modulo m; more than half the period forward is really a step back.
    const std::uint64_t fwd = (raw + m - last_raw_) % m;
    if (fwd > m / 2) {
      delta = -static_cast<std::int64_t>(m - fwd);
    } else {
      delta = static_cast<std::int64_t>(fwd);
      if (raw < last_raw_) ++wraps_;
    }
  }
  if (delta < 0) ++steps_back_;
  last_raw_ = raw;
  *last_ += delta;
  return *last_;
}

std::string_view ClockParams::validate() const {
  if (!(window_s > 0.0) || !(bucket_s > 0.0) || bucket_s * 2.0 > window_s) {
    return "clock: window_s and bucket_s must be positive, with at least two buckets in the window";
  }
  if (!(min_span_s >= bucket_s) || min_span_s > window_s) {
    return "clock: min_span_s must lie between bucket_s and window_s";
  }
  if (!std::isfinite(nominal_skew) || !(max_abs_skew > 0.0) || std::abs(nominal_skew) > max_abs_skew) {
    return "clock: nominal_skew must be finite and within max_abs_skew (> 0)";
  }
  if (!(jump_threshold_s > 0.0) || jump_confirm < 1) {
    return "clock: jump_threshold_s must be positive and jump_confirm at least 1";
  }
  if (latency_ns < 0) return "clock: latency_ns must not be negative";
  return {};
}

ClockModel::ClockModel(const ClockParams& params) : params_(params) {
  if (const auto problem = params_.validate(); !problem.empty()) throw std::invalid_argument(std::string(problem));
  skew_ = params_.nominal_skew;
}

std::int64_t ClockModel::offset_ns() const {
  return ref_offset_ns_ + static_cast<std::int64_t>(std::llround(a_ * 1e9));
}

Stamp ClockModel::map(std::int64_t sensor_ns) const {
  if (!ref_) return Stamp{sensor_ns};
  const double x = static_cast<double>(sensor_ns - *ref_) * 1e-9;
  const auto corr = static_cast<std::int64_t>(std::llround(model_y(x) * 1e9));
  return Stamp{sensor_ns + ref_offset_ns_ + corr - params_.latency_ns};
}

void ClockModel::reseed(std::int64_t sensor_ns, Stamp host) {
  ref_ = sensor_ns;
  ref_offset_ns_ = host.ns - sensor_ns;
  buckets_.clear();
  suspects_.clear();
  a_ = 0.0;
  skew_ = params_.nominal_skew;
}

void ClockModel::add_pair(std::int64_t sensor_ns, Stamp host) {
  ++pairs_;
  const double x = static_cast<double>(sensor_ns - *ref_) * 1e-9;
  const double y = static_cast<double>(host.ns - sensor_ns - ref_offset_ns_) * 1e-9;
  const auto index = static_cast<std::int64_t>(std::floor(x / params_.bucket_s));
  // Buckets stay sorted by index; a sample of an earlier bucket (a step back) goes where it belongs.
  auto it = buckets_.end();
  while (it != buckets_.begin() && std::prev(it)->index > index) --it;
  if (it != buckets_.begin() && std::prev(it)->index == index) {
    Bucket& b = *std::prev(it);
    if (y < b.y) {
      b.x = x;
      b.y = y;
    }
  } else {
    if (buckets_.full()) {  // a full ring would drop its first bucket: grow it (the iterator with it)
      const auto at = it - buckets_.begin();
      buckets_.set_capacity(2 * buckets_.capacity());
      it = buckets_.begin() + at;
    }
    buckets_.insert(it, Bucket{index, x, y});
  }
  const double newest = buckets_.back().x;
  while (buckets_.size() > 2 && buckets_.front().x < newest - params_.window_s) buckets_.pop_front();
}

void ClockModel::refit() {
  const auto offset_only = [this](double skew) {
    skew_ = skew;
    double a = buckets_.front().y - skew * buckets_.front().x;
    for (const Bucket& b : buckets_) a = std::min(a, b.y - skew * b.x);
    a_ = a;
  };
  const double span = buckets_.back().x - buckets_.front().x;
  if (buckets_.size() < 2 || span < params_.min_span_s) {
    offset_only(params_.nominal_skew);
    return;
  }
  // Lower convex hull of the bucket minima (monotone chain; they are sorted by x).
  std::vector<const Bucket*>& hull = hull_;
  hull.clear();
  for (const Bucket& b : buckets_) {
    while (hull.size() >= 2) {
      const Bucket& p = *hull[hull.size() - 2];
      const Bucket& q = *hull.back();
      // Drop q when it lies on or above the segment p-b.
      const double cross = (q.x - p.x) * (b.y - p.y) - (q.y - p.y) * (b.x - p.x);
      if (cross <= 0.0) {
        hull.pop_back();
      } else {
        break;
      }
    }
    hull.push_back(&b);
  }
  double xbar = 0.0;
  for (const Bucket& b : buckets_) xbar += b.x;
  xbar /= static_cast<double>(buckets_.size());
  std::size_t i = 0;
  while (i + 2 < hull.size() && hull[i + 1]->x < xbar) ++i;
  const Bucket& p = *hull[i];
  const Bucket& q = *hull[i + 1];
  const double slope = (q.y - p.y) / (q.x - p.x);
  if (!std::isfinite(slope) || std::abs(slope) > params_.max_abs_skew) {
    ++rejected_skews_;
    offset_only(params_.nominal_skew);
    return;
  }
  skew_ = slope;
  a_ = p.y - slope * p.x;
}

Mapping ClockModel::observe(std::int64_t sensor_ns, Stamp host) {
  Mapping out;
  if (!ref_) {
    reseed(sensor_ns, host);
    add_pair(sensor_ns, host);
    refit();
    out.mapped = map(sensor_ns);
    return out;
  }
  out.fitted = true;
  const Stamp predicted = map(sensor_ns);
  const double residual_s = static_cast<double>(host.ns - predicted.ns - params_.latency_ns) * 1e-9;
  if (std::abs(residual_s) > params_.jump_threshold_s) {
    suspects_.push_back(Suspect{sensor_ns, host, residual_s});
    if (suspects_.size() > static_cast<std::size_t>(params_.jump_confirm)) suspects_.pop_front();
    const auto [lo, hi] =
        std::minmax_element(suspects_.begin(), suspects_.end(),
                            [](const Suspect& a, const Suspect& b) { return a.residual_s < b.residual_s; });
    const bool agree = hi->residual_s - lo->residual_s <= params_.jump_threshold_s;
    if (suspects_.size() == static_cast<std::size_t>(params_.jump_confirm) && agree) {
      const std::deque<Suspect> pending = std::move(suspects_);
      reseed(pending.front().sensor_ns, pending.front().host);
      for (const Suspect& s : pending) add_pair(s.sensor_ns, s.host);
      refit();
      ++jumps_;
      out.jumped = true;
      out.mapped = map(sensor_ns);
      out.residual_ns = host.ns - out.mapped.ns - params_.latency_ns;
      return out;
    }
    out.suspect = true;
    out.mapped = Stamp{host.ns - params_.latency_ns};
    out.residual_ns = static_cast<std::int64_t>(std::llround(residual_s * 1e9));
    return out;
  }
  suspects_.clear();
  add_pair(sensor_ns, host);
  refit();
  out.mapped = map(sensor_ns);
  out.residual_ns = host.ns - out.mapped.ns - params_.latency_ns;
  return out;
}

}  // namespace fieldguard::sync
