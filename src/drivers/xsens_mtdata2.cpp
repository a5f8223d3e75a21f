// MTData2 payload decoding (protocols.md §5.3).

#include "fieldguard/drivers/xsens_mtdata2.hpp"

#include <bit>

namespace fieldguard::xsens {
namespace {

constexpr std::size_t kPacketHeader = 3;  // data id u16, size u8
constexpr std::size_t kUtcTimeSize = 12;
constexpr std::size_t kGnssPvtSize = 94;
constexpr std::size_t kSatInfoHeader = 8;
constexpr std::size_t kSatelliteSize = 4;

constexpr double kFp1220Scale = 1.0 / 1048576.0;     // 2^-20
constexpr double kFp1632Scale = 1.0 / 4294967296.0;  // 2^-32

std::int32_t load_be_i32(ByteSpan b, std::size_t off) { return std::bit_cast<std::int32_t>(load_be32(b, off)); }

std::uint64_t load_be64(ByteSpan b, std::size_t off) {
  return (static_cast<std::uint64_t>(load_be32(b, off)) << 32) | load_be32(b, off + 4);
}

// The values of one packet: n reals of the id's precision.
class Reals {
 public:
  Reals(ByteSpan data, std::uint16_t id) : data_(data), precision_(precision_of(id)) {}
  [[nodiscard]] bool has(std::size_t n) const { return data_.size() == n * value_size(precision_); }
  [[nodiscard]] double operator[](std::size_t i) const {
    return decode_real(data_.subspan(i * value_size(precision_)), precision_);
  }
  [[nodiscard]] Vec3 vec3() const { return {(*this)[0], (*this)[1], (*this)[2]}; }
  [[nodiscard]] Quat quat() const { return {(*this)[0], (*this)[1], (*this)[2], (*this)[3]}; }

