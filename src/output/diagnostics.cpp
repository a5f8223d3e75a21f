#include "fieldguard/output/diagnostics.hpp"

namespace fieldguard::output::j1939 {

Dtc Diagnostics::code(std::size_t k) {
  if (k < 2 * safety::kSensorCount) {
    const auto s = static_cast<safety::Sensor>(k / 2);
    return Dtc{sensor_spn(s), k % 2 == 0 ? kFmiAbnormalUpdateRate : kFmiErratic, 0};
  }
  if (k == 2 * safety::kSensorCount) return Dtc{kSpnPipeline, kFmiAbnormalUpdateRate, 0};
  return Dtc{kSpnCanOutput, k == 2 * safety::kSensorCount + 1 ? kFmiBadDevice : kFmiConditionExists, 0};
}

DiagnosticMessage Diagnostics::update(const safety::Decision& d, const BusFaults& bus) {
  const bool starting = (d.reasons & safety::bit(safety::Reason::StartingUp)) != 0;
  std::array<bool, kCodes> now{};
  for (std::size_t i = 0; i < safety::kSensorCount; ++i) {
    const auto s = static_cast<safety::Sensor>(i);
    now[2 * i] = !starting && (d.fault_sensors & safety::bit(s)) != 0;
    now[2 * i + 1] = !starting && (d.implausible_sensors & safety::bit(s)) != 0;
  }
  now[2 * safety::kSensorCount] = !starting && (d.reasons & safety::bit(safety::Reason::PipelineLate)) != 0;
  // The bus's own faults are faults from the start: the start-up is the sensors', not the bus's.
  now[2 * safety::kSensorCount + 1] = bus.send_errors;
  now[2 * safety::kSensorCount + 2] = bus.address_conflict;

  DiagnosticMessage m;
  bool stops = false;
  for (std::size_t k = 0; k < kCodes; ++k) {
    if (now[k] && !active_[k] && occurrences_[k] < 126) ++occurrences_[k];
    active_[k] = now[k];
    if (!now[k]) continue;
    Dtc c = code(k);
    c.occurrences = occurrences_[k];
    m.dtcs.push_back(c);
    stops = stops || k <= 2 * safety::kSensorCount;  // the safety monitor stops for each of these
  }
  if (!m.dtcs.empty()) {
    m.lamps.amber_warning = Lamp::On;
    if (d.stop && stops) m.lamps.red_stop = Lamp::On;
  }
  return m;
}

DiagnosticMessage Diagnostics::previously_active() const {
  DiagnosticMessage m;
  for (std::size_t k = 0; k < kCodes; ++k) {
    if (active_[k] || occurrences_[k] == 0) continue;
    Dtc c = code(k);
    c.occurrences = occurrences_[k];
    m.dtcs.push_back(c);
  }
  return m;
}

}  // namespace fieldguard::output::j1939
