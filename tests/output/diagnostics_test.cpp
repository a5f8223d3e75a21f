// The safety monitor's faults as DM1 DTCs: which SPN and FMI for which fault, occurrence counts across updates,
// the lamps, nothing while starting up; and the DM1 that goes on the bus decodes back (one frame or BAM).

#include "fieldguard/output/diagnostics.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace fieldguard::output::j1939 {
namespace {

namespace safety = output::safety;

safety::Decision go() {
  safety::Decision d;
  d.stop = false;
  d.reason = safety::Reason::None;
  return d;
}

safety::Decision fault(std::uint8_t silent, std::uint8_t implausible, bool late = false) {
  safety::Decision d;
  d.stop = true;
  d.reason = safety::Reason::SensorFault;
  d.fault_sensors = silent;
  d.implausible_sensors = implausible;
  if (silent != 0) d.reasons |= safety::bit(safety::Reason::SensorFault);
  if (implausible != 0) d.reasons |= safety::bit(safety::Reason::ImplausibleData);
  if (late) d.reasons |= safety::bit(safety::Reason::PipelineLate);
  return d;
}

TEST(Diagnostics, EachFaultItsOwnSpnAndFmi) {
  Diagnostics dg;
  EXPECT_TRUE(dg.update(go()).dtcs.empty());
  const DiagnosticMessage m =
      dg.update(fault(safety::bit(safety::Sensor::Gnss), safety::bit(safety::Sensor::Ahrs), true));
  const std::vector<Dtc> expect{{520194, 9, 1}, {520195, 2, 1}, {520200, 9, 1}};
  EXPECT_EQ(m.dtcs, expect);
  EXPECT_EQ(m.lamps.amber_warning, Lamp::On);
  EXPECT_EQ(m.lamps.red_stop, Lamp::On);
  EXPECT_EQ(m.lamps.malfunction, Lamp::Off);
  // On the bus: three DTCs take the transport protocol, and decode back.
  const auto bytes = encode_diagnostic(m);
  EXPECT_EQ(bytes.size(), 14U);
  const auto back = decode_diagnostic(bytes);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->dtcs, expect);
}

TEST(Diagnostics, OccurrencesCountEachTimeAFaultReturns) {
  Diagnostics dg;
  const auto lidar = fault(safety::bit(safety::Sensor::Lidar), 0);
  EXPECT_EQ(dg.update(lidar).dtcs.at(0).occurrences, 1);
  EXPECT_EQ(dg.update(lidar).dtcs.at(0).occurrences, 1) << "still the same occurrence";
  const DiagnosticMessage cleared = dg.update(go());
  EXPECT_TRUE(cleared.dtcs.empty());
  EXPECT_EQ(cleared.lamps.amber_warning, Lamp::Off);
  const auto again = dg.update(lidar);
  ASSERT_EQ(again.dtcs.size(), 1U);
  EXPECT_EQ(again.dtcs[0], (Dtc{520192, 9, 2}));
  for (int i = 0; i < 200; ++i) {
    (void)dg.update(go());
    (void)dg.update(lidar);
  }
  EXPECT_EQ(dg.update(lidar).dtcs[0].occurrences, 126) << "J1939-73 counts to 126";
}

TEST(Diagnostics, NothingWhileStartingUp) {
  Diagnostics dg;
  safety::Decision d;  // the monitor's first decision: stop, starting up, every sensor awaited
  d.reasons = safety::bit(safety::Reason::StartingUp);
  d.fault_sensors = 0x0F;
  const DiagnosticMessage m = dg.update(d);
  EXPECT_TRUE(m.dtcs.empty());
  EXPECT_EQ(m.lamps.amber_warning, Lamp::Off);
  EXPECT_EQ(encode_diagnostic(m).size(), 8U);  // the no-DTC DM1: one frame
}

TEST(Diagnostics, TheBusOwnFaultsWarnWithoutTheStopLamp) {
  Diagnostics dg;
  safety::Decision starting;
  starting.reasons = safety::bit(safety::Reason::StartingUp);
  BusFaults bus;
  bus.send_errors = true;
  const DiagnosticMessage m = dg.update(starting, bus);  // a bus fault is one from the start
  ASSERT_EQ(m.dtcs.size(), 1U);
  EXPECT_EQ(m.dtcs[0], (Dtc{520201, 12, 1}));
  EXPECT_EQ(m.lamps.amber_warning, Lamp::On);
  EXPECT_EQ(m.lamps.red_stop, Lamp::Off) << "the tractor is stopped for starting up, not for the bus";
  bus = {};
  bus.address_conflict = true;
  const DiagnosticMessage c = dg.update(go(), bus);
  ASSERT_EQ(c.dtcs.size(), 1U);
  EXPECT_EQ(c.dtcs[0], (Dtc{520201, 31, 1}));
}

TEST(Diagnostics, PreviouslyActiveKeepsTheCountsOfClearedFaults) {
  Diagnostics dg;
  EXPECT_TRUE(dg.previously_active().dtcs.empty());
  (void)dg.update(fault(safety::bit(safety::Sensor::Scan2d), 0));
  EXPECT_TRUE(dg.previously_active().dtcs.empty()) << "still active: DM1's, not DM2's";
  (void)dg.update(go());
  (void)dg.update(fault(safety::bit(safety::Sensor::Scan2d), 0));
  (void)dg.update(fault(0, safety::bit(safety::Sensor::Gnss)));
  const DiagnosticMessage m = dg.previously_active();
  ASSERT_EQ(m.dtcs.size(), 1U);
  EXPECT_EQ(m.dtcs[0], (Dtc{520193, 9, 2}));
  EXPECT_EQ(m.lamps.amber_warning, Lamp::Off);
}

}  // namespace
}  // namespace fieldguard::output::j1939
