#include "sim/sensor.hpp"

#include <algorithm>
#include <cmath>

#include "sim/hdl32e.hpp"
#include "sim/rs32.hpp"
#include "sim/rs32_encoder.hpp"
#include "sim/vlp16.hpp"

namespace fieldguard::sim {

namespace {

constexpr std::int64_t kUsPerHour = 3600LL * 1000 * 1000;

Sensor hdl32e_sensor() {
  Sensor s;
  s.model = SensorModel::Hdl32e;
  s.name = "hdl32e";
  s.label = "HDL-32E";
  s.lasers = hdl32e::kLasers;
  s.vertical_deg = hdl32e::kVerticalDeg;
  // j times the firing's fraction (not j firings divided by the block): the rays as the simulator always cast them,
  // so that HDL-32E captures stay byte-identical.
  const double firing = static_cast<double>(hdl32e::kFiringNs) / static_cast<double>(hdl32e::kBlockNs);
  for (std::size_t j = 0; j < kSlots; ++j) {
    s.slot_ns[j] = static_cast<std::int64_t>(j) * hdl32e::kFiringNs;
    s.slot_fraction[j] = static_cast<double>(j) * firing;
  }
  s.group_ns = hdl32e::kBlockNs;
  s.data_port = hdl32e::kDataPort;
  return s;
}

Sensor vlp16_sensor() {
  Sensor s;
  s.model = SensorModel::Vlp16;
  s.name = "vlp16";
  s.label = "VLP-16";
  s.lasers = vlp16::kLasers;
  for (std::size_t slot = 0; slot < kSlots; ++slot) {
    const auto sequence = static_cast<std::int64_t>(slot / vlp16::kLasers);
    const std::size_t laser = slot % vlp16::kLasers;
    s.slot_ns[slot] = sequence * vlp16::kSequenceNs + static_cast<std::int64_t>(laser) * vlp16::kFiringNs;
    s.slot_fraction[slot] = static_cast<double>(s.slot_ns[slot]) / static_cast<double>(vlp16::kBlockNs);
    s.vertical_deg[slot] = vlp16::kVerticalDeg[laser];
  }
  s.group_ns = vlp16::kBlockNs;
  s.data_port = hdl32e::kDataPort;
  return s;
}

Sensor rs32_sensor() {
  Sensor s;
  s.model = SensorModel::Rs32;
  s.name = "rs32";
  s.label = "RS-LiDAR-32";
  s.lasers = rs32::kChannels;
  s.vertical_deg = rs32::kVerticalDeg;
  s.horizontal_deg = rs32::kHorizontalDeg;
  s.slot_ns = rs32::kFiringOffsetNs;
  for (std::size_t c = 0; c < kSlots; ++c) {
    s.slot_fraction[c] = static_cast<double>(s.slot_ns[c]) / static_cast<double>(rs32::kBlockNs);
  }
  s.group_ns = rs32::kBlockNs;
  s.distance_unit_m = rs32::kDistanceUnitM;
  s.min_range_m = rs32::kMinRangeM;
  s.optical_centre_m = rs32::kOpticalCentreM;
  s.data_port = rs32::kMsopPort;
  s.info_port = rs32::kDifopPort;
  s.info_period_ns = rs32::kDifopPeriodNs;
  return s;
}

}  // namespace

std::optional<SensorModel> sensor_model(std::string_view name) {
  if (name == "hdl32e") return SensorModel::Hdl32e;
  if (name == "vlp16") return SensorModel::Vlp16;
  if (name == "rs32") return SensorModel::Rs32;
  return std::nullopt;
}

std::optional<ReturnMode> return_mode(std::string_view name) {
  if (name == "strongest") return ReturnMode::Strongest;
  if (name == "dual") return ReturnMode::Dual;
  return std::nullopt;
}

std::string_view to_string(ReturnMode m) { return m == ReturnMode::Dual ? "dual" : "strongest"; }

Sensor make_sensor(SensorModel model, ReturnMode mode) {
  Sensor s = model == SensorModel::Rs32    ? rs32_sensor()
             : model == SensorModel::Vlp16 ? vlp16_sensor()
                                           : hdl32e_sensor();
  s.mode = mode;
  return s;
}

std::int64_t Sensor::last_firing_ns() const {
  return packet_ns() - group_ns + *std::max_element(slot_ns.begin(), slot_ns.end());
}

int Sensor::packets_per_rotation(double rate_hz) const {
  const double packet_s = static_cast<double>(packet_ns()) * 1e-9;
  return std::max(1, static_cast<int>(std::lround(1.0 / (rate_hz * packet_s))));
}

bool Sensor::rate_supported(double rate_hz) const {
  // The RS-32's motor runs at 300, 600 or 1200 rpm only (protocols.md §2.3).
  if (model == SensorModel::Rs32) return rate_hz == 5.0 || rate_hz == 10.0 || rate_hz == 20.0;
  return rate_hz >= 5.0 && rate_hz <= 20.0;
}

std::string Sensor::rate_rule() const {
  if (model == SensorModel::Rs32) return "5, 10 or 20 Hz (the RS-LiDAR-32's 300, 600 or 1200 rpm)";
  return "a number of Hz from 5 to 20 (the " + std::string(label) + "'s range)";
}

std::pair<EncodedReturn, EncodedReturn> Sensor::dual_pair(EncodedReturn first, EncodedReturn last) const {
  // One echo (or none) fills both blocks alike.
  if (last.distance == 0) return {first, first};
  if (first.distance == 0) return {last, last};
  if (model == SensorModel::Rs32) {
    // The strongest echo in the even block and the other one (the last, or the second strongest when the last is
    // the strongest) in the odd block: rs_driver's reading, which the project's decoder follows; the manuals leave
    // which is which unconfirmed (protocols.md §2.2).
    return last.intensity > first.intensity ? std::pair{last, first} : std::pair{first, last};
  }
  // Velodyne (protocols.md §1.8): the last echo in the even block, the strongest in the odd one or, when the last is
  // also the strongest, the second strongest: of two echoes, the odd block holds the first either way.
  return {last, first};
}

PacketBytes Sensor::encode(const PacketBlocks& blocks, std::int64_t first_firing_unix_ns) const {
  if (model == SensorModel::Rs32) return rs32::encode_msop(blocks, first_firing_unix_ns);
  // The timestamp marks the packet's last firing (HDL-32E manual, appendix E; protocols.md §1.7); the simulated
  // VLP-16 keeps the same convention.
  const std::int64_t us = (first_firing_unix_ns + last_firing_ns()) / 1000;
  return encode_velodyne(blocks, static_cast<std::uint32_t>(us % kUsPerHour),
                         dual() ? hdl32e::kReturnDual : hdl32e::kReturnStrongest,
                         model == SensorModel::Vlp16 ? vlp16::kProductVlp16 : hdl32e::kProductHdl32e);
}

PacketBytes Sensor::encode_info(double rate_hz, std::int64_t unix_ns) const {
  return rs32::encode_difop(static_cast<std::uint16_t>(std::lround(rate_hz * 60.0)), dual(), unix_ns);
}

}  // namespace fieldguard::sim
