#pragma once
// Xsens MTData2 payloads (protocols.md §5.3): a sequence of packets {data id u16 BE, size u8, data}, all values
// big-endian. The data id's low bits select, for the float-valued types, the precision (id & 0x3: float32,
// fixed 12.20, fixed 16.32, float64) and the coordinate system (id & 0xC: ENU, NED, NWU). Unknown data ids are
// skipped (their size says how far) and counted. Pure: no I/O, no logging, errors as values.

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/expected.hpp"
#include "fieldguard/drivers/xsens.hpp"

namespace fieldguard::xsens {

// Data ids with the precision and coordinate-system bits cleared (Xsens xsdataidentifier.h).
namespace data_id {
inline constexpr std::uint16_t kTemperature = 0x0810;
inline constexpr std::uint16_t kUtcTime = 0x1010;
inline constexpr std::uint16_t kPacketCounter = 0x1020;
inline constexpr std::uint16_t kSampleTimeFine = 0x1060;
inline constexpr std::uint16_t kSampleTimeCoarse = 0x1070;
inline constexpr std::uint16_t kQuaternion = 0x2010;
inline constexpr std::uint16_t kRotationMatrix = 0x2020;
inline constexpr std::uint16_t kEulerAngles = 0x2030;
inline constexpr std::uint16_t kBaroPressure = 0x3010;
inline constexpr std::uint16_t kDeltaV = 0x4010;
inline constexpr std::uint16_t kAcceleration = 0x4020;
inline constexpr std::uint16_t kFreeAcceleration = 0x4030;
inline constexpr std::uint16_t kAccelerationHr = 0x4040;
inline constexpr std::uint16_t kAltitudeMsl = 0x5010;
inline constexpr std::uint16_t kAltitudeEllipsoid = 0x5020;
inline constexpr std::uint16_t kPositionEcef = 0x5030;
inline constexpr std::uint16_t kLatLon = 0x5040;
inline constexpr std::uint16_t kGnssPvtData = 0x7010;
inline constexpr std::uint16_t kGnssSatInfo = 0x7020;
inline constexpr std::uint16_t kRateOfTurn = 0x8020;
inline constexpr std::uint16_t kDeltaQ = 0x8030;
inline constexpr std::uint16_t kRateOfTurnHr = 0x8040;
inline constexpr std::uint16_t kMagneticField = 0xC020;
inline constexpr std::uint16_t kVelocityXyz = 0xD010;
inline constexpr std::uint16_t kStatusByte = 0xE010;
inline constexpr std::uint16_t kStatusWord = 0xE020;

inline constexpr std::uint16_t kTypeMask = 0xFFF0;
inline constexpr std::uint16_t kCoordinateSystemMask = 0x000C;
inline constexpr std::uint16_t kPrecisionMask = 0x0003;
}  // namespace data_id

enum class Precision : std::uint8_t { Float32 = 0, Fp1220 = 1, Fp1632 = 2, Float64 = 3 };
enum class CoordinateSystem : std::uint8_t { Enu = 0, Ned = 1, Nwu = 2, Reserved = 3 };  // (id & 0xC) >> 2

[[nodiscard]] constexpr Precision precision_of(std::uint16_t id) { return static_cast<Precision>(id & 0x3U); }
[[nodiscard]] constexpr CoordinateSystem coordinate_system_of(std::uint16_t id) {
  return static_cast<CoordinateSystem>((id & 0xCU) >> 2);
}
// Bytes one value takes: 4, 4, 6, 8.
[[nodiscard]] constexpr std::size_t value_size(Precision p) {
  return p == Precision::Fp1632 ? 6U : p == Precision::Float64 ? 8U : 4U;
}
[[nodiscard]] std::string_view to_string(Precision p);         // "Float32", "FP1220", "FP1632", "Float64"
[[nodiscard]] std::string_view to_string(CoordinateSystem c);  // "ENU", "NED", "NWU", "reserved"

// One value of the given precision at the start of `b` (which holds at least value_size(p) bytes).
// Fixed 12.20: int32 / 2^20. Fixed 16.32: 4 bytes fraction (u32) then 2 bytes integer part (i16), = i48 / 2^32.
[[nodiscard]] double decode_real(ByteSpan b, Precision p);

struct Vec3 {
  double x = 0.0, y = 0.0, z = 0.0;
};
struct Quat {
  double w = 1.0, x = 0.0, y = 0.0, z = 0.0;  // q0 (scalar), q1, q2, q3
};

struct UtcTime {
  std::uint32_t ns = 0;
  std::uint16_t year = 0;
  std::uint8_t month = 0, day = 0, hour = 0, minute = 0, second = 0;
  std::uint8_t flags = 0;  // validity: bit 0 date, bit 1 time of day, bit 2 fully resolved
};

// GnssPvtData (0x7010, 94 bytes): the receiver's navigation solution, raw integers as sent (u-blox NAV-PVT).
struct GnssPvt {
  std::uint32_t itow_ms = 0;
  std::uint16_t year = 0;
  std::uint8_t month = 0, day = 0, hour = 0, min = 0, sec = 0, valid = 0;
  std::uint32_t t_acc_ns = 0;
  std::int32_t nano_ns = 0;
  std::uint8_t fix_type = 0, flags = 0, num_sv = 0, reserved1 = 0;
  std::int32_t lon_1e7deg = 0, lat_1e7deg = 0;
  std::int32_t height_mm = 0, hmsl_mm = 0;  // above the ellipsoid, above mean sea level
  std::uint32_t h_acc_mm = 0, v_acc_mm = 0;
  std::int32_t vel_n_mmps = 0, vel_e_mmps = 0, vel_d_mmps = 0, gspeed_mmps = 0;
  std::int32_t head_mot_1e5deg = 0;
  std::uint32_t s_acc_mmps = 0, head_acc_1e5deg = 0;
  std::int32_t head_veh_1e5deg = 0;
  std::uint16_t gdop = 0, pdop = 0, tdop = 0, vdop = 0, hdop = 0, ndop = 0, edop = 0;  // x 0.01
};

struct GnssSatellite {
  std::uint8_t gnss_id = 0, sv_id = 0, cno_dbhz = 0, flags = 0;
};
// GnssSatInfo (0x7020): 8-byte header, then 4 bytes a satellite.
struct GnssSatInfo {
  std::uint32_t itow_ms = 0;
  std::uint8_t num_svs = 0;
  std::array<std::uint8_t, 3> reserved{};
  std::vector<GnssSatellite> satellites;
};

// One MTData2 message: each field is set when its packet was present.
struct MtData2 {
  std::optional<std::uint16_t> packet_counter;
  std::optional<std::uint32_t> sample_time_fine;    // 10 kHz ticks
  std::optional<std::uint32_t> sample_time_coarse;  // s
  std::optional<UtcTime> utc_time;

