// The MCAP writer against the specification, read back by a small reader written here from the specification
// (https://mcap.dev/spec): every record walked, every CRC and offset checked. The independent reader is
// @mcap/core (tests/interop/node/mcap_check.mjs, run by the mcap_interop tests).

#include "fieldguard/writers/mcap_writer.hpp"

#include <gtest/gtest.h>
#include <zlib.h>
#include <zstd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

namespace fieldguard::app {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::uint32_t crc_of(std::string_view s) {
  return static_cast<std::uint32_t>(crc32_z(0, reinterpret_cast<const Bytef*>(s.data()), s.size()));
}

// Little-endian reads at a cursor; each checks it stays inside the bytes.
struct Cursor {
  std::string_view b;
  std::size_t at = 0;
  template <class T>
  T get() {
    EXPECT_LE(at + sizeof(T), b.size());
    if (at + sizeof(T) > b.size()) return T{};
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i)
      v |= static_cast<std::uint64_t>(static_cast<unsigned char>(b[at + i])) << (8 * i);
    at += sizeof(T);
    return static_cast<T>(v);
  }
  std::string_view bytes(std::size_t n) {
    EXPECT_LE(at + n, b.size());
    n = std::min(n, b.size() - std::min(at, b.size()));
    const auto r = b.substr(at, n);
    at += n;
    return r;
  }
  std::string_view str() { return bytes(get<std::uint32_t>()); }
};

struct Record {
  std::uint8_t op = 0;
  std::size_t offset = 0;  // of the opcode, in the file (or in the chunk's records)
  std::string_view content;
};

std::vector<Record> records(std::string_view bytes, std::size_t from, std::size_t to) {
  std::vector<Record> out;
  Cursor c{bytes, from};
  while (c.at < to) {
    Record r;
    r.offset = c.at;
    r.op = c.get<std::uint8_t>();
    r.content = c.bytes(c.get<std::uint64_t>());
    out.push_back(r);
  }
  EXPECT_EQ(c.at, to);
  return out;
}

struct Written {
  std::uint16_t channel;
  std::uint64_t time;
  std::string data;
};

