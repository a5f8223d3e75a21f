#pragma once
// Value types -> CAN frames, through the layouts of can_layout.hpp. Out-of-range values are clamped to
// their signal's range and counted (saturated_values(), the summary's Saturated bit and the heartbeat's
// SaturatedValues); nothing a caller passes, NaN and infinities included, is undefined behaviour.
// Thread-compatible: one encoder per sending thread (it owns the alive counters).

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "fieldguard/output/can_frame.hpp"
#include "fieldguard/output/can_layout.hpp"
#include "fieldguard/perception/obstacle.hpp"

namespace fieldguard::output {

inline constexpr std::uint8_t kMaxObstacleMessages = 16;  // FG_OBSTACLE.Index is 4 bits

struct CanParams {
  std::uint8_t source_address = 0x80;      // ours
  std::uint8_t controller_address = 0x26;  // the steering controller's: set it to the one on the tractor's bus
  std::array<std::uint8_t, kMessageCount> priority{6, 6, 3, 6};  // by MessageId, 0 = highest
  std::uint8_t max_obstacles = 8;                                // FG_OBSTACLE messages per frame, 0..16
};

// Every problem with `p`, each as "key: what is wrong and what to do"; empty when usable.
[[nodiscard]] std::vector<std::string> validate(const CanParams& p);

enum class FrameStatus : std::uint8_t { Ok = 0, PartialFrame = 1, Degraded = 2, NotReady = 3 };

struct FrameReport {
  std::uint32_t frame_counter = 0;  // sent modulo 2^16
  FrameStatus status = FrameStatus::Ok;
  std::span<const perception::Obstacle> obstacles;  // any order: the encoder picks the nearest
};

enum class StopCommand : std::uint8_t { Go = 0, Stop = 1, Error = 2 };

struct StopReasons {
  bool obstacle_in_zone = false;
  bool sensor_fault = false;
  bool pipeline_late = false;
  bool starting_up = false;
  bool shutting_down = false;
};

struct StopRequest {
  StopCommand command = StopCommand::Stop;
  StopReasons reasons;
};

enum class SensorHealth : std::uint8_t { Ok = 0, Fault = 1, NotRequired = 2, Unknown = 3 };

struct Heartbeat {
  SensorHealth lidar3d = SensorHealth::Unknown;
  SensorHealth lidar2d = SensorHealth::Unknown;
  SensorHealth gnss = SensorHealth::Unknown;
  SensorHealth ahrs = SensorHealth::Unknown;
  std::uint64_t frames_lost = 0;  // since start; sent modulo 2^16
};

class CanEncoder {
 public:
  // Throws std::invalid_argument with validate()'s problems when `p` is unusable.
  explicit CanEncoder(const CanParams& p);

  // Appends FG_OBSTACLE_SUMMARY, then one FG_OBSTACLE per obstacle, nearest first (by distance_m, then
  // bearing), up to max_obstacles. NaN distances sort first: an obstacle we cannot place is treated as near.
  void encode_frame(const FrameReport& report, std::vector<CanFrame>& out);
  // Each call is one transmission: the alive counter advances.
  [[nodiscard]] CanFrame encode_stop(const StopRequest& request);
  [[nodiscard]] CanFrame encode_heartbeat(const Heartbeat& heartbeat);

  // New parameters (a configuration reload), the alive counters going on where they were: the controller sees
  // one sequence whatever the daemon does. Throws std::invalid_argument as the constructor does.
  void reconfigure(const CanParams& p);

  [[nodiscard]] std::uint32_t id_of(MessageId m) const { return ids_[static_cast<std::size_t>(m)]; }
  [[nodiscard]] std::uint64_t saturated_values() const { return saturated_; }
  [[nodiscard]] const CanParams& params() const { return params_; }

 private:
  bool put(CanFrame& f, const Signal& s, double value);
  void encode_obstacle(const perception::Obstacle& o, std::size_t rank, bool& clamped, CanFrame& f);

  CanParams params_;
  std::array<std::uint32_t, kMessageCount> ids_{};
  std::uint64_t saturated_ = 0;
  std::uint8_t stop_alive_ = 0;
  std::uint8_t heartbeat_alive_ = 0;
  std::vector<std::uint32_t> order_;  // reused between frames
};

// Ids for `p` (J1939: priority, PGN, destination for the PDU1 stop request, our source address).
[[nodiscard]] std::uint32_t message_id(const CanParams& p, MessageId m);

// The CRC the layouts name (CRC-8/SAE-J1850) over the bytes before the message's Crc signal.
[[nodiscard]] std::uint8_t payload_crc(const CanFrame& f, const Signal& crc_signal);

}  // namespace fieldguard::output
