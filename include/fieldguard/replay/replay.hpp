#pragma once
// `fieldguard replay`: a capture (and the byte logs of a recording) through the daemon's own frame path, with
// its outputs written in frame order. The command line is the app's (app/commands.cpp); this is what it asks.

#include <cstddef>
#include <optional>
#include <string>

namespace fieldguard::app {

struct ReplayOptions {
  std::string config;                                         // configuration file
  std::optional<std::string> pcap;                            // the capture; exactly one of pcap and session
  std::optional<std::string> session;                         // a directory written by `fieldguard record`
  std::optional<std::string> scan2d_log, gnss_log, ahrs_log;  // byte logs given one by one
  std::optional<std::string> samples_out, obstacles_out, bev_dir, pcd_dir, can_log;
  std::optional<std::string> mcap_out;    // an MCAP recording of the frames (writers/mcap_recorder.hpp)
  std::string mcap_compression = "zstd";  // its chunks': zstd, lz4 or none
  std::optional<std::string> geojson_out;  // the obstacles' footprints in WGS84 (writers/geojson.hpp)
  std::optional<std::size_t> workers;  // 1..64; pipeline.workers of the configuration when not given
  bool quiet = false;                  // no progress line
};

// Runs the replay and prints its summary; returns the process exit code (fieldguard/core/exit_code.hpp).
int replay(const ReplayOptions& options);

}  // namespace fieldguard::app
