#pragma once
// A sensor's own clock mapped onto the host clock.
//
// Two steps. WrapUnwrapper turns the raw, wrapping counter of a sensor (Velodyne microseconds past the hour,
// Xsens SampleTimeFine, NMEA UTC time of day, SCIP 24-bit milliseconds) into a monotonic nanosecond count.
// ClockModel then fits host = sensor + offset + skew * (sensor - ref) from (sensor time, receive time) pairs.
//
// Receive times are late by a delay that is never negative (serial framing, USB polling, scheduling), so the
// estimator is a lower envelope, not a regression: pairs are min-filtered into buckets of sensor time over a
// sliding window, and the line taken is the edge of the lower convex hull of those minima that spans their mean
// sensor time. Among all lines below every pair, that one minimises the summed distance to the pairs (the
// linear programme of Moon, Skelly and Towsley, "Estimation and removal of clock skew from network delay
// measurements", INFOCOM 1999). The mapped time is therefore "when a sample with the least delay seen would have
// arrived": a constant transport latency cannot be told from an offset and stays in, unless given as
// ClockParams::latency_ns.
//
// A pair far off the model (beyond jump_threshold) on jump_confirm consecutive samples that agree among
// themselves is a jump (sensor reset, GPS time correction, a counter wrapping while the stream was silent): the
// model is re-seeded from those samples and the jump counted. Samples under suspicion are mapped to their
// receive time (minus latency_ns) and flagged `suspect`; a lone one (a host stall) leaves the model alone.
// jump_threshold_s must exceed the spread of the receive delay, or a quiet sample after a slow start reads as
// a jump.
//
// Pure: times are passed in, never read. Thread-compatible.

#include <boost/circular_buffer.hpp>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string_view>
#include <vector>

#include "fieldguard/core/time.hpp"

