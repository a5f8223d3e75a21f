// The subcommands' command lines: each parses its arguments into the options of its module and calls it.

#include <charconv>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "app/args.hpp"
#include "app/commands.hpp"
#include "fieldguard/core/exit_code.hpp"
#include "fieldguard/daemon/daemon.hpp"
#include "fieldguard/inspect/inspect.hpp"
#include "fieldguard/replay/replay.hpp"

namespace fieldguard::app {
namespace {

constexpr const char* kReplayHelp =
    "usage: fieldguard replay --config FILE (--pcap FILE | --session DIR) [--obstacles-out FILE] [--bev-dir DIR]\n"
    "                         [--pcd-dir DIR] [--samples-out FILE] [--can-log FILE] [--workers N] [--quiet]\n"
    "\n"
    "Runs a capture of Velodyne packets (classic pcap or pcapng; Ethernet, VLAN, Linux cooked SLL/SLL2 or raw\n"
    "IPv4) through the decoder and the same frame path as the daemon. The capture alone gives one frame per\n"
    "rotation, in the 3D LiDAR's sensor frame. With the byte logs of the 2D LiDAR, GNSS or AHRS (a --session, or\n"
    "the --*-log options) the capture and the logs are merged by receive time and fused as live: frames of whole\n"
    "rotations at sync.rate_hz with the 2D scan nearest in time, each point deskewed with the vehicle's pose\n"
    "(`geo:`) into the levelled detection frame (x the heading, y left, z up, origin at the 3D LiDAR's mounting),\n"
    "the 2D scan lifted into it; a frame that lacks a sensor goes out after sync.timeout_s, marked.\n"
    "\n"
"  --config FILE   configuration (see config/fieldguard.yaml)\n"
    "  --pcap FILE     the capture\n"
    "  --session DIR   a directory written by `fieldguard record`: DIR/lidar.pcap and the byte logs of the 2D\n"
    "                  LiDAR (scan2d.log), GNSS (gnss.log) and AHRS (ahrs.log), each decoded by the same decoders\n"
    "                  as live\n"
    "  --scan2d-log FILE, --gnss-log FILE, --ahrs-log FILE\n"
    "                  byte logs of a recording given one by one (with --pcap), instead of a --session\n"
    "  --samples-out FILE  write every decoded sample of every sensor as a JSON line (as `record --samples-out`)\n"
    "  --obstacles-out FILE  run the detection pipeline and write one JSON line per frame, in order:\n"
    "                  {\"frame\", \"stamp\" (s, capture time of the rotation's first packet), \"partial\",\n"
    "                  \"points_in\", \"obstacles\": [{\"min\", \"max\" (m, sensor frame), \"points\", \"obb\",\n"
    "                  \"distance\" (m), \"bearing\" (deg, + left), \"height\" (m above local ground), \"class\"}]};\n"
    "                  a fused frame adds \"fusion\" (levelling full | attitude_only | none, rotations, scan_points,\n"
    "                  missing sensors, timed_out, dropped_points, pose: plane easting/northing/up/zone and\n"
    "                  roll/pitch/yaw deg) and per obstacle \"plane\" [easting, northing, up] of its footprint\n"
    "  --bev-dir DIR   write a bird's-eye PNG per frame (points by height, ground dimmed, obstacle boxes\n"
    "                  with their distance, ROI and body box, 1 m grid)\n"
    "  --pcd-dir DIR   write one binary PCD per frame: frame_NNNNNN.pcd, and frame_NNNNNN_partial.pcd for\n"
    "                  the first and last rotations when they are not a full turn (fields x y z intensity ring\n"
    "                  time; sensor frame x forward, y left, z up, metres; time in s after the rotation start;\n"
    "                  a fused frame's points are in the detection frame and its ring field holds the 2D scan's\n"
    "                  step for the 2D LiDAR's points)\n"
    "  --can-log FILE  run the detection pipeline and the safety monitor (`safety:`) and write every CAN frame\n"
    "                  the daemon would have sent (`can:` addresses, DBC config/fieldguard.dbc) as a candump -L\n"
    "                  log stamped with capture time: heartbeats and the stop request every\n"
    "                  can.heartbeat_period_s from the first packet (STOP, starting up, until the first frame\n"
    "                  is decided), and per frame, when its last data is in, the obstacle summary, the\n"
    "                  obstacles and the stop request. A sensor counts as heard at the receive time of its\n"
    "                  newest data at or before the decision; one without a log counts as never heard\n"
    "  --workers N     run the detection pipeline on N worker threads (1..64; default: pipeline.workers of the\n"
    "                  configuration, 1 without it). Every output is written in frame order on the main\n"
    "                  thread and is byte-identical for any N; no frame is ever dropped (the reader waits\n"
    "                  for the workers when they fall behind)\n"
    "  --quiet         no progress line\n"
    "\n"
    "Ends with a summary: packets read, decoded, dropped by reason, rotations, points, wall time.\n"
    "Exit code 0 when the capture was used, 2 for unusable input (missing or unreadable file, not a pcap,\n"
    "no Velodyne data in it, invalid configuration), 1 when writing the output failed.\n";

constexpr const char* kRunHelp =
    "usage: fieldguard run --config FILE [--can-log FILE] [--quiet]\n"
    "\n"
    "The daemon: receives the enabled live sensors (3D LiDAR over UDP on lidar.data_port; the 2D LiDAR, GNSS\n"
    "and AHRS when enabled), makes frames of them (each 3D LiDAR rotation alone; fused by `sync:` and compensated\n"
    "by `geo:` when another sensor is enabled), runs obstacle detection on pipeline.workers threads, decides\n"
    "stop / go with the safety monitor (`safety:`) on every frame and between frames (a silent or implausible\n"
    "sensor or a stalled pipeline stops the tractor within its timeout), and\n"
    "sends the CAN messages of config/fieldguard.dbc to the `can:` sink (socketcan | candump | none),\n"
    "heartbeat and stop request every can.heartbeat_period_s whatever the pipeline does. With can.speed set,\n"
    "the tractor's speed is read off can.interface and sizes the stop zone while it is fresh.\n"
    "\n"
    "  --config FILE   configuration (see config/fieldguard.yaml)\n"
    "  --can-log FILE  write the CAN frames to this candump -L log instead of the configured sink\n"
    "  --quiet         no summary on exit\n"
    "\n"
    "Signals: SIGTERM / SIGINT end it within a second, after a last STOP (shutting down); SIGHUP reloads the\n"
    "configuration file (a configuration with errors is refused, the errors are logged and the running one\n"
    "stays; a good one restarts the sources and the pipeline, starting again from STOP, starting up).\n"
    "Under systemd (Type=notify): READY=1 once every required sensor has been heard, WATCHDOG=1 fed by the\n"
    "decisions (none while rotations wait in the pipeline longer than safety.max_frame_interval_s), STATUS=\n"
    "a one-line health summary.\n"
    "Exit code 0 after a signal, 2 for an unusable configuration or a sensor port that cannot be opened.\n";

constexpr const char* kRecordHelp =
    "usage: fieldguard record --config FILE --out DIR [--duration SECONDS] [--samples-out FILE]\n"
    "\n"
    "Saves what the enabled live sources receive until SIGINT/SIGTERM or --duration:\n"
    "  DIR/lidar.pcap    3D LiDAR UDP datagrams (data and position ports), nanosecond pcap, kernel receive times\n"
    "  DIR/scan2d.log    the 2D LiDAR's SCIP 2.0 TCP conversation, both directions   (byte log)\n"
    "  DIR/gnss.log      the GNSS receiver's serial bytes                             (byte log)\n"
    "  DIR/ahrs.log      the AHRS's serial bytes                                      (byte log)\n"
    "A byte log is \"FGBYTELOG1\\n\", a line naming the source, then records of: u64 receive time (ns since the\n"
    "epoch), u32 length, u8 direction (0 from the sensor, 1 to it), the bytes; integers little-endian.\n"
    "`fieldguard replay --session DIR` plays a recording back through the same decoders.\n"
    "\n"
    "  --samples-out FILE  also decode live and write every sample as a JSON line (what replay --samples-out\n"
    "                      writes from the recording)\n";

constexpr const char* kInspectHelp =
    "usage: fieldguard inspect FILE [--format nmea|xsens|velodyne|robosense|scip|candump]\n"
    "                               [--data-port P] [--position-port P]\n"
    "\n"
    "Decodes a capture and prints every decoded sample as one JSON line on stdout, then a summary on stderr:\n"
    "records by kind, rejected input by reason, and the bytes that were noise. Rejected input gives no record.\n"
    "The format is guessed from the first bytes when --format is left out (a pcap by the UDP ports or sizes of\n"
    "its first datagrams: robosense for 6699/7788, velodyne otherwise).\n"
    "\n"
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
    "\n"
    "Exit code 0 when the file was read (even with rejections), 2 when it is unusable (missing, empty, a format\n"
    "that cannot be told, a pcap or byte log whose header is broken).\n";

// --workers: 1..64 (sync::PoolParams' limits). Empty optional and a message when it is not.
std::optional<std::size_t> parse_workers(const std::string& text, std::string& error) {
  unsigned long long n = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
  if (ec != std::errc() || ptr != text.data() + text.size() || n < 1 || n > 64) {
    error = "--workers takes a whole number of worker threads from 1 to 64, got '" + text + "'";
    return std::nullopt;
  }
  return static_cast<std::size_t>(n);
}

// A UDP port option: 1..65535. nullopt (with `error` set) for anything else.
std::optional<std::uint16_t> port_option(const Args& args, const std::string& name, std::string& error) {
  const auto v = args.get(name);
  if (!v) return std::nullopt;
  unsigned port = 0;
  const auto r = std::from_chars(v->data(), v->data() + v->size(), port);
  if (r.ec != std::errc{} || r.ptr != v->data() + v->size() || port == 0 || port > 65535) {
    error = "--" + name + " wants a UDP port number 1..65535, not '" + *v + "'";
    return std::nullopt;
  }
  return static_cast<std::uint16_t>(port);
}

}  // namespace

int cmd_replay(const std::vector<std::string>& argv) {
  const Args args(argv, {"config", "pcap", "session", "scan2d-log", "gnss-log", "ahrs-log", "pcd-dir", "bev-dir",
                         "obstacles-out", "samples-out", "workers", "can-log"},
                  {"help", "quiet"});
  if (args.has("help")) {
    std::fputs(kReplayHelp, stdout);
    return kExitOk;
  }
  if (!args.ok() || !args.positional().empty() || !args.has("config") || (args.has("pcap") == args.has("session"))) {
    std::fprintf(stderr, "fieldguard replay: %s\n%s",
                 !args.ok() ? args.error().c_str()
                 : !args.positional().empty() ? ("unexpected argument '" + args.positional().front() + "'").c_str()
                                               : "--config and one of --pcap or --session are required",
                 kReplayHelp);
    return kExitBadInput;
  }
  ReplayOptions opt;
  opt.config = *args.get("config");
  if (auto w = args.get("workers")) {
    std::string err;
    opt.workers = parse_workers(*w, err);
    if (!opt.workers) {
      std::fprintf(stderr, "fieldguard replay: %s\n", err.c_str());
      return kExitBadInput;
    }
  }
  opt.pcap = args.get("pcap");
  opt.session = args.get("session");
  opt.scan2d_log = args.get("scan2d-log");
  opt.gnss_log = args.get("gnss-log");
  opt.ahrs_log = args.get("ahrs-log");
  opt.samples_out = args.get("samples-out");
  opt.obstacles_out = args.get("obstacles-out");
  opt.bev_dir = args.get("bev-dir");
  opt.pcd_dir = args.get("pcd-dir");
  opt.can_log = args.get("can-log");
  opt.quiet = args.has("quiet");
  return replay(opt);
}

int cmd_run(const std::vector<std::string>& argv) {
  const Args args(argv, {"config", "can-log"}, {"help", "quiet"});
  if (args.has("help")) {
    std::fputs(kRunHelp, stdout);
    return kExitOk;
  }
  if (!args.ok() || !args.positional().empty() || !args.has("config")) {
    std::fprintf(stderr, "fieldguard run: %s\n%s",
                 !args.ok()                    ? args.error().c_str()
                 : !args.positional().empty() ? ("unexpected argument '" + args.positional().front() + "'").c_str()
                                               : "--config is required",
                 kRunHelp);
    return kExitBadInput;
  }
  return run_daemon({*args.get("config"), args.get("can-log"), args.has("quiet")});
}

int cmd_record(const std::vector<std::string>& argv) {
  const Args args(argv, {"config", "out", "duration", "samples-out"}, {"help"});
  if (args.has("help")) {
    std::fputs(kRecordHelp, stdout);
    return kExitOk;
  }
  if (!args.ok() || !args.positional().empty() || !args.has("config") || !args.has("out")) {
    std::fprintf(stderr, "fieldguard record: %s\n%s", args.ok() ? "--config and --out are required" : args.error().c_str(),
                 kRecordHelp);
    return kExitBadInput;
  }
  return record({*args.get("config"), *args.get("out"), args.get("duration"), args.get("samples-out")});
}

int cmd_inspect(const std::vector<std::string>& argv) {
  const Args args(argv, {"format", "data-port", "position-port"}, {"help"});
  if (args.has("help")) {
    std::fputs(kInspectHelp, stdout);
    return kExitOk;
  }
  if (!args.ok() || args.positional().size() != 1) {
    const std::string why = !args.ok()                    ? args.error()
                            : args.positional().empty()  ? std::string("no capture file given")
                                                          : "more than one file: " + args.positional()[1];
    std::fprintf(stderr, "fieldguard inspect: %s\n\n%s", why.c_str(), kInspectHelp);
    return kExitBadInput;
  }
  InspectOptions opt;
  opt.path = args.positional().front();
  std::string port_error;
  opt.data_port = port_option(args, "data-port", port_error);
  if (port_error.empty()) opt.position_port = port_option(args, "position-port", port_error);
  if (!port_error.empty()) {
    std::fprintf(stderr, "fieldguard inspect: %s\n", port_error.c_str());
    return kExitBadInput;
  }
  opt.format = args.get("format");
  return inspect_capture(opt);
}

}  // namespace fieldguard::app