// Writes `n` messages round-robin on three channels of two schemas, with chunks of `chunk_bytes`.
std::vector<Written> write_sample(const fs::path& path, McapCompression compression, std::size_t chunk_bytes, int n) {
  McapWriter w;
  McapOptions o;
  o.compression = compression;
  o.chunk_bytes = chunk_bytes;
  o.library = "test";
  EXPECT_TRUE(w.open(path.string(), o)) << w.error();
  const auto s1 = w.add_schema("foxglove.PointCloud", "jsonschema", R"({"type":"object"})");
  const auto s2 = w.add_schema("fieldguard.Decision", "jsonschema", R"({"type":"object"})");
  const std::uint16_t ch[] = {w.add_channel(s1, "/a", "json"), w.add_channel(s1, "/b", "json", {{"k", "v"}}),
                              w.add_channel(s2, "/c", "json")};
  EXPECT_EQ(s1, 1);
  EXPECT_EQ(ch[2], 3);
  std::vector<Written> out;
  for (int i = 0; i < n; ++i) {
    Written m{ch[i % 3], std::uint64_t{1'000'000'000} + static_cast<std::uint64_t>(i) * std::uint64_t{100'000'000},
              R"({"i":)" + std::to_string(i) + ",\"pad\":\"" + std::string(static_cast<std::size_t>(i * 7 % 300), 'x') +
                  "\"}"};
    EXPECT_TRUE(w.write(m.channel, m.time, m.data)) << w.error();
    out.push_back(std::move(m));
  }
  EXPECT_TRUE(w.close()) << w.error();
  EXPECT_EQ(w.stats().messages, static_cast<std::uint64_t>(n));
  return out;
}

// Reads the file as the specification lays it out and checks it against what was written.
void check_file(const std::string& f, const std::vector<Written>& written, bool zstd) {
  constexpr std::string_view kMagic("\x89MCAP0\r\n", 8);
  ASSERT_GT(f.size(), 2 * kMagic.size() + 29);
  EXPECT_EQ(std::string_view(f).substr(0, 8), kMagic);
  EXPECT_EQ(std::string_view(f).substr(f.size() - 8), kMagic);
  // Footer: the last record, 20 bytes of content.
  const std::size_t footer_at = f.size() - 8 - 29;
  Cursor footer{f, footer_at};
  ASSERT_EQ(footer.get<std::uint8_t>(), 0x02);
  ASSERT_EQ(footer.get<std::uint64_t>(), 20U);
  const auto summary_start = footer.get<std::uint64_t>();
  const auto summary_offset_start = footer.get<std::uint64_t>();
  const auto summary_crc = footer.get<std::uint32_t>();
  EXPECT_EQ(summary_crc, crc_of(std::string_view(f).substr(summary_start, footer_at + 1 + 8 + 16 - summary_start)));

  // The data section: Header first, Data End last, its CRC over everything before it.
  const auto data = records(f, 8, summary_start);
  ASSERT_GE(data.size(), 3U);
  EXPECT_EQ(data.front().op, 0x01);
  ASSERT_EQ(data.back().op, 0x0F);
  EXPECT_EQ(Cursor{data.back().content}.get<std::uint32_t>(),
            crc_of(std::string_view(f).substr(0, data.back().offset)));

  std::vector<Written> read;
  std::map<std::size_t, std::size_t> chunk_lengths;  // chunk offset -> record length
  int schemas = 0;
  int channels = 0;
  for (std::size_t i = 0; i < data.size(); ++i) {
    const Record& r = data[i];
    if (r.op == 0x03) ++schemas;
    if (r.op == 0x04) ++channels;
    EXPECT_NE(r.op, 0x05) << "a message outside a chunk";
    if (r.op != 0x06) continue;
    chunk_lengths[r.offset] = r.content.size() + 9;
    Cursor c{r.content};
    const auto start = c.get<std::uint64_t>();
    const auto end = c.get<std::uint64_t>();
    const auto size = c.get<std::uint64_t>();
    const auto crc = c.get<std::uint32_t>();
    const auto compression = c.str();
    const auto body = c.bytes(c.get<std::uint64_t>());
    std::string plain(body);
    if (zstd) {
      EXPECT_EQ(compression, "zstd");
      plain.resize(size);
      EXPECT_EQ(ZSTD_decompress(plain.data(), plain.size(), body.data(), body.size()), size);
    } else {
      EXPECT_EQ(compression, "");
    }
    ASSERT_EQ(plain.size(), size);
    EXPECT_EQ(crc, crc_of(plain));
    // Its messages, then one Message Index per channel pointing at them.
    std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> index;
    for (const Record& m : records(plain, 0, plain.size())) {
      ASSERT_EQ(m.op, 0x05);
      Cursor mc{m.content};
      Written w;
      w.channel = mc.get<std::uint16_t>();
      mc.get<std::uint32_t>();
      w.time = mc.get<std::uint64_t>();
      EXPECT_EQ(mc.get<std::uint64_t>(), w.time);
      w.data = std::string(m.content.substr(mc.at));
      EXPECT_GE(w.time, start);
      EXPECT_LE(w.time, end);
      index[w.channel].emplace_back(w.time, m.offset);
      read.push_back(std::move(w));
    }
    std::size_t j = i + 1;
    for (const auto& [channel, entries] : index) {
      ASSERT_LT(j, data.size());
      ASSERT_EQ(data[j].op, 0x07);
      Cursor ic{data[j].content};
      EXPECT_EQ(ic.get<std::uint16_t>(), channel);
      EXPECT_EQ(ic.get<std::uint32_t>(), entries.size() * 16);
      for (const auto& [t, off] : entries) {
        EXPECT_EQ(ic.get<std::uint64_t>(), t);
        EXPECT_EQ(ic.get<std::uint64_t>(), off);
      }
      ++j;
    }
  }
  EXPECT_EQ(schemas, 2);
  EXPECT_EQ(channels, 3);
  ASSERT_EQ(read.size(), written.size());
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read[i].channel, written[i].channel);
    EXPECT_EQ(read[i].time, written[i].time);
    EXPECT_EQ(read[i].data, written[i].data);
  }

  // The summary: schemas, channels, statistics, chunk indexes, grouped; the summary offsets name each group.
  const auto summary = records(f, summary_start, summary_offset_start);
  std::map<std::uint8_t, std::pair<std::size_t, std::size_t>> groups;  // op -> [first offset, end)
  for (const Record& r : summary) {
    auto [it, fresh] = groups.try_emplace(r.op, r.offset, r.offset);
    EXPECT_TRUE(fresh || it->second.second == r.offset) << "summary records of op " << int{r.op} << " not grouped";
    it->second.second = r.offset + 9 + r.content.size();
    if (r.op == 0x0B) {
      Cursor c{r.content};
      EXPECT_EQ(c.get<std::uint64_t>(), written.size());
      EXPECT_EQ(c.get<std::uint16_t>(), 2);
      EXPECT_EQ(c.get<std::uint32_t>(), 3U);
      c.get<std::uint32_t>();
      c.get<std::uint32_t>();
      EXPECT_EQ(c.get<std::uint32_t>(), chunk_lengths.size());
      EXPECT_EQ(c.get<std::uint64_t>(), written.front().time);
      EXPECT_EQ(c.get<std::uint64_t>(), written.back().time);
      EXPECT_EQ(c.get<std::uint32_t>(), 3U * 10U);
      for (std::uint16_t ch = 1; ch <= 3; ++ch) {
        EXPECT_EQ(c.get<std::uint16_t>(), ch);
        std::uint64_t n = 0;
        for (const auto& w : written) n += w.channel == ch ? 1 : 0;
        EXPECT_EQ(c.get<std::uint64_t>(), n);
      }
    }
    if (r.op == 0x08) {
      Cursor c{r.content};
      c.get<std::uint64_t>();
      c.get<std::uint64_t>();
      const auto at = c.get<std::uint64_t>();
      ASSERT_TRUE(chunk_lengths.contains(at)) << "a chunk index pointing at no chunk";
      EXPECT_EQ(c.get<std::uint64_t>(), chunk_lengths[at]);
      const auto map_bytes = c.get<std::uint32_t>();
      for (std::uint32_t k = 0; k < map_bytes / 10; ++k) {
        c.get<std::uint16_t>();
        EXPECT_EQ(f[c.get<std::uint64_t>()], '\x07') << "a message index offset pointing elsewhere";
      }
    }
  }
  EXPECT_EQ(groups.size(), 4U);
  EXPECT_TRUE(groups.contains(0x03) && groups.contains(0x04) && groups.contains(0x0B) && groups.contains(0x08));
  const auto offsets = records(f, summary_offset_start, footer_at);
  EXPECT_EQ(offsets.size(), groups.size());
  for (const Record& r : offsets) {
    ASSERT_EQ(r.op, 0x0E);
    Cursor c{r.content};
    const auto op = c.get<std::uint8_t>();
    ASSERT_TRUE(groups.contains(op));
    EXPECT_EQ(c.get<std::uint64_t>(), groups[op].first);
    EXPECT_EQ(c.get<std::uint64_t>(), groups[op].second - groups[op].first);
  }
}

