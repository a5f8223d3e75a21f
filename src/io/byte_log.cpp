#include "fieldguard/io/byte_log.hpp"

#include <cerrno>
#include <cstring>
#include <utility>

namespace fieldguard::io {
namespace {

constexpr std::size_t kMagicSize = sizeof(kByteLogMagic) - 1;
constexpr std::size_t kRecordHeader = 13;

void put_le(std::uint8_t* p, std::uint64_t v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

}  // namespace

Expected<ByteLogWriter, std::string> ByteLogWriter::create(const std::string& path, const std::string& source) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return Unexpected{"cannot create " + path + ": " + std::strerror(errno)};
  std::string line = source;
  for (char& c : line) {
    if (c == '\n') c = ' ';
  }
  line += '\n';
  if (std::fwrite(kByteLogMagic, 1, kMagicSize, f) != kMagicSize ||
      std::fwrite(line.data(), 1, line.size(), f) != line.size()) {
    std::fclose(f);
    return Unexpected{"cannot write " + path};
  }
  return ByteLogWriter(f);
}

ByteLogWriter::ByteLogWriter(ByteLogWriter&& o) noexcept : file_(std::exchange(o.file_, nullptr)) {}
ByteLogWriter& ByteLogWriter::operator=(ByteLogWriter&& o) noexcept {
  if (this != &o) {
    if (file_ != nullptr) std::fclose(file_);
    file_ = std::exchange(o.file_, nullptr);
  }
  return *this;
}
ByteLogWriter::~ByteLogWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

bool ByteLogWriter::write(Stamp host_time, Direction direction, ByteSpan bytes) {
  if (file_ == nullptr || bytes.size() > kByteLogMaxRecord) return false;
  std::uint8_t h[kRecordHeader];
  put_le(h, static_cast<std::uint64_t>(host_time.ns), 8);
  put_le(h + 8, bytes.size(), 4);
  h[12] = static_cast<std::uint8_t>(direction);
  return std::fwrite(h, 1, sizeof h, file_) == sizeof h &&
         std::fwrite(bytes.data(), 1, bytes.size(), file_) == bytes.size();
}

bool ByteLogWriter::flush() { return file_ != nullptr && std::fflush(file_) == 0; }

Expected<ByteLogReader, std::string> ByteLogReader::open(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return Unexpected{"cannot open " + path + ": " + std::strerror(errno)};
  ByteLogReader r(f);
  char magic[kMagicSize] = {};
  if (std::fread(magic, 1, kMagicSize, f) != kMagicSize || std::memcmp(magic, kByteLogMagic, kMagicSize) != 0) {
    return Unexpected{path + " is not a fieldguard byte log (no FGBYTELOG1 header)"};
  }
  for (int c = std::fgetc(f); c != '\n'; c = std::fgetc(f)) {
    if (c == EOF || r.source_.size() > 4096) return Unexpected{path + ": the header line is cut short or too long"};
    r.source_ += static_cast<char>(c);
  }
  return r;
}

ByteLogReader::ByteLogReader(ByteLogReader&& o) noexcept
    : file_(std::exchange(o.file_, nullptr)),
      source_(std::move(o.source_)),
      truncated_(o.truncated_),
      error_(std::move(o.error_)) {}
ByteLogReader& ByteLogReader::operator=(ByteLogReader&& o) noexcept {
  if (this != &o) {
    if (file_ != nullptr) std::fclose(file_);
    file_ = std::exchange(o.file_, nullptr);
    source_ = std::move(o.source_);
    truncated_ = o.truncated_;
    error_ = std::move(o.error_);
  }
  return *this;
}
ByteLogReader::~ByteLogReader() {
  if (file_ != nullptr) std::fclose(file_);
}

std::optional<ByteLogRecord> ByteLogReader::next() {
  if (file_ == nullptr || truncated_ || !error_.empty()) return std::nullopt;
  std::uint8_t h[kRecordHeader];
  const std::size_t got = std::fread(h, 1, sizeof h, file_);
  if (got == 0) return std::nullopt;
  if (got != sizeof h) {
    truncated_ = true;
    return std::nullopt;
  }
  const ByteSpan hs(h, sizeof h);
  const auto t = static_cast<std::int64_t>(static_cast<std::uint64_t>(load_le32(hs, 0)) |
                                           (static_cast<std::uint64_t>(load_le32(hs, 4)) << 32));
  const std::uint32_t n = load_le32(hs, 8);
  if (n > kByteLogMaxRecord || h[12] > 1) {
    error_ = "corrupt record (length " + std::to_string(n) + ", direction " + std::to_string(h[12]) + ")";
    return std::nullopt;
  }
  ByteLogRecord r;
  r.host_time = Stamp{t};
  r.direction = static_cast<Direction>(h[12]);
  r.bytes.resize(n);
  if (std::fread(r.bytes.data(), 1, n, file_) != n) {
    truncated_ = true;
    return std::nullopt;
  }
  return r;
}

}  // namespace fieldguard::io
