#include "fieldguard/output/can_layout.hpp"

#include <cmath>
#include <stdexcept>

namespace fieldguard::output {
namespace {

// Proprietary B (PDU2, broadcast) PGNs 0xFF00-0xFFFF: the group extension picks ours. The stop request is
// Proprietary A (PDU1, 0xEF00), addressed to the steering controller so no other node acts on it.
constexpr std::uint32_t kPgnSummary = 0xFF10;
constexpr std::uint32_t kPgnObstacle = 0xFF11;
constexpr std::uint32_t kPgnStop = 0xEF00;
constexpr std::uint32_t kPgnHeartbeat = 0xFF12;

constexpr std::array<ValueName, 1> kNoObstacle{{{65535, "NO_OBSTACLE"}}};
constexpr std::array<ValueName, 4> kStatusNames{{{0, "OK"}, {1, "PARTIAL_FRAME"}, {2, "DEGRADED"}, {3, "NOT_READY"}}};
constexpr std::array<ValueName, 2> kTruncNames{{{0, "ALL_SENT"}, {1, "TRUNCATED"}}};
constexpr std::array<ValueName, 2> kSatNames{{{0, "NONE"}, {1, "CLAMPED"}}};
constexpr std::array<ValueName, 2> kSizeNames{{{0, "SMALL"}, {1, "LARGE"}}};
constexpr std::array<ValueName, 4> kCommandNames{{{0, "GO"}, {1, "STOP"}, {2, "ERROR"}, {3, "NOT_AVAILABLE"}}};
constexpr std::array<ValueName, 2> kFlagNames{{{0, "NO"}, {1, "YES"}}};
constexpr std::array<ValueName, 4> kHealthNames{{{0, "OK"}, {1, "FAULT"}, {2, "NOT_REQUIRED"}, {3, "UNKNOWN"}}};

constexpr std::string_view kCrcComment =
    "CRC-8/SAE-J1850 (poly 0x1D, init 0xFF, xorout 0xFF, not reflected; check 0x4B) over bytes 0-6";

constexpr std::array<Signal, 7> kSummary{{
    {"ObstacleCount", 0, 8, ByteOrder::Intel, false, 1, 0, 0, 250, "",
     "Obstacles in this frame after the filters; 250 = 250 or more"},
    {"NearestDistance", 8, 16, ByteOrder::Intel, false, 0.01, 0, 0, 600, "m",
     "Horizontal distance from the 3D LiDAR to the nearest point of the nearest obstacle", kNoObstacle},
    {"NearestBearing", 24, 16, ByteOrder::Intel, false, 0.01, -180, -180, 180, "deg",
     "Bearing of the nearest obstacle's box centre from the LiDAR's x axis, positive to the left", kNoObstacle},
    {"FrameCounter",
     40,
     16,
     ByteOrder::Intel,
     false,
     1,
     0,
     0,
     65535,
     "",
     "Pipeline frame number, wraps at 65535",
     {},
     Overflow::Wrap},
    {"Status", 56, 4, ByteOrder::Intel, false, 1, 0, 0, 15, "", "State of the frame this summary describes",
     kStatusNames},
    {"ListTruncated", 60, 1, ByteOrder::Intel, false, 1, 0, 0, 1, "",
     "More obstacles were found than OBSTACLE messages are configured; the nearest were sent", kTruncNames},
    {"Saturated", 61, 1, ByteOrder::Intel, false, 1, 0, 0, 1, "",
     "A value in this frame's summary or obstacle messages was outside its signal's range and was clamped", kSatNames},
}};

constexpr std::array<Signal, 8> kObstacle{{
    {"Index", 0, 4, ByteOrder::Intel, false, 1, 0, 0, 15, "", "Rank in this frame, 0 = nearest"},
    {"SizeClass", 4, 2, ByteOrder::Intel, false, 1, 0, 0, 3, "",
     "SMALL: fits in 1.2 x 1.2 x 2.2 m (a person); LARGE: implement, bale, building, tree", kSizeNames},
    {"XMin", 6, 11, ByteOrder::Intel, true, 0.1, 0, -102.4, 102.3, "m", "Box, LiDAR frame, x forward"},
    {"XMax", 17, 11, ByteOrder::Intel, true, 0.1, 0, -102.4, 102.3, "m", "Box, LiDAR frame, x forward"},
    {"YMin", 28, 11, ByteOrder::Intel, true, 0.1, 0, -102.4, 102.3, "m", "Box, LiDAR frame, y left"},
    {"YMax", 39, 11, ByteOrder::Intel, true, 0.1, 0, -102.4, 102.3, "m", "Box, LiDAR frame, y left"},
    {"Height", 50, 6, ByteOrder::Intel, false, 0.2, 0, 0, 12.6, "m", "Highest point above the local ground"},
    {"Points", 56, 8, ByteOrder::Intel, false, 1, 0, 0, 255, "",
     "Points in the cluster after voxel downsampling; 255 = 255 or more"},
}};

constexpr std::array<Signal, 8> kStop{{
    {"Command", 0, 2, ByteOrder::Intel, false, 1, 0, 0, 3, "", "GO only when every reason below is clear",
     kCommandNames},
    {"ReasonObstacle", 8, 1, ByteOrder::Intel, false, 1, 0, 0, 1, "", "An obstacle is inside the stop zone",
     kFlagNames},
    {"ReasonSensorFault", 9, 1, ByteOrder::Intel, false, 1, 0, 0, 1, "",
     "A required sensor is silent past its timeout or its data is implausible", kFlagNames},
    {"ReasonPipelineLate", 10, 1, ByteOrder::Intel, false, 1, 0, 0, 1, "", "The pipeline is later than its deadline",
     kFlagNames},
    {"ReasonStartingUp", 11, 1, ByteOrder::Intel, false, 1, 0, 0, 1, "",
     "Not every required sensor has been healthy yet since start", kFlagNames},
    {"ReasonShuttingDown", 12, 1, ByteOrder::Intel, false, 1, 0, 0, 1, "", "The daemon is stopping", kFlagNames},
    {"AliveCounter",
     48,
     4,
     ByteOrder::Intel,
     false,
     1,
     0,
     0,
     15,
     "",
     "+1 per STOP_REQUEST sent, wraps 15 -> 0; a repeat or a jump means a frozen or lossy sender",
     {},
     Overflow::Wrap},
    {"Crc", 56, 8, ByteOrder::Intel, false, 1, 0, 0, 255, "", kCrcComment},
}};

constexpr std::array<Signal, 8> kHeartbeat{{
    {"Lidar3d", 0, 2, ByteOrder::Intel, false, 1, 0, 0, 3, "", "3D LiDAR health", kHealthNames},
    {"Lidar2d", 2, 2, ByteOrder::Intel, false, 1, 0, 0, 3, "", "2D LiDAR health", kHealthNames},
    {"Gnss", 4, 2, ByteOrder::Intel, false, 1, 0, 0, 3, "", "GNSS receiver health", kHealthNames},
    {"Ahrs", 6, 2, ByteOrder::Intel, false, 1, 0, 0, 3, "", "AHRS health", kHealthNames},
    {"FramesLost",
     8,
     16,
     ByteOrder::Intel,
     false,
     1,
     0,
     0,
     65535,
     "",
     "Frames dropped since start (sync or queue), wraps at 65535",
     {},
     Overflow::Wrap},
    {"SaturatedValues",
     24,
     16,
     ByteOrder::Intel,
     false,
     1,
     0,
     0,
     65535,
     "",
     "Signal values clamped to their range since start, wraps at 65535",
     {},
     Overflow::Wrap},
    {"AliveCounter",
     48,
     4,
     ByteOrder::Intel,
     false,
     1,
     0,
     0,
     15,
     "",
     "+1 per HEARTBEAT sent, wraps 15 -> 0",
     {},
     Overflow::Wrap},
    {"Crc", 56, 8, ByteOrder::Intel, false, 1, 0, 0, 255, "", kCrcComment},
}};

// The enums in the header index these tables.
static_assert(kSummary[summary_sig::NearestBearing].name == "NearestBearing" &&
              kSummary[summary_sig::Saturated].name == "Saturated" && kSummary.size() == summary_sig::Saturated + 1);
static_assert(kObstacle[obstacle_sig::XMin].name == "XMin" && kObstacle[obstacle_sig::Points].name == "Points" &&
              kObstacle.size() == obstacle_sig::Points + 1);
static_assert(kStop[stop_sig::ReasonShuttingDown].name == "ReasonShuttingDown" && kStop[stop_sig::Crc].name == "Crc" &&
              kStop.size() == stop_sig::Crc + 1);
static_assert(kHeartbeat[heartbeat_sig::FramesLost].name == "FramesLost" &&
              kHeartbeat[heartbeat_sig::Crc].name == "Crc" && kHeartbeat.size() == heartbeat_sig::Crc + 1);

const std::array<MessageLayout, kMessageCount> kMessages{{
    {MessageId::ObstacleSummary, "FG_OBSTACLE_SUMMARY", kPgnSummary, 6, 8, 0,
     "What the pipeline found in one LiDAR rotation; sent once per frame before its FG_OBSTACLE messages", kSummary},
    {MessageId::Obstacle, "FG_OBSTACLE", kPgnObstacle, 6, 8, 0,
     "One per obstacle, nearest first, up to the configured count; follows its frame's FG_OBSTACLE_SUMMARY. In the "
     "DBC its signals are multiplexed on Index (XMin_0 is the nearest obstacle's XMin)",
     kObstacle, "Index"},
    {MessageId::StopRequest, "FG_STOP_REQUEST", kPgnStop, 3, 8, 100,
     "Stop request to the steering controller (Proprietary A, addressed). Sent cyclically; the controller must stop "
     "when it stops arriving, when AliveCounter repeats or jumps, or when Crc is wrong. Crc: CRC-8/SAE-J1850, poly "
     "0x1D, init 0xFF, xorout 0xFF, over bytes 0-6",
     kStop},
    {MessageId::Heartbeat, "FG_HEARTBEAT", kPgnHeartbeat, 6, 8, 100,
     "Fixed-rate health of the daemon and its sensors. Crc: CRC-8/SAE-J1850, poly 0x1D, init 0xFF, xorout 0xFF, "
     "over bytes 0-6",
     kHeartbeat},
}};

std::uint64_t field_mask(std::uint8_t length) {
  return length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1U;
}

std::uint64_t load_le(std::span<const std::uint8_t, 8> d) {
  std::uint64_t v = 0;
  for (std::size_t i = 8; i-- > 0;) v = (v << 8U) | d[i];
  return v;
}

void store_le(std::span<std::uint8_t, 8> d, std::uint64_t v) {
  for (std::size_t i = 0; i < 8; ++i) d[i] = static_cast<std::uint8_t>(v >> (8U * i));
}

// Motorola: start at the MSB, walk down within a byte, then to bit 7 of the next byte.
std::size_t motorola_next(std::size_t pos) { return pos % 8 == 0 ? pos + 15 : pos - 1; }

// A signal that does not fit in 8 bytes is a bug in a layout table, not data from the world.
void check_fits(const Signal& s) {
  bool ok = s.length >= 1 && s.length <= 64;
  if (ok && s.order == ByteOrder::Intel) {
    ok = s.start_bit + std::size_t{s.length} <= 64;
  } else if (ok) {
    // The LSB lies length-1 steps further along the sawtooth walk.
    const std::size_t msb_byte = s.start_bit / 8;
    const std::size_t bits_left_in_first = s.start_bit % 8 + 1;
    const std::size_t rest = s.length > bits_left_in_first ? s.length - bits_left_in_first : 0;
    ok = s.start_bit < 64 && msb_byte + (rest + 7) / 8 < 8;
  }
  if (!ok) throw std::invalid_argument("output: CAN signal does not fit in 8 bytes");
}

std::int64_t to_raw_rounded(const Signal& s, double physical) {
  return static_cast<std::int64_t>(std::llround((physical - s.offset) / s.scale));
}

}  // namespace

std::span<const MessageLayout> message_layouts() { return kMessages; }

const MessageLayout& layout(MessageId id) {
  const auto i = static_cast<std::size_t>(id);
  if (i >= kMessages.size()) throw std::out_of_range("output::layout: no such message");
  return kMessages[i];
}

void put_raw(std::span<std::uint8_t, 8> data, const Signal& s, std::uint64_t raw) {
  check_fits(s);
  const std::uint64_t mask = field_mask(s.length);
  raw &= mask;
  if (s.order == ByteOrder::Intel) {
    std::uint64_t v = load_le(data);
    v = (v & ~(mask << s.start_bit)) | (raw << s.start_bit);
    store_le(data, v);
    return;
  }
  std::size_t pos = s.start_bit;
  for (std::size_t i = s.length; i-- > 0;) {
    const auto bit = static_cast<std::uint8_t>(1U << (pos % 8));
    if (((raw >> i) & 1U) != 0) {
      data[pos / 8] = static_cast<std::uint8_t>(data[pos / 8] | bit);
    } else {
      data[pos / 8] = static_cast<std::uint8_t>(data[pos / 8] & ~bit);
    }
    if (i > 0) pos = motorola_next(pos);
  }
}

std::uint64_t get_raw(std::span<const std::uint8_t, 8> data, const Signal& s) {
  check_fits(s);
  const std::uint64_t mask = field_mask(s.length);
  if (s.order == ByteOrder::Intel) return (load_le(data) >> s.start_bit) & mask;
  std::uint64_t raw = 0;
  std::size_t pos = s.start_bit;
  for (std::size_t i = s.length; i-- > 0;) {
    raw = (raw << 1U) | ((data[pos / 8] >> (pos % 8)) & 1U);
    if (i > 0) pos = motorola_next(pos);
  }
  return raw;
}

bool put_physical(std::span<std::uint8_t, 8> data, const Signal& s, double value) {
  if (s.overflow == Overflow::Wrap) {
    const double r = std::round((value - s.offset) / s.scale);
    // Beyond 2^63 the cast is undefined and the low bits are long gone: clamp and count.
    if (!std::isfinite(r) || std::fabs(r) >= 9.2e18) {
      put_raw(data, s, 0);
      return false;
    }
    put_raw(data, s, static_cast<std::uint64_t>(static_cast<std::int64_t>(r)));
    return true;
  }
  const std::int64_t lo = to_raw_rounded(s, s.min);
  const std::int64_t hi = to_raw_rounded(s, s.max);
  const double r = std::round((value - s.offset) / s.scale);
  std::int64_t raw = 0;
  bool in_range = true;
  if (std::isnan(r) || r < static_cast<double>(lo)) {
    raw = lo;
    in_range = false;
  } else if (r > static_cast<double>(hi)) {
    raw = hi;
    in_range = false;
  } else {
    raw = static_cast<std::int64_t>(r);
  }
  put_raw(data, s, static_cast<std::uint64_t>(raw));
  return in_range;
}

double get_physical(std::span<const std::uint8_t, 8> data, const Signal& s) {
  const std::uint64_t raw = get_raw(data, s);
  double v = static_cast<double>(raw);
  if (s.is_signed && s.length < 64 && ((raw >> (s.length - 1U)) & 1U) != 0) {
    v -= std::ldexp(1.0, s.length);
  }
  return v * s.scale + s.offset;
}

}  // namespace fieldguard::output