class McapWriterTest : public ::testing::Test {
 protected:
  fs::path dir_ = fs::temp_directory_path() /
                  ("fg_mcap_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  void SetUp() override { fs::create_directories(dir_); }
  void TearDown() override { fs::remove_all(dir_); }
};

TEST_F(McapWriterTest, StoredChunksReadBackWithEveryOffsetAndCrc) {
  const auto path = dir_ / "a.mcap";
  // Chunks of 1 KiB: several chunks, each with messages of all three channels.
  const auto written = write_sample(path, McapCompression::None, 1024, 60);
  check_file(slurp(path), written, false);
}

TEST_F(McapWriterTest, ZstdChunksReadBack) {
  const auto path = dir_ / "z.mcap";
  const auto written = write_sample(path, McapCompression::Zstd, 2048, 80);
  check_file(slurp(path), written, true);
}

TEST_F(McapWriterTest, OneChunkWhenEverythingFits) {
  const auto path = dir_ / "one.mcap";
  const auto written = write_sample(path, McapCompression::Zstd, 1U << 20U, 10);
  check_file(slurp(path), written, true);
}

TEST_F(McapWriterTest, NoMessagesIsStillAValidFile) {
  const auto path = dir_ / "empty.mcap";
  McapWriter w;
  ASSERT_TRUE(w.open(path.string(), {}));
  w.add_channel(w.add_schema("s", "jsonschema", "{}"), "/t", "json");
  ASSERT_TRUE(w.close());
  const std::string f = slurp(path);
  EXPECT_EQ(f.substr(f.size() - 8), std::string("\x89MCAP0\r\n", 8));
  EXPECT_EQ(w.stats().chunks, 0U);
}

TEST_F(McapWriterTest, UnwritablePathIsAnErrorNamingIt) {
  McapWriter w;
  EXPECT_FALSE(w.open((dir_ / "no" / "such" / "dir.mcap").string(), {}));
  EXPECT_NE(w.error().find("no/such/dir.mcap"), std::string::npos) << w.error();
  EXPECT_FALSE(w.is_open());
  EXPECT_EQ(w.add_channel(1, "/t", "json"), 0);
}

TEST_F(McapWriterTest, AFullDiskIsReportedNotIgnored) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  McapWriter w;
  McapOptions o;
  o.chunk_bytes = 1024;
  ASSERT_TRUE(w.open("/dev/full", o));
  const auto ch = w.add_channel(w.add_schema("s", "jsonschema", "{}"), "/t", "json");
  bool failed = false;
  for (int i = 0; i < 2000 && !failed; ++i) failed = !w.write(ch, 1, std::string(512, 'x'));
  failed = !w.close() || failed;
  EXPECT_TRUE(failed);
  EXPECT_NE(w.error().find("No space left"), std::string::npos) << w.error();
}

TEST_F(McapWriterTest, AMessageOnAChannelNeverAddedIsRefused) {
  McapWriter w;
  ASSERT_TRUE(w.open((dir_ / "x.mcap").string(), {}));
  EXPECT_FALSE(w.write(7, 1, "{}"));
  EXPECT_NE(w.error().find("channel 7"), std::string::npos) << w.error();
  EXPECT_FALSE(w.close());
}

TEST_F(McapWriterTest, OneFilePerWriter) {
  McapWriter w;
  ASSERT_TRUE(w.open((dir_ / "1.mcap").string(), {}));
  ASSERT_TRUE(w.close());
  EXPECT_FALSE(w.open((dir_ / "2.mcap").string(), {}));
}

}  // namespace
}  // namespace fieldguard::app
