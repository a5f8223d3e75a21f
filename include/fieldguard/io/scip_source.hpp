#pragma once
// The Hokuyo UTM-30LX-EW as a live source: a TcpClient moves the bytes, scip::ReplyParser frames the
// replies, scip::Client runs the start-up sequence (SCIP2.0, VV, PP, II, BM, MD/ME) and decodes the scans.
// A refused command, a parser that keeps failing (garbage), a reset or silence drop the connection and it is
// made again after the backoff, from the top of the sequence. Thread contract: the io thread.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "fieldguard/drivers/scip_client.hpp"
#include "fieldguard/drivers/scip_data.hpp"
#include "fieldguard/io/tcp_client.hpp"

namespace fieldguard::io {

struct ScipSourceOptions {
  TcpClientOptions tcp;
  scip::ClientConfig client;
  // Framing errors tolerated on one connection before it is dropped and made again.
  std::uint32_t max_parser_errors = 8;
};

struct ScipSourceStats {
  std::atomic<std::uint64_t> scans{0};
  std::atomic<std::uint64_t> refusals{0};        // the sensor refused a command of the start-up sequence
  std::atomic<std::uint64_t> parser_errors{0};   // framing errors (bad check code, malformed line, ...)
  std::atomic<std::uint64_t> decode_errors{0};   // replies whose contents could not be decoded
  std::atomic<std::uint64_t> sensor_trouble{0};  // scan replies with status 21..97
};

class ScipSource {
 public:
  using ScanHandler = std::function<void(const scip::Scan&, const scip::Geometry&, Stamp rx_time)>;
  // Every change of the link or of the protocol, with a one-line reason. `trouble`: the link was lost or refused
  // (the source waits and connects again) or the sensor reported a fault; false for connecting and connected.
  using StateHandler = std::function<void(bool trouble, const std::string& what)>;

  ScipSource(boost::asio::io_context& io, ScipSourceOptions options, ScanHandler on_scan, StateHandler on_state = {});
  ~ScipSource();
  ScipSource(const ScipSource&) = delete;
  ScipSource& operator=(const ScipSource&) = delete;

  // Every byte of the conversation as it passes, for recording: to_sensor false = from the sensor.
  using TapHandler = std::function<void(ByteSpan bytes, bool to_sensor, Stamp time)>;
  void set_tap(TapHandler tap);

  void start();
  void stop();  // closes the connection: the sensor stops streaming when its client goes

  [[nodiscard]] const ScipSourceStats& stats() const;
  [[nodiscard]] const TcpClientStats& link() const;
  [[nodiscard]] scip::ClientState protocol_state() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldguard::io