 private:
  ByteSpan data_;
  Precision precision_;
};

UtcTime utc_time(ByteSpan d) {
  UtcTime t;
  t.ns = load_be32(d, 0);
  t.year = load_be16(d, 4);
  t.month = d[6];
  t.day = d[7];
  t.hour = d[8];
  t.minute = d[9];
  t.second = d[10];
  t.flags = d[11];
  return t;
}

GnssPvt gnss_pvt(ByteSpan d) {
  GnssPvt p;
  p.itow_ms = load_be32(d, 0);
  p.year = load_be16(d, 4);
  p.month = d[6];
  p.day = d[7];
  p.hour = d[8];
  p.min = d[9];
  p.sec = d[10];
  p.valid = d[11];
  p.t_acc_ns = load_be32(d, 12);
  p.nano_ns = load_be_i32(d, 16);
  p.fix_type = d[20];
  p.flags = d[21];
  p.num_sv = d[22];
  p.reserved1 = d[23];
  p.lon_1e7deg = load_be_i32(d, 24);
  p.lat_1e7deg = load_be_i32(d, 28);
  p.height_mm = load_be_i32(d, 32);
  p.hmsl_mm = load_be_i32(d, 36);
  p.h_acc_mm = load_be32(d, 40);
  p.v_acc_mm = load_be32(d, 44);
  p.vel_n_mmps = load_be_i32(d, 48);
  p.vel_e_mmps = load_be_i32(d, 52);
  p.vel_d_mmps = load_be_i32(d, 56);
  p.gspeed_mmps = load_be_i32(d, 60);
  p.head_mot_1e5deg = load_be_i32(d, 64);
  p.s_acc_mmps = load_be32(d, 68);
  p.head_acc_1e5deg = load_be32(d, 72);
  p.head_veh_1e5deg = load_be_i32(d, 76);
  p.gdop = load_be16(d, 80);
  p.pdop = load_be16(d, 82);
  p.tdop = load_be16(d, 84);
  p.vdop = load_be16(d, 86);
  p.hdop = load_be16(d, 88);
  p.ndop = load_be16(d, 90);
  p.edop = load_be16(d, 92);
  return p;
}

GnssSatInfo sat_info(ByteSpan d) {
  GnssSatInfo s;
  s.itow_ms = load_be32(d, 0);
  s.num_svs = d[4];
  s.reserved = {d[5], d[6], d[7]};
  for (std::size_t off = kSatInfoHeader; off + kSatelliteSize <= d.size(); off += kSatelliteSize) {
    s.satellites.push_back({d[off], d[off + 1], d[off + 2], d[off + 3]});
  }
  return s;
}

// Decodes one packet into `out`. Returns false when the size does not fit the data id; unknown ids are noted.
bool decode_packet(std::uint16_t id, ByteSpan d, MtData2& out) {
  namespace di = data_id;
  const Reals r(d, id);
  switch (id & di::kTypeMask) {
    case di::kPacketCounter:
      if (d.size() != 2) return false;
      out.packet_counter = load_be16(d, 0);
      return true;
    case di::kSampleTimeFine:
      if (d.size() != 4) return false;
      out.sample_time_fine = load_be32(d, 0);
      return true;
    case di::kSampleTimeCoarse:
      if (d.size() != 4) return false;
      out.sample_time_coarse = load_be32(d, 0);
      return true;
    case di::kUtcTime:
      if (d.size() != kUtcTimeSize) return false;
      out.utc_time = utc_time(d);
      return true;
    case di::kStatusByte:
      if (d.size() != 1) return false;
      out.status_byte = d[0];
      return true;
    case di::kStatusWord:
      if (d.size() != 4) return false;
      out.status_word = load_be32(d, 0);
      return true;
    case di::kBaroPressure:
      if (d.size() != 4) return false;
      out.baro_pressure_pa = load_be32(d, 0);
      return true;
    case di::kGnssPvtData:
      if (d.size() != kGnssPvtSize) return false;
      out.gnss_pvt = gnss_pvt(d);
      return true;
    case di::kGnssSatInfo:
      if (d.size() < kSatInfoHeader || (d.size() - kSatInfoHeader) % kSatelliteSize != 0) return false;
      out.gnss_sat_info = sat_info(d);
      return true;
    case di::kTemperature:
      if (!r.has(1)) return false;
      out.temperature_c = r[0];
      return true;
    case di::kAltitudeMsl:
      if (!r.has(1)) return false;
      out.altitude_msl_m = r[0];
      return true;
    case di::kAltitudeEllipsoid:
      if (!r.has(1)) return false;
      out.altitude_ellipsoid_m = r[0];
      return true;
    case di::kLatLon:
      if (!r.has(2)) return false;
      out.lat_deg = r[0];
      out.lon_deg = r[1];
      return true;
    case di::kQuaternion:
      if (!r.has(4)) return false;
      out.quaternion = r.quat();
      out.quaternion_frame = coordinate_system_of(id);
      return true;
    case di::kDeltaQ:
      if (!r.has(4)) return false;
      out.delta_q = r.quat();
      return true;
    case di::kRotationMatrix: {
      if (!r.has(9)) return false;
      std::array<double, 9> m{};
      for (std::size_t i = 0; i < m.size(); ++i) m[i] = r[i];
      out.rotation_matrix = m;
      out.rotation_matrix_frame = coordinate_system_of(id);
      return true;
    }
    default: break;
  }
  // The three-value types.
  std::optional<Vec3>* target = nullptr;
  switch (id & di::kTypeMask) {
    case di::kEulerAngles:
      target = &out.euler_deg;
      out.euler_frame = coordinate_system_of(id);
      break;
    case di::kVelocityXyz:
      target = &out.velocity_mps;
      out.velocity_frame = coordinate_system_of(id);
      break;
    case di::kDeltaV: target = &out.delta_v; break;
    case di::kAcceleration: target = &out.acceleration; break;
    case di::kFreeAcceleration: target = &out.free_acceleration; break;
    case di::kAccelerationHr: target = &out.acceleration_hr; break;
    case di::kRateOfTurn: target = &out.rate_of_turn; break;
    case di::kRateOfTurnHr: target = &out.rate_of_turn_hr; break;
    case di::kMagneticField: target = &out.magnetic_field; break;
    case di::kPositionEcef: target = &out.position_ecef_m; break;
    default: out.unknown_ids.push_back(id); return true;
  }
  if (!r.has(3)) return false;
  *target = r.vec3();
  return true;
}

}  // namespace

std::string_view to_string(Precision p) {
  switch (p) {
    case Precision::Float32: return "Float32";
    case Precision::Fp1220: return "FP1220";
    case Precision::Fp1632: return "FP1632";
    case Precision::Float64: return "Float64";
  }
  return "unknown";
}

std::string_view to_string(CoordinateSystem c) {
  switch (c) {
    case CoordinateSystem::Enu: return "ENU";
    case CoordinateSystem::Ned: return "NED";
    case CoordinateSystem::Nwu: return "NWU";
    case CoordinateSystem::Reserved: return "reserved";
  }
  return "unknown";
}

double decode_real(ByteSpan b, Precision p) {
  switch (p) {
    case Precision::Float32: return static_cast<double>(std::bit_cast<float>(load_be32(b, 0)));
    case Precision::Fp1220: return static_cast<double>(load_be_i32(b, 0)) * kFp1220Scale;
    case Precision::Fp1632: {
      // 48-bit two's complement: the integer part (i16) is the high part, the fraction (u32) the low part.
      const auto integer = static_cast<std::int16_t>(load_be16(b, 4));
      const std::int64_t fixed = static_cast<std::int64_t>(integer) * 4294967296LL + load_be32(b, 0);
      return static_cast<double>(fixed) * kFp1632Scale;
    }
    case Precision::Float64: return std::bit_cast<double>(load_be64(b, 0));
  }
  return 0.0;
}

Expected<MtData2, Error> decode_mtdata2(ByteSpan payload) {
  MtData2 out;
  std::size_t off = 0;
  while (off < payload.size()) {
    if (payload.size() - off < kPacketHeader) return Unexpected{Error::TruncatedPacket};
    const std::uint16_t id = load_be16(payload, off);
    const std::size_t size = payload[off + 2];
    off += kPacketHeader;
    if (payload.size() - off < size) return Unexpected{Error::TruncatedPacket};
    if (!decode_packet(id, payload.subspan(off, size), out)) return Unexpected{Error::BadPacketSize};
    off += size;
  }
  return out;
}

}  // namespace fieldguard::xsens
