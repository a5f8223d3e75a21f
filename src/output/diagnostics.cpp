#include "fieldguard/output/diagnostics.hpp"

namespace fieldguard::output::j1939 {

DiagnosticMessage Diagnostics::update(const safety::Decision& d) {
  const bool starting = (d.reasons & safety::bit(safety::Reason::StartingUp)) != 0;
  std::array<bool, kCodes> now{};
  std::array<Dtc, kCodes> code{};
  for (std::size_t i = 0; i < safety::kSensorCount; ++i) {
    const auto s = static_cast<safety::Sensor>(i);
    now[2 * i] = !starting && (d.fault_sensors & safety::bit(s)) != 0;
    code[2 * i] = Dtc{sensor_spn(s), kFmiAbnormalUpdateRate, 0};
    now[2 * i + 1] = !starting && (d.implausible_sensors & safety::bit(s)) != 0;
    code[2 * i + 1] = Dtc{sensor_spn(s), kFmiErratic, 0};
  }
  now[kCodes - 1] = !starting && (d.reasons & safety::bit(safety::Reason::PipelineLate)) != 0;
  code[kCodes - 1] = Dtc{kSpnPipeline, kFmiAbnormalUpdateRate, 0};

  DiagnosticMessage m;
  for (std::size_t k = 0; k < kCodes; ++k) {
    if (now[k] && !active_[k] && occurrences_[k] < 126) ++occurrences_[k];
    active_[k] = now[k];
    if (!now[k]) continue;
    code[k].occurrences = occurrences_[k];
    m.dtcs.push_back(code[k]);
  }
  if (!m.dtcs.empty()) {
    m.lamps.amber_warning = Lamp::On;
    if (d.stop) m.lamps.red_stop = Lamp::On;
  }
  return m;
}

}  // namespace fieldguard::output::j1939
