// fieldguard-sim: writes a LiDAR capture (classic pcap: HDL-32E, VLP-16 or RS-LiDAR-32, strongest or dual return) of
// a simulated scene and its ground truth (JSONL).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cli/cli.hpp"
#include "sim/pcap_writer.hpp"
#include "sim/scenes.hpp"
#include "sim/sensor.hpp"
#include "sim/session.hpp"
#include "sim/simulator.hpp"
#include "sim/truth_writer.hpp"

namespace {

using namespace fieldguard::sim;
namespace cli = fieldguard::tools::cli;

constexpr std::int64_t kDefaultStartS = 1718449170;  // 2024-06-15 10:59:30 UTC: the hour turns after 30 s

constexpr const char* kSynopsis =
    "fieldguard-sim --scene NAME (--pcap FILE | --session DIR) [--truth FILE] [--rotations N]\n"
    "                      [--sensor hdl32e|vlp16|rs32] [--return strongest|dual] [--rate HZ]\n"
    "                      [--seed N] [--start-time UNIX_S] [--threads N] [--quiet]\n"
    "                      [--antenna X,Y,Z] [--origin LAT,LON,H] [--heading DEG]\n"
    "       fieldguard-sim --list-scenes | --help";

constexpr const char* kAbout =
    "Simulates a LiDAR 0.95 m above a field at the front of a tractor (a Velodyne HDL-32E by default) and\n"
    "writes its packets as a classic pcap (Ethernet/IPv4/UDP, each packet recorded at its last firing)\n"
    "plus one ground-truth JSON line per rotation.";

// What follows the options: the rotation rule, the scene catalogue (word-wrapped at 100 columns, indented
// by 6), the truth's layout and the exit codes.
std::string footer() {
  std::string out =
      "Every rotation starts exactly at azimuth 0 (the cut angle) with block 0 of a packet, so each one is a\n"
      "full turn. A reader's rotation assembler may still flag the first and the last rotation of the file\n"
      "as partial (it cannot know the first one began at the cut, and the stream ends after the last).\n\n"
      "Sensors (--sensor):\n"
      "  hdl32e  Velodyne HDL-32E: data packets to port 2368, factory bytes 0x37 (strongest) or 0x39 (dual)\n"
      "          and 0x21, 2 mm units; the timestamp marks the packet's last firing\n"
      "  vlp16   Velodyne VLP-16: as the HDL-32E, product byte 0x22, 16 lasers fired twice per block\n"
      "  rs32    RoboSense RS-LiDAR-32: MSOP to port 6699 (0.5 cm units, header time = the packet's first\n"
      "          firing) and a DIFOP to port 7788 every second, the first before any MSOP (rpm, return mode,\n"
      "          angles: the example unit of protocols.md 2.4, horizontal corrections +0.3/-0.3 deg\n"
      "          alternating, so a few firings at the start and end of a rotation lie across the cut);\n"
      "          returns from 0.4 m\n"
      "Dual return (--return dual): each firing fills a pair of blocks, so a packet covers half the azimuth.\n"
      "A ray that stops in foliage or a crop canopy goes on, and what it meets 0.5 m or more behind is a\n"
      "second echo; one echo fills both blocks. Velodyne pairs: the last echo, then the strongest (or the\n"
      "second strongest); RS-LiDAR-32 pairs: the strongest, then the other.\n\n"
      "Scenes (default rotations in brackets):\n";
  for (const SceneInfo& s : scene_catalog()) {
    out += "  " + std::string(s.name) + " [" + std::to_string(s.default_rotations) + "]\n";
    std::string_view text = s.summary;
    while (!text.empty()) {
      std::size_t cut = text.size();
      if (cut > 94) {
        cut = text.rfind(' ', 94);
        if (cut == std::string_view::npos) cut = 94;
      }
      out += "      " + std::string(text.substr(0, cut)) + "\n";
      text.remove_prefix(std::min(text.size(), cut + 1));
    }
  }
  out +=
      "\nGround truth: see tools/sim/truth_writer.hpp; boxes are in the sensor frame (x forward, y left, z up).\n"
      "Exit codes: 0 written; 1 writing failed; 2 bad command line.";
  return out;
}

struct Options {
  std::string scene;
  std::string pcap;
  std::string truth;
  std::optional<int> rotations;
  SensorModel sensor = SensorModel::Hdl32e;
  ReturnMode returns = ReturnMode::Strongest;
  std::string rate = "10";  // checked once the sensor is known
  std::uint64_t seed = 1;
  std::int64_t start_s = kDefaultStartS;
  unsigned threads = 1;
  bool quiet = false;
  bool list_scenes = false;
  std::string session;
  Vec3 antenna{0.0, 0.0, 2.8};
  Geodetic origin{48.1, 11.6, 520.0};
  double heading_deg = 60.0;
};

// "a,b,c": exactly three finite numbers.
bool parse_triple(std::string_view s, double& a, double& b, double& c) {
  const std::size_t p1 = s.find(',');
  const std::size_t p2 = p1 == std::string_view::npos ? p1 : s.find(',', p1 + 1);
  if (p2 == std::string_view::npos) return false;
  return cli::parse_number(s.substr(0, p1), a) && cli::parse_number(s.substr(p1 + 1, p2 - p1 - 1), b) &&
         cli::parse_number(s.substr(p2 + 1), c) && std::isfinite(a) && std::isfinite(b) && std::isfinite(c);
}

// The command line into `opt`; declares every option with its help.
void declare(CLI::App& app, Options& opt) {
  app.add_option("--scene", opt.scene, "one of the scenes below")->type_name("NAME");
  app.add_option("--pcap", opt.pcap, "capture to write")->type_name("FILE");
  app.add_option("--session", opt.session,
                 "also write the other sensors as `fieldguard record` does: DIR/lidar.pcap (unless\n"
                 "--pcap), DIR/gnss.log (NMEA GGA, RMC, HDT at 10 Hz, RTK noise), DIR/ahrs.log (Xsens\n"
                 "MTData2 at 100 Hz: counter, SampleTimeFine, Euler ENU), DIR/scan2d.log (SCIP 2.0\n"
                 "MD session of a UTM-30LX-EW on the front bumper, 40 Hz) and DIR/pose.truth.jsonl")
      ->type_name("DIR");
  cli::checked(
      app, "--antenna", opt.antenna, [](std::string_view s, Vec3& v) { return parse_triple(s, v.x, v.y, v.z); },
      [](const Vec3& v) { return std::abs(v.x) <= 20.0 && std::abs(v.y) <= 5.0 && v.z >= 0.0 && v.z <= 6.0; },
      "X,Y,Z in metres on the tractor (|x| <= 20, |y| <= 5, 0 <= z <= 6)",
      "GNSS antenna in the vehicle frame (origin on the ground below the rear axle;\n"
      "default 0,0,2.8: on the cab roof)")
      ->type_name("X,Y,Z");
  cli::checked(
      app, "--origin", opt.origin,
      [](std::string_view s, Geodetic& g) { return parse_triple(s, g.lat_deg, g.lon_deg, g.h_m); },
      [](const Geodetic& g) {
        return std::abs(g.lat_deg) <= 85.0 && std::abs(g.lon_deg) <= 180.0 && std::abs(g.h_m) <= 9000.0;
      },
      "LAT,LON,H (|lat| <= 85 deg, |lon| <= 180 deg, |h| <= 9000 m)",
      "the world origin (WGS84 deg, deg, m; default 48.1,11.6,520: north of Munich)")
      ->type_name("LAT,LON,H");
  cli::number(
      app, "--heading", opt.heading_deg, [](double d) { return d >= 0.0 && d < 360.0; },
      "degrees from 0 to under 360 (clockwise from north)", "compass heading of the tractor's path (default 60)")
      ->type_name("DEG");
  app.add_option("--truth", opt.truth, "ground truth to write (default: FILE without .pcap + .truth.jsonl)")
      ->type_name("FILE");
  cli::number(
      app, "--rotations", opt.rotations, [](int n) { return n >= 1; }, "a whole number >= 1",
      "rotations to simulate (default: the scene's)")
      ->type_name("N");
  cli::checked(
      app, "--sensor", opt.sensor,
      [](std::string_view s, SensorModel& m) {
        const auto model = sensor_model(s);
        if (model) m = *model;
        return model.has_value();
      },
      [](SensorModel /*m*/) { return true; }, "hdl32e, vlp16 or rs32", "the LiDAR (default hdl32e; see Sensors below)")
      ->type_name("NAME");
  cli::checked(
      app, "--return", opt.returns,
      [](std::string_view s, ReturnMode& m) {
        const auto mode = return_mode(s);
        if (mode) m = *mode;
        return mode.has_value();
      },
      [](ReturnMode /*m*/) { return true; }, "strongest or dual", "return mode (default strongest)")
      ->type_name("MODE");
  app.add_option("--rate", opt.rate,
                 "rotation rate (default 10): 5..20 on the Velodynes, 5, 10 or 20 on the\n"
                 "RS-LiDAR-32; rounded to a whole number of packets per rotation (HDL-32E,\n"
                 "strongest: 10 -> 181 packets, 9.991 Hz; the summary line gives the real rate)")
      ->type_name("HZ");
  cli::number(
      app, "--seed", opt.seed, [](std::uint64_t /*seed*/) { return true; }, "a whole number >= 0",
      "random seed (default 1); the same seed gives byte-identical output")
      ->type_name("N");
  cli::number(
      app, "--start-time", opt.start_s, [](std::int64_t t) { return t >= 0; }, "Unix seconds (a whole number >= 0)",
      "Unix time of the first firing (default 1718449170 = 10:59:30 UTC, so the\n"
      "packet timestamps wrap at the top of the hour after 30 s)")
      ->type_name("S");
  cli::number(app, "--threads", opt.threads, cli::Between<unsigned>{0, 64},
              "threads casting rays (default 1; 0 = one per hardware thread, at most 8);\n"
              "the output is byte-identical for any N. Each rotation waits for all of them,\n"
              "so on a busy machine more threads can be slower")
      ->type_name("N");
  app.add_flag("--quiet", opt.quiet, "no progress or summary on stderr");
  app.add_flag("--list-scenes", opt.list_scenes, "print the scenes' names, one a line, and exit");
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  cli::Tool tool("fieldguard-sim", kSynopsis, kAbout, footer(), "(fieldguard-sim --help lists the options and scenes)");
  declare(tool.app(), opt);
  if (const auto exit_code = tool.parse(argc, argv)) return *exit_code;
  if (opt.list_scenes) {
    for (const SceneInfo& s : scene_catalog()) std::cout << s.name << "\n";
    return 0;
  }
  if (opt.scene.empty()) return tool.fail("--scene is required (--list-scenes lists them)");
  const Sensor sensor = make_sensor(opt.sensor, opt.returns);
  double rate_hz = 0.0;
  if (!cli::parse_number(opt.rate, rate_hz) || !sensor.rate_supported(rate_hz)) {
    return tool.fail("--rate: wants " + sensor.rate_rule() + ", not '" + opt.rate + "'");
  }
  const SceneInfo* info = find_scene(opt.scene);
  if (info == nullptr) return tool.fail("unknown scene '" + opt.scene + "' (--list-scenes lists them)");
  if (opt.pcap.empty() && !opt.session.empty()) opt.pcap = opt.session + "/lidar.pcap";
  if (opt.pcap.empty()) return tool.fail("--pcap FILE or --session DIR is required");
  if (!opt.session.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(opt.session, ec);
    if (ec) {
      std::cerr << "fieldguard-sim: cannot create " << opt.session << ": " << ec.message() << "\n";
      return 1;
    }
  }
  if (opt.truth.empty()) {
    std::string base = opt.pcap;
    if (base.size() > 5 && base.ends_with(".pcap")) base.resize(base.size() - 5);
    opt.truth = base + ".truth.jsonl";
  }

  SimSettings settings;
  settings.rate_hz = rate_hz;
  settings.sensor = opt.sensor;
  settings.returns = opt.returns;
  settings.seed = opt.seed;
  settings.start_time_ns = opt.start_s * 1000000000LL;
  settings.threads = opt.threads;
  const int rotations = opt.rotations.value_or(info->default_rotations);
  SceneSetup setup;
  setup.seed = opt.seed;
  setup.rotations = rotations;
  setup.period_s = Simulator::period_for(rate_hz, opt.sensor, opt.returns);
  const auto start = std::chrono::steady_clock::now();
  Simulator sim(*build_scene(opt.scene, setup), settings);

  PcapWriter pcap;
  if (!pcap.open(opt.pcap)) {
    std::cerr << "fieldguard-sim: " << pcap.error() << "\n";
    return 1;
  }
  std::ofstream truth(opt.truth, std::ios::binary | std::ios::trunc);
  if (!truth) {
    std::cerr << "fieldguard-sim: cannot create " << opt.truth << "\n";
    return 1;
  }
  std::vector<TimedPacket> packets;
  std::uint64_t points = 0;
  std::uint64_t packet_count = 0;
  for (int k = 0; k < rotations; ++k) {
    packets.clear();
    const FrameTruth t = sim.rotation(static_cast<std::uint64_t>(k), packets);
    for (const TimedPacket& p : packets) {
      if (!pcap.write_udp(p.bytes, p.pcap_time_ns, p.port, p.port)) {
        std::cerr << "fieldguard-sim: " << pcap.error() << "\n";
        return 1;
      }
    }
    truth << truth_json_line(t) << '\n';
    points += t.returns;
    packet_count += packets.size();
    if (!opt.quiet && (k + 1) % 100 == 0)
      std::cerr << "fieldguard-sim: " << (k + 1) << "/" << rotations << " rotations\n";
  }
  truth.close();
  if (!truth || !pcap.close()) {
    std::cerr << "fieldguard-sim: writing failed: " << (pcap.error().empty() ? opt.truth : pcap.error()) << "\n";
    return 1;
  }
  SessionCounts session_counts;
  if (!opt.session.empty()) {
    SessionSettings ss;
    ss.dir = opt.session;
    ss.seed = opt.seed;
    ss.start_time_ns = settings.start_time_ns;
    ss.duration_s = rotations * sim.period_s();
    ss.origin = opt.origin;
    ss.field_heading_deg = opt.heading_deg;
    ss.antenna = opt.antenna;
    std::string error;
    if (!write_session(sim.scene(), ss, session_counts, error)) {
      std::cerr << "fieldguard-sim: " << error << "\n";
      return 1;
    }
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!opt.quiet) {
    std::fprintf(stderr,
                 "fieldguard-sim: scene %s, seed %llu, %s %s return: %d rotations at %.4f Hz (%d data packets "
                 "each), %llu packets, %.0f points per rotation, %.2f s (%.1f rotations/s)\n  %s\n  %s\n",
                 opt.scene.c_str(), static_cast<unsigned long long>(opt.seed), std::string(sensor.label).c_str(),
                 std::string(to_string(opt.returns)).c_str(), rotations, 1.0 / sim.period_s(),
                 sim.packets_per_rotation(), static_cast<unsigned long long>(packet_count),
                 static_cast<double>(points) / rotations, secs, rotations / secs, opt.pcap.c_str(), opt.truth.c_str());
    if (!opt.session.empty()) {
      std::fprintf(stderr, "  %s: %llu GNSS epochs, %llu AHRS samples, %llu 2D scans\n", opt.session.c_str(),
                   static_cast<unsigned long long>(session_counts.gnss_epochs),
                   static_cast<unsigned long long>(session_counts.ahrs_samples),
                   static_cast<unsigned long long>(session_counts.scans));
    }
  }
  return 0;
}
