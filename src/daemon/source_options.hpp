#pragma once
// The live sources' options from the sensor sections of the configuration: `record` and `run` open the same
// 2D LiDAR connection and GNSS / AHRS ports the same way.

#include <cstdint>

#include "fieldguard/config/config.hpp"
#include "fieldguard/io/scip_source.hpp"
#include "fieldguard/io/serial_reader.hpp"

namespace fieldguard::app {

[[nodiscard]] inline io::SerialOptions serial_options(const SerialConfig& c) {
  return {.device = c.device,
          .baud = c.baud,
          .data_bits = c.data_bits,
          .parity = c.parity,
          .stop_bits = c.stop_bits,
          .silence_timeout_s = c.silence_timeout_s,
          .reopen_interval_s = c.reopen_interval_s};
}

[[nodiscard]] inline io::ScipSourceOptions scip_source_options(const Scan2dConfig& c) {
  io::ScipSourceOptions o;
  o.tcp = {.host = c.host,
           .port = c.port,
           .connect_timeout_s = c.connect_timeout_s,
           .silence_timeout_s = c.silence_timeout_s,
           .backoff_max_s = c.backoff_max_s};
  o.client.scan.first_step = static_cast<std::uint16_t>(c.start_step);
  o.client.scan.last_step = static_cast<std::uint16_t>(c.end_step);
  o.client.intensity = c.intensity;
  return o;
}

}  // namespace fieldguard::app