namespace fieldguard::sync {

// Roll-over periods of the sensors' counters, as raw ticks, and the length of a tick.
struct CounterKind {
  std::uint64_t modulus = 0;  // raw values are in [0, modulus); 0 = does not wrap (64-bit)
  std::int64_t tick_ns = 1;
};
inline constexpr CounterKind kVelodyneMicrosPastHour{3'600'000'000ULL, 1'000};  // wraps every hour
inline constexpr CounterKind kXsensSampleTimeFine{1ULL << 32, 100'000};         // 10 kHz, ~4.97 days
inline constexpr CounterKind kXsensPacketCounter{1ULL << 16, 1};                // a count, not a time
inline constexpr CounterKind kNmeaNanosOfDay{86'400'000'000'000ULL, 1};         // UTC time of day
inline constexpr CounterKind kScipMillis{1ULL << 24, 1'000'000};                // ~4.66 hours

// Raw counter -> monotonic ticks. A step back of up to half the modulus is a step back (a late or repeated
// sample: it is returned as such and counted), a larger one is a wrap forward. Thread-compatible.
class WrapUnwrapper {
 public:
  explicit WrapUnwrapper(CounterKind kind) : kind_(kind) {}

  // Sets the unwrapped value the first raw value maps to (e.g. the hour the first Velodyne packet falls in).
  // Without it the first raw value maps to itself.
  void seed_base(std::int64_t base_ticks) { base_ = base_ticks; }

  // Monotonic ticks for `raw` (raw values >= modulus are reduced modulo it and counted as bad).
  [[nodiscard]] std::int64_t unwrap(std::uint64_t raw);
  // Nanoseconds: unwrap(raw) * tick_ns.
  [[nodiscard]] std::int64_t unwrap_ns(std::uint64_t raw) { return unwrap(raw) * kind_.tick_ns; }

  void reset() {
    last_.reset();
    base_.reset();
  }
  [[nodiscard]] std::uint64_t wraps() const { return wraps_; }
  [[nodiscard]] std::uint64_t steps_back() const { return steps_back_; }
  [[nodiscard]] std::uint64_t out_of_range() const { return out_of_range_; }
  [[nodiscard]] const CounterKind& kind() const { return kind_; }

 private:
  CounterKind kind_;
  std::optional<std::int64_t> base_;
  std::optional<std::int64_t> last_;  // unwrapped ticks of the last value
  std::uint64_t last_raw_ = 0;
  std::uint64_t wraps_ = 0;
  std::uint64_t steps_back_ = 0;
  std::uint64_t out_of_range_ = 0;
};

struct ClockParams {
  double window_s = 20.0;          // sliding window of sensor time the fit uses
  double bucket_s = 0.5;           // min-filter bucket width; the hull is taken over bucket minima
  double min_span_s = 2.0;         // below this span only the offset is fitted (skew from `nominal_skew`)
  double nominal_skew = 0.0;       // skew assumed before the span allows fitting it
  double max_abs_skew = 500e-6;    // a fitted skew beyond this is refused (the offset-only fit is used)
  double jump_threshold_s = 0.05;  // a pair this far off the model is suspect
  int jump_confirm = 3;            // consecutive agreeing suspects that make a jump
  std::int64_t latency_ns = 0;     // known constant transport latency, subtracted from the mapped time

  // Empty when valid; otherwise one message per problem.
  [[nodiscard]] std::string_view validate() const;
};

struct Mapping {
  Stamp mapped;                  // the sample's time on the host clock
  std::int64_t residual_ns = 0;  // receive time - model time of the sample, after the sample was taken in
  bool suspect = false;          // far off the model: mapped from the receive time, pending a jump decision
  bool jumped = false;           // this sample confirmed a jump; the model was re-seeded
  bool fitted = false;           // the model had at least one pair before this one (else mapped = receive time)
};

// Offset and skew of one sensor clock against the host clock. Sensor times are monotonic nanoseconds (the
// unwrapper's output). Thread-compatible.
class ClockModel {
 public:
  explicit ClockModel(const ClockParams& params = {});  // throws std::invalid_argument when invalid

  // Takes in one pair and maps its sensor time.
  Mapping observe(std::int64_t sensor_ns, Stamp host);
  // Maps a sensor time with the current model (receive-time-free; e.g. per point of a rotation).
  [[nodiscard]] Stamp map(std::int64_t sensor_ns) const;

  [[nodiscard]] bool has_model() const { return ref_.has_value(); }
  [[nodiscard]] double skew() const { return skew_; }  // host seconds per sensor second, minus 1
  [[nodiscard]] std::int64_t offset_ns() const;        // host - sensor at the reference point
  [[nodiscard]] std::uint64_t jumps() const { return jumps_; }
  [[nodiscard]] std::uint64_t pairs() const { return pairs_; }
  [[nodiscard]] std::uint64_t rejected_skews() const { return rejected_skews_; }
  [[nodiscard]] const ClockParams& params() const { return params_; }

 private:
  struct Bucket {
    std::int64_t index = 0;  // floor(sensor time / bucket width)
    double x = 0.0;          // sensor time of the minimum, s after ref
    double y = 0.0;          // host - sensor at the minimum, s after the reference offset
  };
  struct Suspect {
    std::int64_t sensor_ns = 0;
    Stamp host;
    double residual_s = 0.0;
  };
  void reseed(std::int64_t sensor_ns, Stamp host);
  void add_pair(std::int64_t sensor_ns, Stamp host);
  void refit();
  [[nodiscard]] double model_y(double x) const { return a_ + skew_ * x; }

  ClockParams params_;
  std::optional<std::int64_t> ref_;  // sensor ns of the reference point
  std::int64_t ref_offset_ns_ = 0;   // host - sensor of the first pair after a (re)seed
  // A ring, grown (doubled) only when a longer window than ever needs it: a steady stream allocates nothing.
  boost::circular_buffer<Bucket> buckets_ = boost::circular_buffer<Bucket>(16);
  std::vector<const Bucket*> hull_;  // refit()'s scratch
  double a_ = 0.0;                   // fitted y at x = 0
  double skew_ = 0.0;
  std::deque<Suspect> suspects_;
  std::uint64_t jumps_ = 0;
  std::uint64_t pairs_ = 0;
  std::uint64_t rejected_skews_ = 0;
};

// A sensor's counter and its clock model together.
class SensorClock {
 public:
  SensorClock(CounterKind kind, const ClockParams& params = {}) : unwrap_(kind), model_(params) {}

  Mapping observe_raw(std::uint64_t raw, Stamp host) { return model_.observe(unwrap_.unwrap_ns(raw), host); }
  [[nodiscard]] WrapUnwrapper& unwrapper() { return unwrap_; }
  [[nodiscard]] const WrapUnwrapper& unwrapper() const { return unwrap_; }
  [[nodiscard]] ClockModel& model() { return model_; }
  [[nodiscard]] const ClockModel& model() const { return model_; }

 private:
  WrapUnwrapper unwrap_;
  ClockModel model_;
};

}  // namespace fieldguard::sync
