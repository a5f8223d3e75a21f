#pragma once
// RoboSense RS-LiDAR-32: MSOP data packets (port 6699) and DIFOP device-info packets (port 7788), 1248 bytes
// each, big-endian (../shared/docs/protocols.md §2). Pure: bytes in, points or errors out; no I/O, no threads,
// no logging. Bad data is a returned DecodeError, counted by the caller (robosense::Stream does).
//
// Points are in the sensor frame of the Velodyne driver (REP-103: x forward at azimuth 0, y left, z up, metres,
// azimuth clockwise seen from above): x = d cos(w) cos(a) + R cos(a0), y = -d cos(w) sin(a) - R sin(a0),
// z = d sin(w), with w the channel's vertical angle, a0 the channel's interpolated firing azimuth, a = a0 + the
// channel's horizontal correction, and R the optical-centre offset (rs_driver decoder_RS32.hpp: RX = 0.03997 m,
// applied along the uncorrected azimuth a0; RY, RZ are not used by rs_driver for the RS-32 points).

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/expected.hpp"
#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/core/time.hpp"
#include "fieldguard/drivers/rotation_assembler.hpp"

namespace fieldguard::robosense {

inline constexpr std::size_t kPacketSize = 1248;  // MSOP and DIFOP alike
inline constexpr std::size_t kHeaderSize = 42;
inline constexpr std::size_t kBlocksPerPacket = 12;
inline constexpr std::size_t kBlockSize = 100;
inline constexpr std::size_t kChannels = 32;
inline constexpr std::uint16_t kDefaultMsopPort = 6699;
inline constexpr std::uint16_t kDefaultDifopPort = 7788;
// Most points an MSOP packet yields: 12 blocks of 32 (single return), or 6 pairs of 32 firings with two (dual).
inline constexpr std::size_t kMaxPointsPerPacket = kBlocksPerPacket * kChannels;

// Firing timing (rs_driver decoder_RS32.hpp, and the RS-LiDAR-32 manual appendix A.1/A.2, whose formula
// 55.52*(seq-1) + 2.88*mod(ch-1,16) + 1.44*floor(ch/16) reproduces this table): one block of 32 firings lasts
// 55.52 us; channel c fires kFiringOffsetUs[c] after the block's first firing.
inline constexpr double kBlockDurationUs = 55.52;
inline constexpr std::array<double, kChannels> kFiringOffsetUs = {
    0.00, 2.88, 5.76, 8.64,  11.52, 14.40, 17.28, 20.16, 23.04, 25.92, 28.80, 31.68, 34.56, 37.44, 40.32, 44.64,
    1.44, 4.32, 7.20, 10.08, 12.96, 15.84, 18.72, 21.60, 24.48, 27.36, 30.24, 33.12, 36.00, 38.88, 41.76, 46.08};
inline constexpr double kOpticalCentreOffsetM = 0.03997;  // rs_driver RS-32 "RX" [single-source]

// DIFOP byte 300 (rs_driver decoder_RS32.hpp getEchoMode, ros_rslidar rawdata.cc processDifop).
enum class ReturnMode : std::uint8_t { Dual = 0, Strongest = 1, Last = 2 };

// Distance encoding (protocols.md §2.2). HalfCm: all 16 bits, 0.5 cm per LSB (rs_driver; firmware since about
// Dec 2018). OneCmGrouped: bit 15 is the block's laser group (A = 0, B = 1; in a B block the two 16-channel
// halves are swapped), bits 0..14 the distance in cm (ros_rslidar rawdata.cc unpack_RS32).
enum class DistanceUnit : std::uint8_t { HalfCm = 0, OneCmGrouped };
// Auto takes the unit from the first DIFOP's top-board firmware version (see distance_unit_from_firmware).
enum class DistanceUnitOption : std::uint8_t { Auto = 0, HalfCm, OneCmGrouped };

[[nodiscard]] std::string_view to_string(ReturnMode m);
[[nodiscard]] std::string_view to_string(DistanceUnit u);

// Decode errors of MSOP and DIFOP packets. Each is counted by the caller, never thrown.
enum class DecodeError : std::uint8_t {
  BadLength,      // payload is not 1248 bytes
  BadMagic,       // the 8-byte header id is not the MSOP one (resp. the DIFOP one)
  BadBlockFlag,   // a data block does not start with FF EE
  BadAzimuth,     // a block azimuth >= 36000 (0.01 degree)
  BadTimestamp,   // the MSOP header's Y-M-D h:m:s ms us fields are out of range
  BadAngleTable,  // DIFOP angle record with a sign byte other than 00/01 (or |angle| >= 90 deg, which a u16
                  // magnitude at 0.001 deg cannot reach: 65.535 deg at most)
  NoCalibration,  // MSOP before the decoder has angles and a distance unit (no DIFOP yet, none configured)
};
[[nodiscard]] std::string_view to_string(DecodeError e);
inline constexpr std::size_t kDecodeErrorCount = 7;

// Per-channel angles, channel = position of the 3-byte record in the MSOP block (0..31).
struct Calibration {
  std::array<double, kChannels> vert_deg{};   // elevation, positive up
  std::array<double, kChannels> horiz_deg{};  // azimuth correction added to the firing azimuth (clockwise)
  friend bool operator==(const Calibration&, const Calibration&) = default;
};

// The DIFOP 3-byte angle record: sign byte (00 positive, 01 negative), magnitude u16 BE in 0.001 degree for the
// RS-32 (manual B.13/B.14, rs_driver RS32DifopPkt2Adapter). nullopt for any other sign byte.
[[nodiscard]] std::optional<std::int32_t> decode_angle_millideg(ByteSpan triplet);

// The YMD time of the MSOP header and DIFOP (year - 2000, month, day, hour, minute, second, ms u16 BE, us u16 BE)
// as UTC (days-from-civil arithmetic, the timegm equivalent; rs_driver uses mktime, i.e. local time).
// nullopt when a field is out of range (month 1..12, day within the month, hour < 24, minute < 60,
// second <= 60, ms < 1000, us < 1000).
[[nodiscard]] std::optional<Stamp> decode_ymd_time(ByteSpan ten_bytes);

// Distance unit from the DIFOP top-board firmware bytes 41..43 (ros_rslidar rawdata.cc processDifop): 00 00 00,
// FF FF FF, 55 AA 5A and E9 01 00 are the old firmware (1 cm, grouped); anything else is 0.5 cm.
[[nodiscard]] DistanceUnit distance_unit_from_firmware(std::uint8_t b41, std::uint8_t b42, std::uint8_t b43);

// What a DIFOP packet says (protocols.md §2.3).
struct DifopInfo {
  std::uint16_t rpm = 0;  // 300 / 600 / 1200; 0 if unset
  std::uint16_t fov_start_cdeg = 0;
  std::uint16_t fov_end_cdeg = 0;
  std::array<std::uint8_t, 5> top_firmware{};
  std::array<std::uint8_t, 5> bottom_firmware{};
  std::array<std::uint8_t, 6> serial{};
  std::uint8_t return_mode_byte = 0;
  ReturnMode return_mode = ReturnMode::Strongest;  // unknown bytes count as single return, as in rs_driver
  std::optional<Stamp> utc_time;                   // nullopt when the time fields are out of range
  DistanceUnit distance_unit = DistanceUnit::HalfCm;
  // nullopt when the vertical table is not written (every triplet FF FF FF or 00 00 00): keep waiting.
  std::optional<Calibration> calibration;
};

// Checks length and magic; BadAngleTable when a written table holds an undecodable or out-of-range record.
[[nodiscard]] Expected<DifopInfo, DecodeError> parse_difop(ByteSpan payload);

// What an MSOP packet says about itself, readable without a calibration.
struct MsopHeader {
  Stamp sensor_time;            // UTC of the packet's first firing (manual appendix A)
  std::uint8_t model_byte = 0;  // byte 30
  float temperature_c = 0.F;    // bytes 38..39, 0.0625 degC per LSB (rs_driver parseTempInLe, ros_rslidar)
  std::array<std::uint16_t, kBlocksPerPacket> azimuth_cdeg{};
  bool dual_layout = false;  // blocks 2k and 2k+1 carry the same azimuth
};

// Validates length, magic, block flags, azimuths and the timestamp.
[[nodiscard]] Expected<MsopHeader, DecodeError> read_msop_header(ByteSpan payload);

// Nominal angles for the time before the first DIFOP (DecoderOptions::nominal_until_difop): the vertical angles of
// ros_rslidar's example rs_lidar_32/angle.csv (protocols.md §2.4: one real unit, rounded to 0.01 degree; RoboSense
// publishes no fixed table, every unit has its own), no horizontal corrections. Off by up to a few tenths of a
// degree from any other unit: good enough to see obstacles for the second until the unit's own table arrives.
[[nodiscard]] const Calibration& nominal_calibration();

// The unit's angle.csv (rs_driver, ros_rslidar): 32 lines, channel 0 first, each the vertical angle and, when
// there, a comma and the horizontal correction, in degrees. An error names the line.
[[nodiscard]] Expected<Calibration, std::string> parse_angle_csv(std::string_view text);

struct DecoderOptions {
  std::optional<Calibration> calibration;  // a configured table (the unit's angle.csv); it wins over DIFOP's
  // Without a configured table: decode with nominal_calibration() (and the 0.5 cm unit of every firmware since
  // 2018 when distance_unit is Auto) until the first DIFOP brings the unit's own. Off: wait for it (rs_driver's
  // wait_for_difop), NoCalibration until then.
  bool nominal_until_difop = false;
  DistanceUnitOption distance_unit = DistanceUnitOption::Auto;
  std::optional<ReturnMode> return_mode;  // none = from DIFOP; before one, from the block layout
  double min_range_m = 0.4;               // rs_driver's RS-32 distance section: 0.4 .. 230 m
  double max_range_m = 230.0;
  double optical_centre_offset_m = kOpticalCentreOffsetM;
};

// The RS-32 decoder: MSOP packets in, points out, once it knows the angles and the distance unit.
// Thread-compatible: decode() is const; apply() must not run concurrently with it.
class Decoder {
 public:
  // Throws std::invalid_argument for an impossible configured calibration (non-finite or |angle| >= 90 deg) or
  // range limits (min < 0, max <= min).
  explicit Decoder(DecoderOptions options = {});

