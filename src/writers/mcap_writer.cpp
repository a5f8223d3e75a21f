#include "fieldguard/writers/mcap_writer.hpp"

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <tuple>

namespace fieldguard::app {
namespace {

// Opcodes (the specification's "Records").
enum Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

constexpr char kMagic[] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};

// Little-endian fields, strings and maps as the specification's "Serialization" section gives them.
template <class T>
void put(std::string& s, T v) {
  for (std::size_t i = 0; i < sizeof(T); ++i)
    s.push_back(static_cast<char>((static_cast<std::uint64_t>(v) >> (8U * i)) & 0xFFU));
}
void put_string(std::string& s, std::string_view v) {
  put<std::uint32_t>(s, static_cast<std::uint32_t>(v.size()));
  s.append(v);
}

// <opcode><u64 length><content>
std::string record(Op op, const std::string& content) {
  std::string r;
  r.reserve(9 + content.size());
  r.push_back(static_cast<char>(op));
  put<std::uint64_t>(r, content.size());
  r += content;
  return r;
}

std::uint32_t crc(std::uint32_t running, std::string_view bytes) {
  return static_cast<std::uint32_t>(
      crc32_z(running, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<z_size_t>(bytes.size())));
}

}  // namespace

struct McapWriter::Zstd {
  ZSTD_CCtx* ctx = ZSTD_createCCtx();
  Zstd() = default;
  ~Zstd() { ZSTD_freeCCtx(ctx); }
  Zstd(const Zstd&) = delete;
  Zstd& operator=(const Zstd&) = delete;
};

const char* to_string(McapCompression c) {
  switch (c) {
    case McapCompression::None: return "";
    case McapCompression::Zstd: return "zstd";
    case McapCompression::Lz4: return "lz4";
  }
  return "";
}

std::optional<McapCompression> mcap_compression(std::string_view word) {
  if (word == "zstd") return McapCompression::Zstd;
  if (word == "lz4") return McapCompression::Lz4;
  if (word == "none") return McapCompression::None;
  return std::nullopt;
}

McapWriter::McapWriter() = default;

McapWriter::~McapWriter() {
  if (file_ != nullptr) static_cast<void>(close());
}

void McapWriter::fail(std::string what) {
  if (error_.empty()) error_ = std::move(what);
}

void McapWriter::emit(const std::string& bytes) {
  if (file_ == nullptr || !error_.empty()) return;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    fail("cannot write " + path_ + ": " + std::strerror(errno));
    return;
  }
  if (in_data_) data_crc_ = crc(data_crc_, bytes);
  stats_.file_bytes += bytes.size();
}

bool McapWriter::open(const std::string& path, McapOptions options) {
  if (file_ != nullptr || stats_.file_bytes != 0) {
    fail("MCAP: a writer writes one file");  // a rotating recorder opens a new writer per file
    return false;
  }
  options_ = std::move(options);
  path_ = path;
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) {
    error_ = "cannot write " + path + ": " + std::strerror(errno);
    return false;
  }
  if (options_.compression == McapCompression::Zstd) zstd_ = std::make_unique<Zstd>();
  std::string header;
  put_string(header, options_.profile);
  put_string(header, options_.library);
  emit(std::string(kMagic, sizeof kMagic) + record(kHeader, header));
  return error_.empty();
}

namespace {
std::string schema_content(std::uint16_t id, std::string_view name, std::string_view encoding, std::string_view data) {
  std::string c;
  put<std::uint16_t>(c, id);
  put_string(c, name);
  put_string(c, encoding);
  put_string(c, data);  // uint32 length-prefixed bytes: the same shape as a string
  return c;
}
}  // namespace

std::uint16_t McapWriter::add_schema(std::string_view name, std::string_view encoding, std::string_view data) {
  if (file_ == nullptr) return 0;
  schemas_.push_back({std::string(name), std::string(encoding), std::string(data)});
  const auto id = static_cast<std::uint16_t>(schemas_.size());
  emit(record(kSchema, schema_content(id, name, encoding, data)));
  return id;
}

namespace {
std::string channel_content(std::uint16_t id, std::uint16_t schema_id, std::string_view topic,
                            std::string_view encoding, const std::map<std::string, std::string>& metadata) {
  std::string c;
  put<std::uint16_t>(c, id);
  put<std::uint16_t>(c, schema_id);
  put_string(c, topic);
  put_string(c, encoding);
  std::string map;
  for (const auto& [k, v] : metadata) {
    put_string(map, k);
    put_string(map, v);
  }
  put<std::uint32_t>(c, static_cast<std::uint32_t>(map.size()));
  c += map;
  return c;
}
}  // namespace

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, std::string_view topic,
                                      std::string_view message_encoding,
                                      const std::map<std::string, std::string>& metadata) {
  if (file_ == nullptr) return 0;
  channels_.push_back({schema_id, std::string(topic), std::string(message_encoding), metadata, 0});
  const auto id = static_cast<std::uint16_t>(channels_.size());
  emit(record(kChannel, channel_content(id, schema_id, topic, message_encoding, metadata)));
  return id;
}

