#pragma once
// Ground that holds on real fields: local planes on a polar grid of concentric zones (after Patchwork++'s
// concentric zone model), each bin's plane grown out of the plane of the bin inside it.
//
// Bins are visited from the sensor outwards. A bin's prior is the plane of the bin just inside it (for the
// innermost ring: one plane fitted to that whole ring, starting level at -sensor_height, its tilt within
// max_tilt_deg). Seeds are the bin's lowest points measured along the prior's slope. A plane z = a x + b y + c
// is fitted to them by least squares with a slope prior: the prior's slope, except along the line from where
// the prior was fitted to these points, where it is the rise between the two (far out, rings reach the
// ground metres apart, and their heights are what shows the ground bending). A bin seen by one scan ring,
// whose points hardly spread across the ring, so keeps that slope and fits only its height. It is then
// refitted to the points within fit_distance_m below and half that above it (the ground is the lower
// envelope: a ridge's flank does not draw the plane up). The bin keeps its own plane only when it is a
// ground plane: not steeper than max_slope_deg, its slope within max_slope_change_deg of the prior's, its
// points spread over at least min_spread_m (a person's legs do not), and its height continuing the prior's
// (within max_step_m plus the rise of max_slope_change_deg over the distance: a haystack, a crop block, a
// building do not), and, with max_below_m, none of the bin's own points more than that below it (the ground is
// the lower envelope: behind a tree row the next row's crowns give a flat "ground" of horizontal-laser returns
// with a lower laser's return under it). Otherwise it continues the prior's plane. Once every bin is done, a
// bin without its own plane gets the planes around it (continued from inside, the first fitted bin outside it,
// the nearest fitted ones either side in its ring) blended by inverse distance. Every point then gets its
// height above its bin's plane (with blend_radial: that plane interpolated with the fitted plane of the bin
// beyond it on the point's side, inwards or outwards, by distance from the point to where each was fitted),
// is ground below ground_threshold_m, and is flagged `guessed` where its bin's ground lies farther than
// max_extrapolation_m from any measured ground. The surface is kept: ground_z(x, y) answers for any (x, y).
// Thread-compatible.

#include <cstdint>
#include <vector>

#include "fieldguard/perception/cloud.hpp"
#include "fieldguard/perception/ground.hpp"
#include "fieldguard/perception/params.hpp"

namespace fieldguard::perception {

class ZoneGround {
 public:
  // Throws std::invalid_argument for a zone layout that is not one (edges not increasing, list lengths that
  // do not match, no rings or sectors).
  explicit ZoneGround(const ZoneParams& params);

  void segment(const Cloud& in, GroundLabels& out);

  // The local ground of the last frame under (x, y): the plane of the bin (x, y) falls in.
  [[nodiscard]] GroundPlane plane_at(float x, float y) const;
  [[nodiscard]] float ground_z(float x, float y) const { return plane_at(x, y).z_at(x, y); }
  // True when that bin's plane was fitted to its own points (not continued from the bin inside it).
  [[nodiscard]] bool fitted_at(float x, float y) const;
  // How far that bin's ground is from where it was measured (0 for a fitted bin, m).
  [[nodiscard]] float support_at(float x, float y) const;
  [[nodiscard]] std::size_t bin_count() const { return bins_.size(); }
  [[nodiscard]] std::uint32_t bin_of(float x, float y) const;
  [[nodiscard]] std::uint32_t bin_of_polar(float r, float theta) const;
  // bin_of for every point of `in` into `out` (resized): four at a time, the same arithmetic lane by lane, so the
  // same bins.
  void bins_of(const Cloud& in, Buffer<std::uint32_t>& out) const;
  // After segment(in, ...): the labels again, one point at a time in cloud order (segment() works bin by bin, four
  // points at a time, with the same arithmetic lane by lane: the same bits). For tests.
  void label_one_at_a_time(const Cloud& in, GroundLabels& out) const;

