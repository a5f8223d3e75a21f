#pragma once
// The vehicle's pose over time: attitude samples (AHRS, ~100 Hz, vehicle -> plane rotation) and
// reference-point positions (GNSS after the lever arm, 5-10 Hz, plane frame), each interpolated at any
// instant: attitude by slerp between the two samples that bracket it, position linearly.
//
// An instant outside the samples is answered from the end sample (attitude held, position continued at
// the last velocity) for a short time and flagged `extrapolated`; farther out it is refused. Two bracketing
// samples farther apart than the gap limit are refused too (a dropout, not a motion to interpolate over).
// Refusals are values (TrackError), never exceptions.
//
// Thread-compatible: one writer, or several readers of a track nobody writes.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fieldguard/core/expected.hpp"
#include "fieldguard/core/time.hpp"

namespace fieldguard::geo {

struct TrackParams {
  double max_attitude_gap_s = 0.05;            // AHRS at 100 Hz: 5 samples lost in a row is a gap
  double max_attitude_extrapolation_s = 0.02;  // hold the first/last attitude this long
  double max_position_gap_s = 0.5;             // GNSS at 5 Hz: 2 fixes lost in a row is a gap
  double max_position_extrapolation_s = 0.25;  // continue the last velocity this long
  std::size_t max_samples = 4096;              // per kind; the oldest go first (~40 s of AHRS at 100 Hz)

  [[nodiscard]] std::vector<std::string> validate() const;
};

enum class TrackError : std::uint8_t {
  Empty,        // no sample of this kind yet
  BeforeStart,  // earlier than the first sample by more than the extrapolation limit
  AfterEnd,     // later than the last sample by more than the extrapolation limit
  Gap,          // the bracketing samples are farther apart than the gap limit
};
[[nodiscard]] const char* to_string(TrackError e);

struct AttitudeAt {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  // vehicle -> plane
  bool extrapolated = false;
};

struct PositionAt {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  // reference point, plane frame
  bool extrapolated = false;
};

struct Pose {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  bool extrapolated = false;
};

class PoseTrack {
 public:
  explicit PoseTrack(const TrackParams& params = {});  // throws std::invalid_argument when invalid

  // False (and counted) for a sample not later than the last one of its kind or with a non-finite value.
  bool add_attitude(Stamp t, const Eigen::Quaterniond& vehicle_in_plane);
  bool add_position(Stamp t, const Eigen::Vector3d& reference_in_plane);

  [[nodiscard]] Expected<AttitudeAt, TrackError> attitude_at(Stamp t) const;
  [[nodiscard]] Expected<PositionAt, TrackError> position_at(Stamp t) const;
  [[nodiscard]] Expected<Pose, TrackError> pose_at(Stamp t) const;

  // Forgets samples no longer needed to answer instants at or after t (keeps the one before t).
  void drop_before(Stamp t);
  // Forgets every sample and count; the room stays for the next samples (a track reused frame after frame).
  void clear();

  [[nodiscard]] std::size_t attitude_count() const { return att_.size(); }
  [[nodiscard]] std::size_t position_count() const { return pos_.size(); }
  [[nodiscard]] std::uint64_t rejected_out_of_order() const { return rejected_order_; }
  [[nodiscard]] std::uint64_t rejected_not_finite() const { return rejected_finite_; }
  [[nodiscard]] const TrackParams& params() const { return params_; }

 private:
  struct AttSample {
    std::int64_t t_ns;
    Eigen::Quaterniond q;
  };
  struct PosSample {
    std::int64_t t_ns;
    Eigen::Vector3d p;
  };
  TrackParams params_;
  std::int64_t att_gap_ns_;
  std::int64_t att_extra_ns_;
  std::int64_t pos_gap_ns_;
  std::int64_t pos_extra_ns_;
  std::vector<AttSample> att_;  // vectors, not deques: a cleared track refills without allocating
  std::vector<PosSample> pos_;
  std::uint64_t rejected_order_ = 0;
  std::uint64_t rejected_finite_ = 0;
};

}  // namespace fieldguard::geo