  // Takes what a DIFOP says. The angle table and the distance unit are taken from the first DIFOP that has
  // them (rs_driver and ros_rslidar do the same) unless configured; return mode and rpm from every DIFOP.
  // The nominal table and unit (nominal_until_difop) give way to the first DIFOP's.
  // Returns true when the DIFOP's angle table differs from the one in use by more than 0.0005 degree (the
  // caller counts it).
  bool apply(const DifopInfo& difop);

  [[nodiscard]] bool ready() const { return calibration_.has_value() && unit_.has_value(); }

  // Appends the packet's points to `out`. time_s of each point is seconds after the packet's sensor_time.
  // Returns NoCalibration (after checking the header) while !ready().
  Expected<MsopHeader, DecodeError> decode(ByteSpan payload, std::vector<LidarPoint>& out) const;
  // The same into `room` (at least kMaxPointsPerPacket long: RotationAssembler::append_room()): `written` points,
  // and when `azimuths` is given, bounds on their azimuth_cdeg (for RotationAssembler::commit()).
  Expected<MsopHeader, DecodeError> decode(ByteSpan payload, std::span<LidarPoint> room, std::size_t& written,
                                           AzimuthRange* azimuths = nullptr) const;

  [[nodiscard]] const std::optional<Calibration>& calibration() const { return calibration_; }
  [[nodiscard]] bool nominal() const { return nominal_; }  // decoding with the nominal table, no DIFOP's yet
  [[nodiscard]] std::optional<DistanceUnit> distance_unit() const { return unit_; }
  [[nodiscard]] std::optional<ReturnMode> return_mode() const { return return_mode_; }
  [[nodiscard]] std::uint16_t rpm() const { return rpm_; }