  std::optional<Quat> quaternion;
  std::optional<std::array<double, 9>> rotation_matrix;  // wire order
  std::optional<Vec3> euler_deg;                         // x roll, y pitch, z yaw
  CoordinateSystem quaternion_frame = CoordinateSystem::Enu;
  CoordinateSystem rotation_matrix_frame = CoordinateSystem::Enu;
  CoordinateSystem euler_frame = CoordinateSystem::Enu;

  std::optional<Vec3> delta_v;            // m/s
  std::optional<Vec3> acceleration;       // m/s², gravity included
  std::optional<Vec3> free_acceleration;  // m/s², gravity removed
  std::optional<Vec3> acceleration_hr;    // m/s²
  std::optional<Vec3> rate_of_turn;       // rad/s
  std::optional<Quat> delta_q;
  std::optional<Vec3> rate_of_turn_hr;  // rad/s
  std::optional<Vec3> magnetic_field;   // a.u.
  std::optional<double> temperature_c;
  std::optional<std::uint32_t> baro_pressure_pa;

  std::optional<double> altitude_msl_m;
  std::optional<double> altitude_ellipsoid_m;
  std::optional<Vec3> position_ecef_m;
  std::optional<double> lat_deg, lon_deg;
  std::optional<Vec3> velocity_mps;
  CoordinateSystem velocity_frame = CoordinateSystem::Enu;

  std::optional<GnssPvt> gnss_pvt;
  std::optional<GnssSatInfo> gnss_sat_info;

  std::optional<std::uint8_t> status_byte;
  std::optional<std::uint32_t> status_word;

  std::vector<std::uint16_t> unknown_ids;  // data ids skipped, in order
};

// StatusWord bits (protocols.md §5.3; newer Xsens headers where older ones disagree).
namespace status {
inline constexpr std::uint32_t kSelfTest = 1U << 0;
inline constexpr std::uint32_t kFilterValid = 1U << 1;
inline constexpr std::uint32_t kGnssFix = 1U << 2;
inline constexpr std::uint32_t kClockSynced = 1U << 6;
inline constexpr std::uint32_t kClippingDetected = 1U << 19;
inline constexpr std::uint32_t kSyncIn = 1U << 21;
inline constexpr std::uint32_t kSyncOut = 1U << 22;
inline constexpr std::uint32_t kFilterModeMask = 7U << 23;
inline constexpr std::uint32_t kRtkStatusMask = 3U << 27;
}  // namespace status

// Decodes an MTData2 payload. Errors: TruncatedPacket, BadPacketSize.
[[nodiscard]] Expected<MtData2, Error> decode_mtdata2(ByteSpan payload);

}  // namespace fieldguard::xsens
