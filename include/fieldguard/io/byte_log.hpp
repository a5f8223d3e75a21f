#pragma once
// The byte log: how `fieldguard record` saves what a TCP or serial sensor link carried, so that replay
// feeds the same bytes, in the same chunks, at the same receive times, to the same decoders.
//
// File layout (all integers little-endian):
//   header  "FGBYTELOG1\n" (11 bytes), then one line of text naming the source ("gnss /dev/ttyUSB0 115200\n")
//   records u64 host_ns | u32 length | u8 direction (0 = received from the sensor, 1 = sent to it) | bytes
// A file cut inside a record (power lost while recording) ends at the last whole record; the reader says so.

#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fieldguard/core/bytes.hpp"
#include "fieldguard/core/expected.hpp"
#include "fieldguard/core/time.hpp"

namespace fieldguard::io {

inline constexpr char kByteLogMagic[] = "FGBYTELOG1\n";
inline constexpr std::uint32_t kByteLogMaxRecord = 1U << 20;  // a longer record is corruption, not data

enum class Direction : std::uint8_t { FromSensor = 0, ToSensor = 1 };

struct ByteLogRecord {
  Stamp host_time;
  Direction direction = Direction::FromSensor;
  std::vector<std::uint8_t> bytes;
};

class ByteLogWriter {
 public:
  // Errors name the file and the reason.
  [[nodiscard]] static Expected<ByteLogWriter, std::string> create(const std::string& path, const std::string& source);
  ByteLogWriter(ByteLogWriter&&) noexcept;
  ByteLogWriter& operator=(ByteLogWriter&&) noexcept;
  ~ByteLogWriter();

  // Returns false when the write failed (disk full, ...); the caller counts it.
  bool write(Stamp host_time, Direction direction, ByteSpan bytes);
  bool flush();

 private:
  explicit ByteLogWriter(std::FILE* f) : file_(f) {}
  std::FILE* file_ = nullptr;
};

class ByteLogReader {
 public:
  [[nodiscard]] static Expected<ByteLogReader, std::string> open(const std::string& path);
  ByteLogReader(ByteLogReader&&) noexcept;
  ByteLogReader& operator=(ByteLogReader&&) noexcept;
  ~ByteLogReader();

  [[nodiscard]] const std::string& source() const { return source_; }
  // The next record, or nullopt at the end (or at a record cut short: truncated() tells).
  [[nodiscard]] std::optional<ByteLogRecord> next();
  [[nodiscard]] bool truncated() const { return truncated_; }
  [[nodiscard]] const std::string& error() const { return error_; }  // corruption that stopped reading

 private:
  explicit ByteLogReader(std::FILE* f) : file_(f) {}
  std::FILE* file_ = nullptr;
  std::string source_;
  bool truncated_ = false;
  std::string error_;
};

}  // namespace fieldguard::io