 private:
  struct Zone {
    float r0, r1;  // m
    float inv_ring_width;
    std::uint32_t rings, sectors, first_bin;
    float sector_scale;          // sectors / (2 pi)
    float max_ring, max_sector;  // just below rings, sectors
  };
  struct Bin {
    GroundPlane plane;
    float ref_x = 0.F, ref_y = 0.F;  // where the plane was last fitted (its points' centroid)
    float center_x = 0.F, center_y = 0.F;
    float support_m = 0.F;  // from the centre to the nearest place a plane it uses was fitted
    bool fitted = false;
  };
  struct Fit {
    GroundPlane plane;
    float mean_x = 0.F, mean_y = 0.F;
    std::uint32_t count = 0;
    GroundPlane sel;  // fitted to the points whose residual to sel lies in [lo, hi)
    float lo = 0.F, hi = 0.F;
  };

  GroundPlane fit_innermost();
  void fit_bin(std::uint32_t bin, const Bin& prior);
  [[nodiscard]] Fit least_squares(const GroundPlane& sel, float lo, float hi, const GroundPlane& prior,
                                  double prior_per_point) const;
  [[nodiscard]] float spread(const Fit& f, float deepest, bool& below) const;
  void residuals(const GroundPlane& plane, float* out) const;
  void sort_into_bins(const Cloud& in);
  void gather_innermost(std::uint32_t b0, std::uint32_t b1);
  void interpolate_gaps();
  void label(const Cloud& in, GroundLabels& out);
  void label_point(const Cloud& in, std::uint32_t i, GroundLabels& out) const;

  ZoneParams params_;
  std::vector<Zone> zones_;
  static constexpr std::uint32_t kNoBin = 0xFFFFFFFFU;
  std::vector<Bin> bins_;
  std::vector<std::uint32_t> inner_, outer_;  // per bin: the bin just inside / outside it, or kNoBin
  std::vector<GroundPlane> filled_;
  // Per bin, once its plane is final: what labelling a point in it needs, in one place (the per-point work was the
  // bin's plane, its neighbours' and their `fitted` flags, looked up point by point).
  struct Label {
    GroundPlane plane;
    float ref_x, ref_y, ref_r2;  // where its plane was fitted, and that place's squared range
    std::uint32_t outer, inner;  // the bin outside / inside it when that one has its own plane, else kNoBin
    std::uint8_t guessed;        // GroundLabels::guessed for its points
  };
  std::vector<Label> label_;
  float sensor_height_m_;
  float tan_max_slope_ = 0.F, tan_max_tilt_ = 0.F, tan_max_change_ = 0.F;
  // Scratch, reused across frames.
  Buffer<std::uint32_t> bin_of_point_;
  // The points sorted by bin (input order within one), each bin's run padded to a multiple of four with points
  // no selection takes (a million metres above its first): least_squares reads a bin four points at a time
  // where it lies, without copying it out first.
  Buffer<std::uint32_t> bin_count_;
  Buffer<std::uint32_t> bin_start_;  // per bin (and one past the last): where its run starts in sx_ .. sz_
  Buffer<std::uint32_t> cursor_;
  Buffer<float> sx_, sy_, sz_;
  Buffer<std::uint32_t> sidx_;            // per sorted point: its index in the cloud (padding: unset)
  Buffer<float> bx_, by_, bz_, tmp_;      // the innermost ring's points (padded), and scratch
  Buffer<std::uint32_t> select_scratch_;  // nth_element_branchfree's
  // The points least_squares and fit_bin look at: one bin's run, or the innermost ring's.
  struct Points {
    const float* x = nullptr;
    const float* y = nullptr;
    const float* z = nullptr;
    std::size_t n = 0;       // points
    std::size_t padded = 0;  // n rounded up to a multiple of four: readable, the rest never selected
  };
  Points pts_;
};

}  // namespace fieldguard::perception
