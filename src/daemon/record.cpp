// `fieldguard record`: save what the live sources receive, for replay. UDP (3D LiDAR data and position
// packets) goes to a pcap; the 2D LiDAR's TCP conversation and the serial links go to byte logs.

#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include "daemon/source_options.hpp"
#include "fieldguard/config/config.hpp"
#include "fieldguard/core/exit_code.hpp"
#include "fieldguard/daemon/daemon.hpp"
#include "fieldguard/engine/logging.hpp"
#include "fieldguard/engine/samples.hpp"
#include "fieldguard/io/byte_log.hpp"
#include "fieldguard/io/pcap_writer.hpp"
#include "fieldguard/io/scip_source.hpp"
#include "fieldguard/io/serial_reader.hpp"
#include "fieldguard/io/udp_receiver.hpp"

namespace fieldguard::app {
namespace {

namespace fs = std::filesystem;

}  // namespace

int record(const RecordOptions& opt) {
  const auto loaded = load_config_file(opt.config);
  if (!loaded.ok()) {
    for (const auto& issue : loaded.issues) std::fprintf(stderr, "%s\n", issue.to_string().c_str());
    return kExitBadInput;
  }
  const Config& cfg = loaded.config;
  const fs::path dir = opt.out;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    std::fprintf(stderr, "fieldguard record: cannot create %s\n", dir.c_str());
    return kExitBadInput;
  }
  double duration_s = 0.0;
  if (opt.duration) duration_s = *opt.duration;

  std::ofstream samples_file;
  if (const auto& s = opt.samples_out) samples_file.open(*s, std::ios::trunc);
  SampleDecoder samples(cfg, samples_file.is_open() ? &samples_file : nullptr);
  const auto log = logger("record");

  auto pcap = io::PcapWriter::create((dir / "lidar.pcap").string());
  if (!pcap) {
    std::fprintf(stderr, "fieldguard record: %s\n", pcap.error().c_str());
    return kExitBadInput;
  }
  boost::asio::io_context io;
  std::uint64_t write_failures = 0;
  auto on_udp = [&](const io::UdpDatagram& d) {
    if (!pcap->write(d)) ++write_failures;
    samples.lidar(d);
  };
  std::vector<std::unique_ptr<io::UdpReceiver>> udp;
  try {
    // The configured model's ports; both families' while it is to be found out (auto).
    std::vector<std::uint16_t> ports;
    if (lidar3d::listens_for(cfg.lidar.model, lidar3d::Family::Velodyne)) {
      ports.insert(ports.end(), {cfg.lidar.data_port, cfg.lidar.position_port});
    }
    if (lidar3d::listens_for(cfg.lidar.model, lidar3d::Family::RoboSense)) {
      ports.insert(ports.end(), {cfg.lidar.msop_port, cfg.lidar.difop_port});
    }
    for (std::uint16_t port : ports) {
      io::UdpReceiverOptions o;
      o.port = port;
      udp.push_back(std::make_unique<io::UdpReceiver>(io, o, on_udp));
      udp.back()->start();
    }
  } catch (const std::system_error& e) {
    std::fprintf(stderr, "fieldguard record: %s\n", e.what());
    return kExitBadInput;
  }

  auto open_log = [&](const char* name, const std::string& source) -> std::optional<io::ByteLogWriter> {
    auto w = io::ByteLogWriter::create((dir / name).string(), source);
    if (!w) {
      log->error("{}", w.error());
      return std::nullopt;
    }
    return std::move(w).value();
  };

  std::optional<io::ByteLogWriter> scan_log;
  std::unique_ptr<io::ScipSource> scip;
  if (cfg.scan2d.enabled) {
    scan_log = open_log("scan2d.log", "scan2d scip " + cfg.scan2d.host + ":" + std::to_string(cfg.scan2d.port));
    const io::ScipSourceOptions o = scip_source_options(cfg.scan2d);
    scip = std::make_unique<io::ScipSource>(io, o, nullptr, [&](bool trouble, const std::string& w) {
      log->log(trouble ? spdlog::level::warn : spdlog::level::info, "scan2d: {}", w);
    });
    scip->set_tap([&](ByteSpan b, bool to_sensor, Stamp t) {
      if (scan_log && !scan_log->write(t, to_sensor ? io::Direction::ToSensor : io::Direction::FromSensor, b))
        ++write_failures;
      samples.scan2d(b, to_sensor);
    });
    scip->start();
  }

  std::optional<io::ByteLogWriter> gnss_log;
  std::optional<io::ByteLogWriter> ahrs_log;
  std::vector<std::unique_ptr<io::SerialReader>> serial;
  if (cfg.gnss.serial.enabled) {
    gnss_log = open_log("gnss.log", "gnss " + cfg.gnss.serial.device + " " + std::to_string(cfg.gnss.serial.baud));
    serial.push_back(std::make_unique<io::SerialReader>(
        io, serial_options(cfg.gnss.serial),
        [&](ByteSpan b, Stamp t) {
          if (gnss_log && !gnss_log->write(t, io::Direction::FromSensor, b)) ++write_failures;
          samples.gnss(b);
        },
        [&](io::SerialState st, const std::string& why) {
          log->log(st == io::SerialState::Open ? spdlog::level::info : spdlog::level::warn, "gnss: {}", why);
        }));
  }
  if (cfg.ahrs.serial.enabled) {
    ahrs_log = open_log("ahrs.log", "ahrs " + cfg.ahrs.serial.device + " " + std::to_string(cfg.ahrs.serial.baud));
    serial.push_back(std::make_unique<io::SerialReader>(
        io, serial_options(cfg.ahrs.serial),
        [&](ByteSpan b, Stamp t) {
          if (ahrs_log && !ahrs_log->write(t, io::Direction::FromSensor, b)) ++write_failures;
          samples.ahrs(b);
        },
        [&](io::SerialState st, const std::string& why) {
          log->log(st == io::SerialState::Open ? spdlog::level::info : spdlog::level::warn, "ahrs: {}", why);
        }));
  }
  for (auto& s : serial) s->start();

  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](const boost::system::error_code&, int) { io.stop(); });
  boost::asio::steady_timer timer(io);
  if (duration_s > 0.0) {
    timer.expires_after(
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(duration_s)));
    timer.async_wait([&](const boost::system::error_code& e) {
      if (!e) io.stop();
    });
  }
  log->info("recording into {}", dir.string());
  io.run();

  for (auto& u : udp) u->stop();
  if (scip) scip->stop();
  for (auto& s : serial) s->stop();
  samples.finish();
  pcap->flush();
  if (scan_log) scan_log->flush();
  if (gnss_log) gnss_log->flush();
  if (ahrs_log) ahrs_log->flush();
  const auto& c = samples.counts();
  std::printf(
      "record summary: %s\n  lidar frames      %llu\n  scans             %llu\n  gnss sentences    %llu\n"
      "  ahrs messages     %llu\n  write failures    %llu\n",
      dir.c_str(), static_cast<unsigned long long>(c.lidar_frames), static_cast<unsigned long long>(c.scans),
      static_cast<unsigned long long>(c.gnss), static_cast<unsigned long long>(c.ahrs),
      static_cast<unsigned long long>(write_failures));
  return write_failures == 0 ? kExitOk : kExitFailure;
}

}  // namespace fieldguard::app
