#pragma once
// The stop decision. Pure and deterministic: no clock is read (every time comes in as an argument), no
// threads, no logging. It returns its decision and, when the decision changes, one event for the app to log
// and send. Thread-compatible: one caller at a time (the app's output stage).
//
// Stop while any reason is active: an obstacle box overlapping the stop zone, a required sensor silent
// longer than its timeout, implausible data from a required sensor, a frame decided later than its deadline
// or no frame for too long, or start-up (until every required sensor has been heard and plausible at once).
// Go only after clear_frames consecutive frames with no reason active.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "fieldguard/core/time.hpp"
#include "fieldguard/output/plausibility.hpp"
#include "fieldguard/output/safety_params.hpp"
#include "fieldguard/perception/obstacle.hpp"

namespace fieldguard::output::safety {

// Values 1..4 follow the list of stop reasons (obstacle in zone, sensor fault, pipeline late,
// starting up); implausible data and no address are ours.
enum class Reason : std::uint8_t {
  None = 0,
  ObstacleInZone = 1,
  SensorFault = 2,
  PipelineLate = 3,
  StartingUp = 4,
  ImplausibleData = 5,
  NoAddress = 6,  // J1939: no source address to send from (lost the contest, none left): nothing reaches the controller
};
[[nodiscard]] std::string_view to_string(Reason r);  // "obstacle in zone", ...
[[nodiscard]] constexpr std::uint8_t bit(Reason r) {
  return r == Reason::None ? std::uint8_t{0} : static_cast<std::uint8_t>(1U << (static_cast<unsigned>(r) - 1U));
}
// The reason reported when several are active, highest first: the stop request reaching nobody, then what makes
// the monitor's own view doubtful (a sensor down, data wrong, the pipeline behind) comes before what it sees, and
// start-up last.
inline constexpr Reason kReasonPriority[] = {Reason::NoAddress,    Reason::SensorFault,    Reason::ImplausibleData,
                                             Reason::PipelineLate, Reason::ObstacleInZone, Reason::StartingUp};

// What the app knows about one sensor at the time of the update.
struct SensorInput {
  Stamp last_data;                  // host receive time of its newest data; 0 = never heard
  Problem problem = Problem::None;  // first implausible sample since the previous update (GnssCheck::take())
};

// A frame the pipeline has finished.
struct FrameInput {
  std::span<const perception::Obstacle> obstacles;  // in the 3D LiDAR's sensor frame
  Stamp data_end;                                   // host receive time of the frame's last data; 0 = unknown (= late)
  std::optional<double> speed_mps;                  // vehicle speed when known and fresh; sizes the zone
};

struct Input {
  Stamp now;  // host time of this decision (the clock of every other host time)
  std::array<SensorInput, kSensorCount> sensors{};
  const FrameInput* frame = nullptr;  // nullptr: a tick between frames (timeouts only; counts no clear frame)
  bool no_address = false;            // the CAN node has no J1939 address (address_claim.hpp: cannot claim)
};

struct Zone {
  double x_min_m = 0.0;
  double x_max_m = 0.0;
  double half_width_m = 0.0;
  bool speed_known = false;
};

struct Event {
  Stamp at;
  bool stop = true;
  Reason reason = Reason::None;  // the reason now (None when it is go)
  bool was_stop = true;          // the state before; for the very first decision, stop / starting up
  Reason previous_reason = Reason::None;
  bool first = false;        // the monitor's first decision
  std::uint8_t reasons = 0;  // every active reason, bit(Reason)
  std::uint8_t sensors = 0;  // the sensors at fault or awaited, bit(Sensor)
  std::string text;          // one readable line: "stop: sensor fault: lidar silent 0.412 s (timeout 0.3 s)"
};

struct Decision {
  bool stop = true;
  Reason reason = Reason::StartingUp;  // the highest active reason; while a stop holds for clear frames, the
                                       // reason that caused it; None when go
  std::uint8_t reasons = 0;            // every reason active in this update, bit(Reason)
  std::uint8_t fault_sensors = 0;      // sensors silent or awaited at start-up, bit(Sensor)
  std::uint8_t implausible_sensors = 0;
  int clear_frames = 0;           // consecutive clear frames so far
  int obstacles_in_zone = 0;      // in the newest frame
  int unplaceable_obstacles = 0;  // non-finite boxes in the newest frame (taken to be in the zone)
  std::optional<float>
      nearest_m;               // the nearest box in the zone, its near edge (x, m ahead of the sensor); newest frame
  Zone zone;                   // the zone the newest frame was checked against
  std::optional<Event> event;  // set when stop/go, the reason or its sensors changed
};

// The decision as an operator reads it first, one short phrase: "GO", "STOP obstacle 5.4 m ahead",
// "STOP obstacle gone, clear 2 of 5 frames", "STOP gnss silent", "STOP ahrs implausible",
// "STOP starting up: waiting for gnss, ahrs", "STOP pipeline late", "STOP no CAN address".
[[nodiscard]] std::string headline(const Decision& d, int clear_frames_needed);

// How much a reason matters to whoever reads the log: Info for what the tractor meets in normal work (starting
// up, an obstacle, go), Warning for what degrades the monitor's own view (a sensor silent or implausible, the
// pipeline late), Error for a stop request that reaches nobody (no CAN address).
enum class Severity : std::uint8_t { Info, Warning, Error };
[[nodiscard]] Severity severity(Reason r);

class Monitor {
 public:
  // Throws std::invalid_argument listing every problem when validate(params) is not empty.
  explicit Monitor(const Params& params);

  [[nodiscard]] Decision update(const Input& in);

  [[nodiscard]] const Params& params() const { return params_; }
  [[nodiscard]] bool started() const { return started_; }
  [[nodiscard]] Zone zone_for(std::optional<double> speed_mps) const;

 private:
  void check_frame(const FrameInput& f, Stamp now);
  [[nodiscard]] std::string obstacle_text() const;

  Params params_;
  bool started_ = false;
  bool stop_ = true;
  Reason reason_ = Reason::StartingUp;  // the reason reported, held while the clear frames are counted
  std::uint8_t event_sensors_ = 0;      // the sensors behind reason_
  int clear_ = 0;
  // Properties of the newest frame, kept through the ticks until the next frame.
  bool obstacle_latched_ = false;
  bool frame_late_latched_ = false;
  int obstacles_in_zone_ = 0;
  int unplaceable_ = 0;
  Zone zone_;
  Stamp last_frame_;                                     // `now` of the newest frame (or of start-up); 0 = neither yet
  std::optional<std::array<float, 4>> nearest_in_zone_;  // x min, x max, y min, y max of the nearest box in the zone
  Zone obstacle_zone_;
  double obstacle_speed_kmh_ = 0.0;
  double late_latency_s_ = 0.0;  // infinite when the frame had no data time
  // What the previous event said: a new event only when one of these changes.
  bool first_ = true;
  bool event_stop_ = true;
  Reason event_reason_ = Reason::StartingUp;
  std::uint8_t event_sensors_sent_ = 0;
};

// True when the obstacle's box overlaps the zone in x-y (touching counts). Both its axis-aligned box and its
// oriented footprint must overlap: every point of the cluster lies in both, so this never misses a point in
// the zone, and a long diagonal object beside the zone does not stop the tractor. A non-finite box overlaps.
[[nodiscard]] bool overlaps(const perception::Obstacle& o, const Zone& z);

}  // namespace fieldguard::output::safety
