#pragma once
// The serial reader's options from a sensor section of the configuration: `record` and `run` open the same
// GNSS and AHRS ports the same way.

#include "fieldguard/app/config.hpp"
#include "fieldguard/io/serial_reader.hpp"

namespace fieldguard::app {

[[nodiscard]] inline io::SerialOptions serial_options(const SerialConfig& c) {
  io::SerialOptions o;
  o.device = c.device;
  o.baud = c.baud;
  o.data_bits = c.data_bits;
  o.parity = c.parity;
  o.stop_bits = c.stop_bits;
  o.silence_timeout_s = c.silence_timeout_s;
  o.reopen_interval_s = c.reopen_interval_s;
  return o;
}

}  // namespace fieldguard::app
