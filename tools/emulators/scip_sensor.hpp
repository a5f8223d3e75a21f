#pragma once
// The sensor side of a SCIP 2.0 conversation as a Hokuyo UTM-30LX-EW holds it: answers command lines
// (SCIP2.0, VV, PP, II, BM, MD/ME, QT, RS) and encodes streamed scan replies. Pure: the TCP emulator
// (fieldguard-scip-emulator) and the simulator's recorded 2D LiDAR session (fieldguard-sim --session) both
// use it, so the two speak the same protocol. Encoding rules from protocols.md §3 through the driver's own
// encode_chars() and check_code().

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace fieldguard::tools {

struct ScipSensorIdentity {
  std::string firmware = "1.1.3(fieldguard emulator)";
  std::string serial = "H0000000";
  bool refuse_laser = false;  // BM answers 01 (the laser could not be lit)
};

class ScipSensor {
 public:
  explicit ScipSensor(ScipSensorIdentity identity = {}) : id_(std::move(identity)) {}

  // The whole reply (echo, status, lines, empty line) to one command line given without its terminator.
  [[nodiscard]] std::string reply(std::string_view line);

  [[nodiscard]] bool streaming() const { return streaming_; }
  [[nodiscard]] bool intensity() const { return intensity_; }
  [[nodiscard]] int first_step() const { return first_; }
  [[nodiscard]] int last_step() const { return last_; }

  // One streamed scan reply to the running MD/ME (status 99): `ranges` in mm, one per step from
  // first_step() to last_step(); `intensities` the same count for ME, ignored for MD. The timestamp is
  // the sensor's ms counter (24 bits on the wire).
  [[nodiscard]] std::string scan(std::span<const std::uint32_t> ranges, std::span<const std::uint32_t> intensities,
                                 std::uint32_t time_ms) const;

 private:
  ScipSensorIdentity id_;
  bool laser_ = false;
  bool streaming_ = false;
  bool intensity_ = false;
  int first_ = 0;
  int last_ = 1080;
  std::string echo_;
};

}  // namespace fieldguard::tools
