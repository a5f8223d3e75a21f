#pragma once
// Contents of SCIP 2.0 replies (protocols.md §3.1-§3.5): VV/PP/II text fields, scans of MD/ME/MS/GD/GE/GS,
// step angles, 2D points and the sensor's 24-bit millisecond clock. Pure functions over parsed replies; every
// malformed content is a returned Error.

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/core/expected.hpp"
#include "fieldguard/drivers/scip.hpp"

namespace fieldguard::scip {

using InfoMap = std::map<std::string, std::string, std::less<>>;

// VV / PP / II (status 00): each payload line "LABEL:value;" (the ';' optional) as label -> value.
// NotThisReply for any other reply, BadField for a line without ':' or an empty label.
[[nodiscard]] Expected<InfoMap, Error> decode_info(const Reply& reply);

// PP, typed. Defaults are the UTM-30LX-EW's reply.
struct Parameters {
  std::string model;              // MODL
  std::uint32_t dmin_mm = 23;     // DMIN: shorter values are error codes, not distances
  std::uint32_t dmax_mm = 60000;  // DMAX
  std::uint32_t ares = 1440;      // ARES: steps in a full turn
  std::uint32_t amin = 0;         // AMIN: first measurable step
  std::uint32_t amax = 1080;      // AMAX: last measurable step
  std::uint32_t afrt = 540;       // AFRT: step of the front
  std::uint32_t scan_rpm = 2400;  // SCAN
};
// BadField when DMIN..SCAN is missing or not a decimal number, or the values contradict each other
// (ares 0, amin > afrt, afrt > amax, dmin > dmax). MODL may be missing (empty).
[[nodiscard]] Expected<Parameters, Error> decode_parameters(const Reply& reply);

// One scan. ranges_mm[i] (and intensities[i]) belong to step first_step + i * cluster (the first step of the
// cluster, as urg_c urg_index2rad and hokuyolx get_angles count them).
struct Scan {
  Command command = Command::MD;
  std::uint32_t timestamp_ms = 0;  // sensor clock, 24 bits: wraps every 16 777.216 s
  std::uint16_t first_step = 0;
  std::uint16_t last_step = 0;
  std::uint8_t cluster = 1;          // 1..99 (an echoed 0 reads as 1)
  std::uint8_t remaining_scans = 0;  // MD/ME/MS echo: scans still to come (0 with a request of 0 = until QT)
  std::string status;                // "99" for MD/ME/MS, "00" for GD/GE/GS
  std::vector<std::uint32_t> ranges_mm;
  std::vector<std::uint32_t> intensities;  // ME/GE only
  [[nodiscard]] std::uint16_t step_of(std::size_t i) const {
    return static_cast<std::uint16_t>(first_step + i * cluster);
  }
};

// Number of values a scan over first..last with `cluster` carries: ceil((last - first + 1) / cluster).
[[nodiscard]] std::size_t values_in_scan(std::uint16_t first_step, std::uint16_t last_step, std::uint8_t cluster);

// A scan reply (MD/ME/MS with status 99, GD/GE/GS with status 00 and data) to a Scan. The data lines are
// concatenated after their check characters are stripped (the parser did), so a value may straddle two lines.
// NotThisReply for anything else (MD's 00 acknowledgement, an error status, VV...).
[[nodiscard]] Expected<Scan, Error> decode_scan(const Reply& reply);

// Step -> angle: theta = (step - front_step) * 360 deg / steps_per_turn, counter-clockwise seen from above
// (x forward, y left; urg_c calculate_xy.c and hokuyolx get_angles). UTM-30LX-EW: 0.25 deg a step, front 540.
struct Geometry {
  std::uint32_t dmin_mm = 23;
  std::uint32_t dmax_mm = 60000;
  double front_step = 540.0;
  double steps_per_turn = 1440.0;
  [[nodiscard]] static Geometry from(const Parameters& p);
};
[[nodiscard]] double step_angle_rad(double step, const Geometry& g = {});
[[nodiscard]] double step_angle_deg(double step, const Geometry& g = {});

struct Point2 {
  float x_m = 0.F;  // forward
  float y_m = 0.F;  // left
  float range_m = 0.F;
  float angle_rad = 0.F;  // counter-clockwise from x
  std::uint16_t step = 0;
  std::uint32_t intensity = 0;  // ME/GE; 0 otherwise
};
// Appends the scan's points, dropping error codes (range < dmin_mm or > dmax_mm).
void scan_to_points(const Scan& scan, const Geometry& g, std::vector<Point2>& out);

// The sensor clock unwrapped to a monotonic 64-bit millisecond count: a step back of more than half the
// 24-bit range is a wrap. Thread-compatible.
class TimestampUnwrapper {
 public:
  [[nodiscard]] std::uint64_t unwrap(std::uint32_t raw_ms);
  void reset() {
    last_.reset();
    wraps_ = 0;
  }
  [[nodiscard]] std::uint64_t wraps() const { return wraps_; }

 private:
  std::optional<std::uint32_t> last_;
  std::uint64_t wraps_ = 0;
};

}  // namespace fieldguard::scip