bool McapWriter::write(std::uint16_t channel, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
                       std::span<const std::byte> data) {
  if (file_ == nullptr || !error_.empty()) return false;
  if (channel == 0 || channel > channels_.size()) {
    fail("MCAP: message on channel " + std::to_string(channel) + ", which was never added");
    return false;
  }
  Channel& ch = channels_[channel - 1U];
  if (chunk_.empty()) {
    chunk_start_ = log_time_ns;
    chunk_end_ = log_time_ns;
  }
  chunk_start_ = std::min(chunk_start_, log_time_ns);
  chunk_end_ = std::max(chunk_end_, log_time_ns);
  if (stats_.messages == 0) first_time_ = last_time_ = log_time_ns;
  first_time_ = std::min(first_time_, log_time_ns);
  last_time_ = std::max(last_time_, log_time_ns);
  chunk_index_[channel].emplace_back(log_time_ns, chunk_.size());
  // Built in place: a point cloud's megabyte is copied once, into the chunk.
  chunk_.push_back(static_cast<char>(kMessage));
  put<std::uint64_t>(chunk_, 2 + 4 + 8 + 8 + data.size());
  put<std::uint16_t>(chunk_, channel);
  put<std::uint32_t>(chunk_, static_cast<std::uint32_t>(ch.messages));  // sequence: per channel, from 0
  put<std::uint64_t>(chunk_, log_time_ns);
  put<std::uint64_t>(chunk_, publish_time_ns);
  chunk_.append(reinterpret_cast<const char*>(data.data()), data.size());
  ++ch.messages;
  ++stats_.messages;
  if (chunk_.size() >= options_.chunk_bytes) return flush_chunk();
  return true;
}

bool McapWriter::flush_chunk() {
  if (chunk_.empty() || !error_.empty()) return error_.empty();
  const std::uint32_t records_crc = crc(0, chunk_);
  std::string_view body = chunk_;
  switch (options_.compression) {
    case McapCompression::None: break;
    case McapCompression::Zstd: {
      compressed_.resize(ZSTD_compressBound(chunk_.size()));
      const std::size_t n = ZSTD_compressCCtx(zstd_->ctx, compressed_.data(), compressed_.size(), chunk_.data(),
                                              chunk_.size(), options_.zstd_level);
      if (ZSTD_isError(n) != 0U) {
        fail(std::string("MCAP: zstd: ") + ZSTD_getErrorName(n));
        return false;
      }
      body = std::string_view(compressed_.data(), n);
      break;
    }
    case McapCompression::Lz4: {
      compressed_.resize(LZ4F_compressFrameBound(chunk_.size(), nullptr));
      const std::size_t n =
          LZ4F_compressFrame(compressed_.data(), compressed_.size(), chunk_.data(), chunk_.size(), nullptr);
      if (LZ4F_isError(n) != 0U) {
        fail(std::string("MCAP: lz4: ") + LZ4F_getErrorName(n));
        return false;
      }
      body = std::string_view(compressed_.data(), n);
      break;
    }
  }
  ChunkIndex ix;
  ix.start_time = chunk_start_;
  ix.end_time = chunk_end_;
  ix.offset = stats_.file_bytes;
  ix.compressed_size = body.size();
  ix.uncompressed_size = chunk_.size();
  std::string c;
  put<std::uint64_t>(c, chunk_start_);
  put<std::uint64_t>(c, chunk_end_);
  put<std::uint64_t>(c, chunk_.size());
  put<std::uint32_t>(c, records_crc);
  put_string(c, to_string(options_.compression));
  put<std::uint64_t>(c, body.size());
  c.append(body);
  const std::string chunk = record(kChunk, c);
  ix.length = chunk.size();
  emit(chunk);
  // One Message Index per channel with a message in the chunk, by channel id.
  const std::uint64_t index_start = stats_.file_bytes;
  for (const auto& [channel, entries] : chunk_index_) {
    std::string m;
    put<std::uint16_t>(m, channel);
    put<std::uint32_t>(m, static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [t, off] : entries) {
      put<std::uint64_t>(m, t);
      put<std::uint64_t>(m, off);
    }
    ix.index_offsets.emplace_back(channel, stats_.file_bytes);
    emit(record(kMessageIndex, m));
  }
  ix.index_length = stats_.file_bytes - index_start;
  chunk_indexes_.push_back(std::move(ix));
  stats_.uncompressed_bytes += chunk_.size();
  ++stats_.chunks;
  chunk_.clear();
  chunk_index_.clear();
  return error_.empty();
}

