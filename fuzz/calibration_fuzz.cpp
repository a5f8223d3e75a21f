// libFuzzer target: the Velodyne calibration file parsers (ROS YAML, VeloView db.xml) on arbitrary text.
// A result must be either an error message or a calibration the decoder accepts.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fieldguard/drivers/velodyne_calibration.hpp"
#include "fieldguard/drivers/velodyne_decoder.hpp"

namespace {

void check(const fieldguard::Expected<fieldguard::velodyne::Calibration, std::string>& r) {
  if (!r) {
    if (r.error().empty()) __builtin_trap();  // every error says what is wrong
    return;
  }
  fieldguard::velodyne::DecoderOptions o;
  o.model = r->model;
  const fieldguard::velodyne::Decoder decoder(*r, o);  // throws (and so fails the run) for a misfit table
  (void)decoder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  check(fieldguard::velodyne::parse_ros_calibration(text));
  check(fieldguard::velodyne::parse_veloview_calibration(text));
  return 0;
}