 private:
  void set_calibration(const Calibration& c);

  DecoderOptions options_;
  std::optional<Calibration> calibration_;
  bool nominal_ = false;  // calibration_ is nominal_calibration(): the first DIFOP with angles replaces it
  std::optional<DistanceUnit> unit_;
  bool unit_assumed_ = false;  // unit_ is the nominal one: the first DIFOP replaces it
  std::optional<ReturnMode> return_mode_;
  std::uint16_t rpm_ = 600;  // rs_driver's default when DIFOP says 0
  struct Channel {
    float cos_vert = 1.F;
    float sin_vert = 0.F;
    float horiz_cdeg = 0.F;
    std::uint16_t ring = 0;
  };
  std::array<Channel, kChannels> table_{};
  // A channel's firing azimuth past its group's, for a group step of so many 0.01 deg: the step's share up to the
  // channel's firing (and the optical centre's direction, which keeps that), plus its horizontal correction.
  struct ChannelTurn {
    double cos_a = 1.0;
    double sin_a = 0.0;
    double cos_f = 1.0;
    double sin_f = 0.0;
    double offset_cdeg = 0.0;
  };
  void fill_turns(double step_cdeg, std::array<ChannelTurn, kChannels>& out) const;
  // By whole step, 0 .. 100 (0.01 deg; 1200 rpm steps 40 a group, 80 a dual pair); filled with the angle table.
  std::vector<std::array<ChannelTurn, kChannels>> turns_;
};

}  // namespace fieldguard::robosense