bool McapWriter::close() {
  if (file_ == nullptr) return error_.empty();
  flush_chunk();
  std::string data_end;
  put<std::uint32_t>(data_end, data_crc_);
  emit(record(kDataEnd, data_end));
  in_data_ = false;

  // The summary, grouped by opcode, each group's place kept for its Summary Offset record.
  const std::uint64_t summary_start = stats_.file_bytes;
  std::uint32_t summary_crc = 0;
  std::vector<std::tuple<Op, std::uint64_t, std::uint64_t>> groups;
  auto summary = [&](Op op, const std::vector<std::string>& contents) {
    if (contents.empty()) return;
    const std::uint64_t start = stats_.file_bytes;
    for (const auto& c : contents) {
      const std::string r = record(op, c);
      summary_crc = crc(summary_crc, r);
      emit(r);
    }
    groups.emplace_back(op, start, stats_.file_bytes - start);
  };
  std::vector<std::string> contents;
  for (std::size_t i = 0; i < schemas_.size(); ++i) {
    const Schema& sc = schemas_[i];
    contents.push_back(schema_content(static_cast<std::uint16_t>(i + 1), sc.name, sc.encoding, sc.data));
  }
  summary(kSchema, contents);
  contents.clear();
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    const Channel& ch = channels_[i];
    contents.push_back(
        channel_content(static_cast<std::uint16_t>(i + 1), ch.schema_id, ch.topic, ch.encoding, ch.metadata));
  }
  summary(kChannel, contents);
  contents.clear();
  {
    std::string c;
    put<std::uint64_t>(c, stats_.messages);
    put<std::uint16_t>(c, static_cast<std::uint16_t>(schemas_.size()));
    put<std::uint32_t>(c, static_cast<std::uint32_t>(channels_.size()));
    put<std::uint32_t>(c, 0);  // attachments
    put<std::uint32_t>(c, 0);  // metadata
    put<std::uint32_t>(c, static_cast<std::uint32_t>(chunk_indexes_.size()));
    put<std::uint64_t>(c, first_time_);
    put<std::uint64_t>(c, last_time_);
    std::string counts;
    for (std::size_t i = 0; i < channels_.size(); ++i) {
      put<std::uint16_t>(counts, static_cast<std::uint16_t>(i + 1));
      put<std::uint64_t>(counts, channels_[i].messages);
    }
    put<std::uint32_t>(c, static_cast<std::uint32_t>(counts.size()));
    c += counts;
    contents.push_back(std::move(c));
  }
  summary(kStatistics, contents);
  contents.clear();
  for (const ChunkIndex& ix : chunk_indexes_) {
    std::string c;
    put<std::uint64_t>(c, ix.start_time);
    put<std::uint64_t>(c, ix.end_time);
    put<std::uint64_t>(c, ix.offset);
    put<std::uint64_t>(c, ix.length);
    put<std::uint32_t>(c, static_cast<std::uint32_t>(ix.index_offsets.size() * 10));
    for (const auto& [channel, off] : ix.index_offsets) {
      put<std::uint16_t>(c, channel);
      put<std::uint64_t>(c, off);
    }
    put<std::uint64_t>(c, ix.index_length);
    put_string(c, to_string(options_.compression));
    put<std::uint64_t>(c, ix.compressed_size);
    put<std::uint64_t>(c, ix.uncompressed_size);
    contents.push_back(std::move(c));
  }
  summary(kChunkIndex, contents);

  const std::uint64_t summary_offset_start = stats_.file_bytes;
  for (const auto& [op, start, length] : groups) {
    std::string c;
    put<std::uint8_t>(c, op);
    put<std::uint64_t>(c, start);
    put<std::uint64_t>(c, length);
    const std::string r = record(kSummaryOffset, c);
    summary_crc = crc(summary_crc, r);
    emit(r);
  }
  // The footer's CRC covers the summary, the summary offsets and the footer up to its own field.
  std::string footer;
  footer.push_back(static_cast<char>(kFooter));
  put<std::uint64_t>(footer, 8 + 8 + 4);
  put<std::uint64_t>(footer, summary_start);
  put<std::uint64_t>(footer, summary_offset_start);
  summary_crc = crc(summary_crc, footer);
  put<std::uint32_t>(footer, summary_crc);
  emit(footer + std::string(kMagic, sizeof kMagic));

  if (std::fflush(file_) != 0) fail("cannot write " + path_ + ": " + std::strerror(errno));
  if (std::fclose(file_) != 0) fail("cannot write " + path_ + ": " + std::strerror(errno));
  file_ = nullptr;
  return error_.empty();
}

}  // namespace fieldguard::app
