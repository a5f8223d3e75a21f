#pragma once
// `fieldguard inspect` of a fieldguard byte log (io/byte_log.hpp: what `fieldguard record` saves of the SCIP
// TCP link, the GNSS and the AHRS serial lines), read chunk by chunk: io::ByteLogReader reads whole files by
// path, inspect also reads pipes. The bytes from the sensor go to the format's decoder as they come, with
// their record's host time; bytes to the sensor are counted.

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/time.hpp"
#include "inspect/inspect_format.hpp"

namespace fieldguard::app::inspect {

// True when the capture starts with the byte log's magic line.
[[nodiscard]] bool starts_with_byte_log(ByteSpan head);
// The byte log's source line ("gnss /dev/ttyUSB0 115200"), lower case, as far as `head` holds it; "" when
// `head` is not a byte log.
[[nodiscard]] std::string byte_log_source(ByteSpan head);

class ByteLogFeed {
 public:
  using SensorBytes = std::function<void(ByteSpan bytes, Stamp host_time)>;
  explicit ByteLogFeed(SensorBytes sensor_bytes) : sensor_bytes_(std::move(sensor_bytes)) {}

  void push(ByteSpan chunk);
  // Counts, and what stopped reading (a broken header makes the capture unusable; a corrupt record or a
  // file cut inside one is a note).
  void finish(Summary& summary);

 private:
  enum class State : std::uint8_t { Magic, Source, RecordHeader, RecordBody, Stopped };
  static constexpr std::size_t kRecordHeaderSize = 13;  // u64 host_ns, u32 length, u8 direction

  void stop(std::string why, bool unusable);
  void start_record();
  void end_record();

  SensorBytes sensor_bytes_;
  State state_ = State::Magic;
  std::string header_;
  std::string source_;
  std::array<std::uint8_t, kRecordHeaderSize> record_header_{};
  std::size_t filled_ = 0;
  Stamp time_;
  std::uint32_t remaining_ = 0;
  bool from_sensor_ = true;
  std::uint64_t records_ = 0;
  std::uint64_t to_sensor_bytes_ = 0;
  std::string stopped_;
  bool unusable_ = false;
};

// What the serial and TCP formats read: the sensor's bytes of a capture that is either a byte log (each record
// from the sensor, with its host time) or the raw bytes themselves (no time).
class SensorBytes {
 public:
  using Sink = std::function<void(ByteSpan bytes, std::optional<Stamp> host_time)>;
  explicit SensorBytes(Sink sink);
  SensorBytes(const SensorBytes&) = delete;  // the feed calls back into this object
  SensorBytes& operator=(const SensorBytes&) = delete;

  // Reads the whole capture; a byte log is told by its first bytes.
  void read(Capture& in);
  [[nodiscard]] bool byte_log() const { return byte_log_; }
  // The byte log's counts and notes; nothing for raw bytes. Call after the format has filled in its own.
  void finish(Summary& summary);

 private:
  Sink sink_;
  ByteLogFeed feed_;
  bool byte_log_ = false;
};

}  // namespace fieldguard::app::inspect
