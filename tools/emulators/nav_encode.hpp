#pragma once
// The navigation sensors' side of the wire, shared by the simulator's recorded sessions (sim/session.cpp)
// and the live navigation emulator (nav_emulator.cpp): an RTK receiver's NMEA epoch (GGA, RMC, HDT) and an
// Xsens MTi's MTData2 message (PacketCounter, SampleTimeFine, EulerAngles). One encoder, so a replayed
// session and a live bench send the daemon the same bytes for the same values.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace fieldguard::tools {

// v with `decimals` digits after the point ("%.*f").
[[nodiscard]] std::string fixed_text(int decimals, double v);

// "$" + body + "*hh\r\n".
[[nodiscard]] std::string nmea_sentence(const std::string& body);
// "hhmmss.ss" of a UTC time (ns since the Unix epoch), truncated to the hundredth.
[[nodiscard]] std::string nmea_time(std::int64_t utc_ns);
// "ddmmyy" of a UTC time.
[[nodiscard]] std::string nmea_date(std::int64_t utc_ns);
// "ddmm.mmmmmmm,N" (deg_digits 2) / "dddmm.mmmmmmm,E" (3): 1e-7 minutes is 0.2 mm, as RTK receivers print it.
[[nodiscard]] std::string nmea_angle(double deg, int deg_digits, char pos, char neg);

// One epoch of an RTK receiver (fix quality 4, RTK fixed).
struct GnssEpoch {
  std::int64_t utc_ns = 0;  // the epoch
  double lat_deg = 0.0;
  double lon_deg = 0.0;
  double h_m = 0.0;  // ellipsoidal height; GGA prints h_m - geoid_separation_m
  double geoid_separation_m = 0.0;
  int satellites = 0;
  double speed_mps = 0.0;
  std::optional<double> course_deg;  // RMC's course over ground; empty when standing
  double heading_deg = 0.0;          // HDT (dual-antenna heading)
};

// "$GNGGA...", "$GNRMC...", "$GNHDT..." in the order the receiver prints them, each with its CR LF.
[[nodiscard]] std::vector<std::string> nmea_epoch(const GnssEpoch& e);

// One MTData2 sample of an MTi (EulerAngles Float32 in ENU: yaw 0 = east, counter-clockwise).
struct AhrsSample {
  std::uint16_t packet_counter = 0;
  std::uint32_t sample_time_fine = 0;  // 10 kHz ticks
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double yaw_deg = 0.0;
};

// The whole Xbus frame (preamble to checksum) of the MTData2 message.
[[nodiscard]] std::vector<std::uint8_t> mtdata2_frame(const AhrsSample& s);

}  // namespace fieldguard::tools
