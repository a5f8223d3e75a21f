#pragma once
// An MCAP file writer (https://mcap.dev/spec, major version 0), written from the specification: schemas and
// channels, messages batched into chunks compressed with zstd or lz4 (Debian's libzstd and liblz4) or stored,
// a message index after each chunk, and on close() the summary a reader seeks with: schemas, channels,
// statistics and chunk indexes, their summary offsets, the footer with its CRC. The data section's CRC is kept
// as it is written, so nothing is read back. Any MCAP reader (Foxglove, Lichtblick, the `mcap` CLI,
// @mcap/core) opens the file; a file cut short by a crash is still readable up to its last whole chunk by a
// reader that scans (no summary then).
// Thread-compatible: one thread writes one file.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace fieldguard::app {

enum class McapCompression : std::uint8_t { None = 0, Zstd = 1, Lz4 = 2 };
// "zstd", "lz4", "" (the names the specification's registry gives; "" is stored).
[[nodiscard]] const char* to_string(McapCompression c);
// "zstd", "lz4" or "none" (the command line's and the configuration's words); nothing for another word.
[[nodiscard]] std::optional<McapCompression> mcap_compression(std::string_view word);

struct McapOptions {
  McapCompression compression = McapCompression::Zstd;
  // Uncompressed bytes batched per chunk: a reader seeking to a time decompresses one chunk, and a crash
  // loses at most the chunk being built.
  std::size_t chunk_bytes = 4U << 20U;
  int zstd_level = 1;   // the fastest: a 10 Hz point cloud must not wait for its compression
  std::string profile;  // "" (no ROS profile: Foxglove's JSON messages)
  std::string library;  // the Header record's free-form writer name
};

struct McapStats {
  std::uint64_t messages = 0;
  std::uint64_t chunks = 0;
  std::uint64_t uncompressed_bytes = 0;  // of the chunks' records
  std::uint64_t file_bytes = 0;          // written so far
};

class McapWriter {
 public:
  McapWriter();
  ~McapWriter();  // closes the file if close() was not called (the summary is written then too)
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Creates (truncates) `path` and writes the magic and the Header. False with error() set when it cannot.
  // Once per writer.
  bool open(const std::string& path, McapOptions options);
  [[nodiscard]] bool is_open() const { return file_ != nullptr; }

  // Ids from 1, in the order added. Each record goes into the data section at once (so before any chunk that
  // holds a message of the channel) and again into the summary. 0 when the file is not open.
  std::uint16_t add_schema(std::string_view name, std::string_view encoding, std::string_view data);
  std::uint16_t add_channel(std::uint16_t schema_id, std::string_view topic, std::string_view message_encoding,
                            const std::map<std::string, std::string>& metadata = {});

  // One message; log times should not go backwards (readers sort each chunk's index, so they still work).
  // False with error() set when the file cannot be written; everything after is refused.
  bool write(std::uint16_t channel, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
             std::span<const std::byte> data);
  bool write(std::uint16_t channel, std::uint64_t log_time_ns, std::string_view data) {
    return write(channel, log_time_ns, log_time_ns, std::as_bytes(std::span(data.data(), data.size())));
  }

  // The last chunk, Data End, the summary, the footer and the closing magic. False with error() set when any
  // of it could not be written (the file is closed either way).
  bool close();

  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] const McapStats& stats() const { return stats_; }
  // The file's size were it closed now, at most: what is written, and the chunk being built uncompressed.
  [[nodiscard]] std::uint64_t size_bound() const { return stats_.file_bytes + chunk_.size(); }

 private:
  struct Schema {
    std::string name;
    std::string encoding;
    std::string data;
  };
  struct Channel {
    std::uint16_t schema_id = 0;
    std::string topic;
    std::string encoding;
    std::map<std::string, std::string> metadata;
    std::uint64_t messages = 0;
  };
  struct ChunkIndex {
    std::uint64_t start_time = 0;
    std::uint64_t end_time = 0;
    std::uint64_t offset = 0;
    std::uint64_t length = 0;
    std::vector<std::pair<std::uint16_t, std::uint64_t>> index_offsets;  // channel -> message index record
    std::uint64_t index_length = 0;
    std::uint64_t compressed_size = 0;
    std::uint64_t uncompressed_size = 0;
  };

  void emit(const std::string& bytes);  // to the file, counted in the data CRC while the data section lasts
  bool flush_chunk();
  void fail(std::string what);

  std::FILE* file_ = nullptr;
  McapOptions options_;
  std::string path_;
  std::string error_;
  McapStats stats_;
  std::uint32_t data_crc_ = 0;
  bool in_data_ = true;
  std::vector<Schema> schemas_;    // id = index + 1
  std::vector<Channel> channels_;  // id = index + 1
  // The chunk being built: its records, and per channel the (log time, offset) of each message in it.
  std::string chunk_;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::uint64_t chunk_start_ = 0;
  std::uint64_t chunk_end_ = 0;
  std::vector<ChunkIndex> chunk_indexes_;
  std::uint64_t first_time_ = 0;
  std::uint64_t last_time_ = 0;
  std::string compressed_;  // scratch
  struct Zstd;              // libzstd's compression context, kept from chunk to chunk
  std::unique_ptr<Zstd> zstd_;
};

}  // namespace fieldguard::app
