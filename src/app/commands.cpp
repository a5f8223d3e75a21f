// The subcommands' command lines: each declares its options (CLI11), checks what CLI11 cannot, and calls its
// module with the options struct that module asks for.

#include "app/commands.hpp"

#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "fieldguard/config/config.hpp"
#include "fieldguard/core/exit_code.hpp"
#include "fieldguard/daemon/daemon.hpp"
#include "fieldguard/drivers/lidar3d_stream.hpp"
#include "fieldguard/inspect/inspect.hpp"
#include "fieldguard/perception/beam_geometry.hpp"
#include "fieldguard/replay/replay.hpp"

namespace fieldguard::app {
namespace {

// A whole number from `lo` to `hi`, or nullopt.
std::optional<unsigned long> whole_number(const std::string& text, unsigned long lo, unsigned long hi) {
  unsigned long n = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
  if (ec != std::errc() || ptr != text.data() + text.size() || n < lo || n > hi) return std::nullopt;
  return n;
}

// What CLI11 left over (each subcommand allows extras so that this message is ours): "unknown option --x" or
// "unexpected argument 'x'"; empty when nothing was left.
std::string leftover(const CLI::App& cmd) {
  const auto rest = cmd.remaining();
  if (rest.empty()) return {};
  const std::string& first = rest.front();
  if (first.rfind("--", 0) == 0 && first != "--") return "unknown option " + first.substr(0, first.find('='));
  return "unexpected argument '" + first + "'";
}

CLI::App* subcommand(CLI::App& top, const char* name, const char* summary, const char* description) {
  CLI::App* cmd = top.add_subcommand(name, summary);
  cmd->allow_extras();
  cmd->footer(description);
  return cmd;
}

constexpr const char* kConfigHelp = "configuration (see config/fieldguard.yaml)";

}  // namespace

int usage_error(const CLI::App& cmd, const std::string& why) {
  std::fprintf(stderr, "fieldguard %s: %s\n%s", cmd.get_name().c_str(), why.c_str(), cmd.help().c_str());
  return kExitBadInput;
}

Command add_check_config(CLI::App& top) {
  auto files = std::make_shared<std::vector<std::string>>();
  CLI::App* cmd =
      subcommand(top, "check-config", "validate a configuration file and list every problem",
                 "Loads FILE as a fieldguard configuration and reports every problem at once, each as\n"
                 "FILE:LINE: key.path: what is wrong and what to do. Exit code 0 when valid, 2 otherwise.\n");
  cmd->add_option("FILE", *files, "the configuration file");
  return {cmd, "fieldguard check-config FILE", [cmd, files] {
            if (const auto why = leftover(*cmd); !why.empty()) return usage_error(*cmd, why);
            if (files->size() != 1) return usage_error(*cmd, "give exactly one configuration file");
            const std::string& path = files->front();
            const auto result = load_config_file(path);
            for (const auto& issue : result.issues) std::fprintf(stderr, "%s\n", issue.to_string().c_str());
            if (!result.ok()) {
              std::fprintf(stderr, "%zu problem%s in %s\n", result.issues.size(), result.issues.size() == 1 ? "" : "s",
                           path.c_str());
              return kExitBadInput;
            }
            std::printf("%s: valid\n", path.c_str());
            // What the rules scaled by the ring spacing take: a configured spacing or each sensor's own.
            const double spacing = result.config.perception.cluster.beam_spacing_deg;
            if (spacing > 0.0) {
              std::printf("ring spacing: %.2f deg for every sensor (perception.cluster.beam_spacing_deg)\n", spacing);
            } else {
              std::printf(
                  "ring spacing: each sensor's own, at each point's elevation (perception.cluster.beam_spacing_deg: "
                  "auto): HDL-32E %s; VLP-16 %s; RS-32 from its DIFOP (nominal: %s)\n",
                  perception::BeamGeometry(lidar3d::ring_elevations_deg(lidar3d::Model::HDL32E)).describe().c_str(),
                  perception::BeamGeometry(lidar3d::ring_elevations_deg(lidar3d::Model::VLP16)).describe().c_str(),
                  perception::BeamGeometry(lidar3d::ring_elevations_deg(lidar3d::Model::RS32)).describe().c_str());
            }
            return kExitOk;
          }};
}

Command add_replay(CLI::App& top) {
  auto opt = std::make_shared<ReplayOptions>();
  auto workers = std::make_shared<std::optional<std::string>>();
  CLI::App* cmd = subcommand(
      top, "replay", "run captured sensor data (pcap) through the pipeline",
      "Runs a capture of Velodyne packets (classic pcap or pcapng; Ethernet, VLAN, Linux cooked SLL/SLL2 or raw\n"
      "IPv4) through the decoder and the same frame path as the daemon. The capture alone gives one frame per\n"
      "rotation, in the 3D LiDAR's sensor frame. With the byte logs of the 2D LiDAR, GNSS or AHRS (a --session, or\n"
      "the --*-log options) the capture and the logs are merged by receive time and fused as live: frames of whole\n"
      "rotations at sync.rate_hz with the 2D scan nearest in time, each point deskewed with the vehicle's pose\n"
      "(`geo:`) into the levelled detection frame (x the heading, y left, z up, origin at the 3D LiDAR's mounting),\n"
      "the 2D scan lifted into it; a frame that lacks a sensor goes out after sync.timeout_s, marked.\n"
      "\n"
      "Ends with a summary: packets read, decoded, dropped by reason, rotations, points, wall time.\n"
      "Exit code 0 when the capture was used, 2 for unusable input (missing or unreadable file, not a pcap,\n"
      "no Velodyne data in it, invalid configuration), 1 when writing the output failed.\n");
  cmd->add_option("--config", opt->config, kConfigHelp)->type_name("FILE");
  cmd->add_option("--pcap", opt->pcap, "the capture")->type_name("FILE");
  cmd->add_option("--session", opt->session,
                  "a directory written by `fieldguard record`: DIR/lidar.pcap and the byte logs\n"
                  "of the 2D LiDAR (scan2d.log), GNSS (gnss.log) and AHRS (ahrs.log), each decoded by\n"
                  "the same decoders as live")
      ->type_name("DIR");
  const char* kLogHelp = "byte log of a recording given one by one (with --pcap),\ninstead of a --session";
  cmd->add_option("--scan2d-log", opt->scan2d_log, std::string("the 2D LiDAR's ") + kLogHelp)->type_name("FILE");
  cmd->add_option("--gnss-log", opt->gnss_log, std::string("the GNSS receiver's ") + kLogHelp)->type_name("FILE");
  cmd->add_option("--ahrs-log", opt->ahrs_log, std::string("the AHRS's ") + kLogHelp)->type_name("FILE");
  cmd->add_option("--samples-out", opt->samples_out,
                  "write every decoded sample of every sensor as a JSON line (as `record --samples-out`)")
      ->type_name("FILE");
  cmd->add_option("--obstacles-out", opt->obstacles_out,
                  "run the detection pipeline and write one JSON line per frame, in order:\n"
                  "{\"frame\", \"stamp\" (s, capture time of the rotation's first packet), \"partial\",\n"
                  "\"points_in\", \"obstacles\": [{\"min\", \"max\" (m, sensor frame), \"points\", \"obb\",\n"
                  "\"distance\" (m), \"bearing\" (deg, + left), \"height\" (m above local ground), \"class\"}]};\n"
                  "a fused frame adds \"fusion\" (levelling full | attitude_only | none, rotations,\n"
                  "scan_points, missing sensors, timed_out, dropped_points, pose: plane easting/northing/up/\n"
                  "zone and roll/pitch/yaw deg) and per obstacle \"plane\" [easting, northing, up] of its\n"
                  "footprint")
      ->type_name("FILE");
  cmd->add_option("--mcap-out", opt->mcap_out,
                  "run the detection pipeline and the safety monitor and record every frame into an MCAP\n"
                  "file for Foxglove or Lichtblick, on the capture's timeline: the points as measured\n"
                  "(/lidar/points) and as detection labelled them (/detection/points), the obstacle boxes\n"
                  "(/detection/obstacles), the stop zone and ROI (/detection/zones), the decision\n"
                  "(/safety/decision), and for a fused frame its pose (/tf) and position (/gnss/fix);\n"
                  "Foxglove's schemas, JSON-encoded (docs/commands.md)")
      ->type_name("FILE");
  cmd->add_option("--geojson-out", opt->geojson_out,
                  "run the detection pipeline and write the obstacles' footprints as GeoJSON: one Polygon\n"
                  "(WGS84 longitude, latitude) per obstacle of each fused frame with a full pose (GNSS and\n"
                  "AHRS), properties frame, stamp, distance_m, height_m, class, held; frames without a pose\n"
                  "give none (counted in the summary)")
      ->type_name("FILE");
  cmd->add_option("--mcap-compression", opt->mcap_compression, "the MCAP chunks' compression (default zstd)")
      ->check(CLI::IsMember({"zstd", "lz4", "none"}))
      ->type_name("zstd|lz4|none");
  cmd->add_option("--bev-dir", opt->bev_dir,
                  "write a bird's-eye PNG per frame (points by height, ground dimmed, obstacle boxes\n"
                  "with their distance, ROI and body box, 1 m grid)")
      ->type_name("DIR");
  cmd->add_option("--pcd-dir", opt->pcd_dir,
                  "write one binary PCD per frame: frame_NNNNNN.pcd, and frame_NNNNNN_partial.pcd for\n"
                  "the first and last rotations when they are not a full turn (fields x y z intensity ring\n"
                  "time; sensor frame x forward, y left, z up, metres; time in s after the rotation start;\n"
                  "a fused frame's points are in the detection frame and its ring field holds the 2D scan's\n"
                  "step for the 2D LiDAR's points)")
      ->type_name("DIR");
  cmd->add_option("--can-log", opt->can_log,
                  "run the detection pipeline and the safety monitor (`safety:`) and write every CAN frame\n"
                  "the daemon would have sent (`can:` addresses, DBC config/fieldguard.dbc) as a candump -L\n"
                  "log stamped with capture time: heartbeats and the stop request every\n"
                  "can.heartbeat_period_s from the first packet (STOP, starting up, until the first frame\n"
                  "is decided), and per frame, when its last data is in, the obstacle summary, the\n"
                  "obstacles and the stop request. A sensor counts as heard at the receive time of its\n"
                  "newest data at or before the decision; one without a log counts as never heard")
      ->type_name("FILE");
  cmd->add_option("--workers", *workers,
                  "run the detection pipeline on N worker threads (1..64; default: pipeline.workers of the\n"
                  "configuration, 1 without it). Every output is written in frame order on the main\n"
                  "thread and is byte-identical for any N; no frame is ever dropped (the reader waits\n"
                  "for the workers when they fall behind)")
      ->type_name("N");
  cmd->add_flag("--quiet", opt->quiet, "no progress line");
  return {cmd,
          "fieldguard replay --config FILE (--pcap FILE | --session DIR) [--obstacles-out FILE] [--mcap-out FILE]\n"
          "                         [--geojson-out FILE] [--bev-dir DIR] [--pcd-dir DIR] [--samples-out FILE] "
          "[--can-log FILE]\n"
          "                         [--workers N] [--quiet]",
          [cmd, opt, workers] {
            if (const auto why = leftover(*cmd); !why.empty()) return usage_error(*cmd, why);
            if (opt->config.empty() || opt->pcap.has_value() == opt->session.has_value()) {
              return usage_error(*cmd, "--config and one of --pcap or --session are required");
            }
            if (*workers) {
              // 1..64: sync::PoolParams' limits.
              opt->workers = whole_number(**workers, 1, 64);
              if (!opt->workers) {
                return usage_error(
                    *cmd, "--workers takes a whole number of worker threads from 1 to 64, got '" + **workers + "'");
              }
            }
            return replay(*opt);
          }};
}

Command add_inspect(CLI::App& top) {
  auto files = std::make_shared<std::vector<std::string>>();
  auto opt = std::make_shared<InspectOptions>();
  auto data_port = std::make_shared<std::optional<std::string>>();
  auto position_port = std::make_shared<std::optional<std::string>>();
  CLI::App* cmd = subcommand(
      top, "inspect", "decode a capture (NMEA, Xsens, ...) into one JSON line per sample",
      "Decodes a capture and prints every decoded sample as one JSON line on stdout, then a summary on stderr:\n"
      "records by kind, rejected input by reason, and the bytes that were noise. Rejected input gives no record.\n"
      "The format is guessed from the first bytes when --format is left out (a pcap by the UDP ports or sizes of\n"
      "its first datagrams: robosense for 6699/7788, velodyne otherwise).\n"
      "\n"
      "Formats:\n"
      "  nmea    NMEA 0183 text (GGA, RMC, VTG, HDT, THS from any talker; '#' comment lines are skipped).\n"
      "          Keys: type (talker + sentence, \"GNGGA\"); GGA: time_utc lat_deg lon_deg alt_m (above mean sea\n"
      "          level) quality sats hdop geoid_sep_m alt_hae_m dgps_age_s dgps_station; RMC: time_utc status\n"
      "          lat_deg lon_deg speed_mps course_deg date mag_var_deg mode; VTG: course_true_deg course_mag_deg\n"
      "          speed_mps mode; HDT: heading_deg; THS: heading_deg mode. South and west are negative; null where\n"
      "          the sentence's field is empty.\n"
      "  xsens   raw Xsens Xbus stream (MTData2). Keys: type \"MTData2\", packet_counter, sample_time_fine (10 kHz\n"
      "          ticks), and when present utc_time, status_word, status_byte, euler_deg [roll, pitch, yaw],\n"
      "          quat [w, x, y, z], rotation_matrix, acc, free_acc, delta_v, gyr (rad/s), delta_q, mag,\n"
      "          temperature_c, baro_pa, lat_deg, lon_deg, alt_ellipsoid_m, vel_mps, gnss_pvt, ... Other messages:\n"
      "          type (message name), mid, payload_hex.\n"
      "  velodyne\n"
      "          pcap/pcapng of an HDL-32E or VLP-16 (data on UDP 2368, position on 8308; --data-port,\n"
      "          --position-port). \"velodyne_data\": time (pcap, s) port timestamp_us (past the hour) return_mode\n"
      "          product_byte first_azimuth_deg last_azimuth_deg points (returns decoded with the detected model).\n"
      "          \"velodyne_position\": time port timestamp_us pps nmea nmea_error lat_deg lon_deg. The summary\n"
      "          says the model and why, and the rotations.\n"
      "  robosense\n"
      "          pcap/pcapng of an RS-LiDAR-32 (MSOP on 6699, DIFOP on 7788; --data-port, --position-port).\n"
      "          \"robosense_msop\": time port timestamp_utc temperature_c first_azimuth_deg last_azimuth_deg\n"
      "          dual_layout points; MSOP packets before a DIFOP with the angle table are rejected\n"
      "          (msop_no_calibration). \"robosense_difop\": time port rpm firmware_top firmware_bottom serial\n"
      "          return_mode return_mode_byte distance_unit fov_start_deg fov_end_deg timestamp_utc angle_table.\n"
      "  scip    a fieldguard byte log (FGBYTELOG1) of a SCIP 2.0 session, or the sensor's replies as raw text.\n"
      "          \"scip_scan\": time (host, s; null for raw text) command timestamp_ms first_step last_step cluster\n"
      "          remaining_scans values valid min_range_mm max_range_mm (over the valid ranges: DMIN..DMAX of PP,\n"
      "          null when none) intensities. \"scip_info\" (VV, PP, II): time command and the reply's LABEL keys.\n"
      "          \"scip_status\" (a status other than 00/99): time command echo status category text.\n"
      "  candump\n"
      "          candump -L / -l log lines \"(1621880457.123456) can0 18FEF100#00FF0000FFFFFFFF\" (or candump's\n"
      "          default \"can0  18FEF100   [8]  00 FF ...\" output). \"can\": time iface id extended dlc data, for\n"
      "          29-bit ids the J1939 fields priority pgn sa (and da below PF 240), rtr / fd fd_flags / len8_dlc /\n"
      "          dir when they apply. \"can_error\": an error frame (time iface id error_class dlc data).\n"
      "          After its frame, J1939 network management and diagnostics: \"j1939_address_claim\" (Address\n"
      "          Claimed, or Cannot Claim from 254): time iface sa cannot_claim name (hex) and the NAME's fields\n"
      "          identity_number manufacturer_code ecu_instance function_instance function vehicle_system\n"
      "          vehicle_system_instance industry_group arbitrary_address_capable. \"j1939_dm1\" / \"j1939_dm2\": "
      "time\n"
      "          iface sa lamps (malfunction red_stop amber_warning protect) dtcs (spn fmi occurrences) transport\n"
      "          (true: reassembled from BAM). \"j1939_bam\": any other message BAM completed: pgn size data.\n"
      "\n"
      "Exit code 0 when the file was read (even with rejections), 2 when it is unusable (missing, empty, a format\n"
      "that cannot be told, a pcap or byte log whose header is broken).\n");
  cmd->add_option("FILE", *files, "the capture");
  cmd->add_option("--format", opt->format, "the capture's format (below); guessed when left out")
      ->type_name(inspect_format_names());
  cmd->add_option("--data-port", *data_port, "velodyne data (default 2368), robosense MSOP (6699) UDP port")
      ->type_name("P");
  cmd->add_option("--position-port", *position_port,
                  "velodyne position (default 8308), robosense DIFOP (7788) UDP port")
      ->type_name("P");
  return {cmd,
          "fieldguard inspect FILE [--format " + inspect_format_names() +
              "]\n"
              "                               [--data-port P] [--position-port P]",
          [cmd, files, opt, data_port, position_port] {
            if (const auto why = leftover(*cmd); !why.empty()) return usage_error(*cmd, why);
            if (files->size() != 1) {
              return usage_error(*cmd, files->empty() ? "no capture file given" : "more than one file: " + (*files)[1]);
            }
            opt->path = files->front();
            const std::tuple<const char*, const std::optional<std::string>&, std::optional<std::uint16_t>&> ports[] = {
                {"data-port", *data_port, opt->data_port}, {"position-port", *position_port, opt->position_port}};
            for (const auto& [name, text, out] : ports) {
              if (!text) continue;
              const auto port = whole_number(*text, 1, 65535);
              if (!port) {
                return usage_error(*cmd,
                                   std::string("--") + name + " wants a UDP port number 1..65535, not '" + *text + "'");
              }
              out = static_cast<std::uint16_t>(*port);
            }
            return inspect_capture(*opt);
          }};
}

Command add_record(CLI::App& top) {
  auto opt = std::make_shared<RecordOptions>();
  CLI::App* cmd = subcommand(
      top, "record", "save what the live sensors send, for replay",
      "Saves what the enabled live sources receive until SIGINT/SIGTERM or --duration:\n"
      "  DIR/lidar.pcap    3D LiDAR UDP datagrams (data and position ports), nanosecond pcap, kernel receive times\n"
      "  DIR/scan2d.log    the 2D LiDAR's SCIP 2.0 TCP conversation, both directions   (byte log)\n"
      "  DIR/gnss.log      the GNSS receiver's serial bytes                             (byte log)\n"
      "  DIR/ahrs.log      the AHRS's serial bytes                                      (byte log)\n"
      "A byte log is \"FGBYTELOG1\\n\", a line naming the source, then records of: u64 receive time (ns since the\n"
      "epoch), u32 length, u8 direction (0 from the sensor, 1 to it), the bytes; integers little-endian.\n"
      "`fieldguard replay --session DIR` plays a recording back through the same decoders.\n");
  cmd->add_option("--config", opt->config, kConfigHelp)->type_name("FILE");
  cmd->add_option("--out", opt->out, "the session directory (created when missing)")->type_name("DIR");
  cmd->add_option("--duration", opt->duration, "stop after this many seconds (default: at a signal)")
      ->type_name("SECONDS")
      ->check(CLI::Validator(
          [](const std::string& text) {
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            return end != text.c_str() && *end == '\0' && v > 0.0 && v < 1e9
                       ? std::string()
                       : "takes a number of seconds above 0, not '" + text + "'";
          },
          "> 0"));
  cmd->add_option("--samples-out", opt->samples_out,
                  "also decode live and write every sample as a JSON line (what replay --samples-out\n"
                  "writes from the recording)")
      ->type_name("FILE");
  return {cmd, "fieldguard record --config FILE --out DIR [--duration SECONDS] [--samples-out FILE]", [cmd, opt] {
            if (const auto why = leftover(*cmd); !why.empty()) return usage_error(*cmd, why);
            if (opt->config.empty() || opt->out.empty()) return usage_error(*cmd, "--config and --out are required");
            return record(*opt);
          }};
}

Command add_run(CLI::App& top) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* cmd = subcommand(
      top, "run", "the daemon: live sensors -> detection -> stop decision -> CAN",
      "The daemon: receives the enabled live sensors (3D LiDAR over UDP on lidar.data_port; the 2D LiDAR, GNSS\n"
      "and AHRS when enabled), makes frames of them (each 3D LiDAR rotation alone; fused by `sync:` and compensated\n"
      "by `geo:` when another sensor is enabled), runs obstacle detection on pipeline.workers threads, decides\n"
      "stop / go with the safety monitor (`safety:`) on every frame and between frames (a silent or implausible\n"
      "sensor or a stalled pipeline stops the tractor within its timeout), and\n"
      "sends the CAN messages of config/fieldguard.dbc to the `can:` sink (socketcan | candump | none),\n"
      "heartbeat and stop request every can.heartbeat_period_s whatever the pipeline does. With can.speed set,\n"
      "the tractor's speed is read off can.interface and sizes the stop zone while it is fresh.\n"
      "\n"
      "Signals: SIGTERM / SIGINT end it within a second, after a last STOP (shutting down); SIGHUP reloads the\n"
      "configuration file (a configuration with errors is refused, the errors are logged and the running one\n"
      "stays; a good one restarts the sources and the pipeline, starting again from STOP, starting up).\n"
      "Under systemd (Type=notify): READY=1 once every required sensor has been heard, WATCHDOG=1 fed by the\n"
      "decisions (none while rotations wait in the pipeline longer than safety.max_frame_interval_s), STATUS=\n"
      "a one-line health summary.\n"
      "With `view:` (off by default) it records MCAP files and serves a status page and the Foxglove\n"
      "WebSocket protocol on view.server.port; neither can delay a decision (docs/view.md).\n"
      "Exit code 0 after a signal, 2 for an unusable configuration or a sensor port that cannot be opened.\n");
  cmd->add_option("--config", opt->config, kConfigHelp)->type_name("FILE");
  cmd->add_option("--can-log", opt->can_log,
                  "write the CAN frames to this candump -L log instead of the configured sink")
      ->type_name("FILE");
  cmd->add_option("--mcap-out", opt->mcap_out,
                  "record the frames for Foxglove as view.mcap.path does, to this path instead: FILE's stem\n"
                  "_0001, _0002, ... (view.mcap.max_mb each, the newest view.mcap.max_files kept)")
      ->type_name("FILE");
  cmd->add_flag("--quiet", opt->quiet, "no summary on exit");
  return {cmd, "fieldguard run --config FILE [--can-log FILE] [--mcap-out FILE] [--quiet]", [cmd, opt] {
            if (const auto why = leftover(*cmd); !why.empty()) return usage_error(*cmd, why);
            if (opt->config.empty()) return usage_error(*cmd, "--config is required");
            return run_daemon(*opt);
          }};
}

}  // namespace fieldguard::app
