#include "fieldguard/output/can_encoder.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <tuple>

#include "fieldguard/output/crc8.hpp"

namespace fieldguard::output {
namespace {

constexpr std::uint8_t kNullAddress = 0xFE;  // J1939: 0xFE null, 0xFF global; neither is a node's address

const Signal& sig(MessageId m, std::size_t i) { return layout(m).signals[i]; }

CanFrame blank(std::uint32_t id, MessageId m) {
  CanFrame f;
  f.id = id;
  f.len = layout(m).dlc;
  return f;
}

void put_flag(CanFrame& f, const Signal& s, bool v) { put_raw(f.data, s, v ? 1U : 0U); }

}  // namespace

std::vector<std::string> validate(const CanParams& p) {
  std::vector<std::string> problems;
  if (p.source_address >= kNullAddress) {
    problems.emplace_back("can.source_address: 0xFE and 0xFF are the J1939 null and global addresses; use 0x00-0xFD");
  }
  if (p.controller_address >= kNullAddress) {
    problems.emplace_back(
        "can.controller_address: 0xFE and 0xFF are the J1939 null and global addresses; use the steering "
        "controller's own address (0x00-0xFD)");
  }
  if (p.controller_address == p.source_address && p.source_address < kNullAddress) {
    problems.emplace_back("can.controller_address: equals can.source_address; two nodes cannot share an address");
  }
  for (std::size_t i = 0; i < p.priority.size(); ++i) {
    if (p.priority[i] > 7) {
      problems.emplace_back("can.priority." + std::string(message_layouts()[i].name) +
                            ": J1939 priority is 0 (highest) to 7");
    }
  }
  if (p.max_obstacles > kMaxObstacleMessages) {
    problems.emplace_back("can.max_obstacles: at most 16 (FG_OBSTACLE.Index is 4 bits)");
  }
  return problems;
}

std::uint32_t message_id(const CanParams& p, MessageId m) {
  const MessageLayout& l = layout(m);
  return j1939_id(p.priority[static_cast<std::size_t>(m)], l.pgn, p.source_address, p.controller_address);
}

std::uint8_t payload_crc(const CanFrame& f, const Signal& crc_signal) {
  const std::size_t n = std::min<std::size_t>(crc_signal.start_bit / 8U, f.data.size());
  return crc8<kCrc8SaeJ1850>(std::span<const std::uint8_t>(f.data.data(), n));
}

CanEncoder::CanEncoder(const CanParams& p) {
  reconfigure(p);
  order_.reserve(64);
}

void CanEncoder::reconfigure(const CanParams& p) {
  const auto problems = validate(p);
  if (!problems.empty()) {
    std::string all = "invalid CAN parameters:";
    for (const auto& s : problems) all += "\n  " + s;
    throw std::invalid_argument(all);
  }
  params_ = p;
  for (std::size_t i = 0; i < kMessageCount; ++i) ids_[i] = message_id(p, static_cast<MessageId>(i));
}

bool CanEncoder::put(CanFrame& f, const Signal& s, double value) {
  if (put_physical(f.data, s, value)) return true;
  ++saturated_;
  return false;
}

void CanEncoder::encode_obstacle(const perception::Obstacle& o, std::size_t rank, bool& clamped, CanFrame& f) {
  using namespace obstacle_sig;
  constexpr MessageId m = MessageId::Obstacle;
  put_raw(f.data, sig(m, Index), rank);
  clamped |= !put(f, sig(m, SizeClass), static_cast<double>(static_cast<std::uint8_t>(o.size_class)));
  clamped |= !put(f, sig(m, XMin), static_cast<double>(o.min[0]));
  clamped |= !put(f, sig(m, XMax), static_cast<double>(o.max[0]));
  clamped |= !put(f, sig(m, YMin), static_cast<double>(o.min[1]));
  clamped |= !put(f, sig(m, YMax), static_cast<double>(o.max[1]));
  clamped |= !put(f, sig(m, Height), static_cast<double>(o.height_above_ground_m));
  clamped |= !put(f, sig(m, Points), static_cast<double>(o.points));
}

void CanEncoder::encode_frame(const FrameReport& report, std::vector<CanFrame>& out) {
  const auto obstacles = report.obstacles;
  // NaN would break the sort's strict weak ordering; map it to -inf (nearest, the cautious reading).
  const auto key = [&](std::uint32_t i) {
    const float d = obstacles[i].distance_m;
    const float b = obstacles[i].bearing_deg;
    return std::make_tuple(std::isnan(d) ? -std::numeric_limits<float>::infinity() : d, std::isnan(b) ? 0.F : b, i);
  };
  order_.resize(obstacles.size());
  std::iota(order_.begin(), order_.end(), 0U);
  const std::size_t sent = std::min<std::size_t>(obstacles.size(), params_.max_obstacles);
  // The summary needs the nearest even when no FG_OBSTACLE is configured.
  const std::size_t ranked = std::max<std::size_t>(sent, obstacles.empty() ? 0 : 1);
  std::partial_sort(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(ranked), order_.end(),
                    [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });

  const std::size_t summary_at = out.size();
  out.push_back(blank(ids_[static_cast<std::size_t>(MessageId::ObstacleSummary)], MessageId::ObstacleSummary));
  bool clamped = false;
  for (std::size_t r = 0; r < sent; ++r) {
    CanFrame f = blank(ids_[static_cast<std::size_t>(MessageId::Obstacle)], MessageId::Obstacle);
    encode_obstacle(obstacles[order_[r]], r, clamped, f);
    out.push_back(f);
  }

  using namespace summary_sig;
  constexpr MessageId m = MessageId::ObstacleSummary;
  CanFrame& s = out[summary_at];
  clamped |= !put(s, sig(m, ObstacleCount), static_cast<double>(obstacles.size()));
  if (obstacles.empty()) {
    // The "NO_OBSTACLE" entries of the value tables.
    put_raw(s.data, sig(m, NearestDistance), static_cast<std::uint64_t>(sig(m, NearestDistance).values[0].raw));
    put_raw(s.data, sig(m, NearestBearing), static_cast<std::uint64_t>(sig(m, NearestBearing).values[0].raw));
  } else {
    const perception::Obstacle& n = obstacles[order_[0]];
    clamped |= !put(s, sig(m, NearestDistance), static_cast<double>(n.distance_m));
    clamped |= !put(s, sig(m, NearestBearing), static_cast<double>(n.bearing_deg));
  }
  put_raw(s.data, sig(m, FrameCounter), report.frame_counter);
  put_raw(s.data, sig(m, Status), static_cast<std::uint64_t>(report.status));
  put_flag(s, sig(m, ListTruncated), obstacles.size() > sent);
  put_flag(s, sig(m, Saturated), clamped);
}

CanFrame CanEncoder::encode_stop(const StopRequest& request) {
  using namespace stop_sig;
  constexpr MessageId m = MessageId::StopRequest;
  CanFrame f = blank(ids_[static_cast<std::size_t>(m)], m);
  put_raw(f.data, sig(m, Command), static_cast<std::uint64_t>(request.command));
  put_flag(f, sig(m, ReasonObstacle), request.reasons.obstacle_in_zone);
  put_flag(f, sig(m, ReasonSensorFault), request.reasons.sensor_fault);
  put_flag(f, sig(m, ReasonPipelineLate), request.reasons.pipeline_late);
  put_flag(f, sig(m, ReasonStartingUp), request.reasons.starting_up);
  put_flag(f, sig(m, ReasonShuttingDown), request.reasons.shutting_down);
  put_raw(f.data, sig(m, AliveCounter), stop_alive_);
  stop_alive_ = static_cast<std::uint8_t>((stop_alive_ + 1U) & 0x0FU);
  put_raw(f.data, sig(m, Crc), payload_crc(f, sig(m, Crc)));
  return f;
}

CanFrame CanEncoder::encode_heartbeat(const Heartbeat& hb) {
  using namespace heartbeat_sig;
  constexpr MessageId m = MessageId::Heartbeat;
  CanFrame f = blank(ids_[static_cast<std::size_t>(m)], m);
  put_raw(f.data, sig(m, Lidar3d), static_cast<std::uint64_t>(hb.lidar3d));
  put_raw(f.data, sig(m, Lidar2d), static_cast<std::uint64_t>(hb.lidar2d));
  put_raw(f.data, sig(m, Gnss), static_cast<std::uint64_t>(hb.gnss));
  put_raw(f.data, sig(m, Ahrs), static_cast<std::uint64_t>(hb.ahrs));
  put_raw(f.data, sig(m, FramesLost), hb.frames_lost);
  put_raw(f.data, sig(m, SaturatedValues), saturated_);
  put_raw(f.data, sig(m, AliveCounter), heartbeat_alive_);
  heartbeat_alive_ = static_cast<std::uint8_t>((heartbeat_alive_ + 1U) & 0x0FU);
  put_raw(f.data, sig(m, Crc), payload_crc(f, sig(m, Crc)));
  return f;
}

}  // namespace fieldguard::output
