// xsens::StreamParser: the real MTi-G-710 streams in any chunking, resynchronisation after garbage and bad
// frames, and a counter for every way a message is lost.

#include "fieldguard/drivers/xsens_stream.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <variant>
#include <vector>

namespace fieldguard::xsens {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes read_bin(const std::string& name) {
  std::ifstream f(std::string(FIELDGUARD_TEST_DATA) + "/xsens/" + name, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

Bytes packet(std::uint16_t id, const Bytes& data) {
  Bytes p = {static_cast<std::uint8_t>(id >> 8), static_cast<std::uint8_t>(id & 0xFF),
             static_cast<std::uint8_t>(data.size())};
  p.insert(p.end(), data.begin(), data.end());
  return p;
}

Bytes cat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

// A small MTData2 message with the given packet counter.
Bytes counter_frame(std::uint16_t counter) {
  return encode_frame(
      mid::kMtData2,
      cat({packet(0x1020, {static_cast<std::uint8_t>(counter >> 8), static_cast<std::uint8_t>(counter & 0xFF)}),
           packet(0x1060, {0, 0, 0x10, 0x00})}));
}

struct Result {
  std::vector<StreamItem> out;
  StreamCounters counters;
};

Result feed(const Bytes& bytes, std::size_t chunk = 0) {
  StreamParser p;
  Result r;
  if (chunk == 0) chunk = bytes.size() + 1;
  for (std::size_t i = 0; i < bytes.size(); i += chunk) {
    p.push(ByteSpan(bytes).subspan(i, std::min(chunk, bytes.size() - i)), r.out);
  }
  p.finish(r.out);
  r.counters = p.counters();
  return r;
}

std::vector<std::uint16_t> counters_of(const Result& r) {
  std::vector<std::uint16_t> c;
  for (const auto& item : r.out) {
    if (const auto* d = std::get_if<MtData2>(&item)) c.push_back(d->packet_counter.value_or(0xFFFF));
  }
  return c;
}

TEST(XsensStream, RealStreamsInAnyChunking) {
  for (int set = 1; set <= 5; ++set) {
    const Bytes stream = read_bin("einride_" + std::to_string(set) + ".bin");
    ASSERT_FALSE(stream.empty()) << set;
    const auto whole = feed(stream);
    EXPECT_EQ(whole.counters.mtdata2, 100U) << set;
    EXPECT_EQ(whole.counters.rejected(), 0U) << set;
    EXPECT_EQ(whole.counters.garbage_bytes, 0U) << set;
    const auto expected = counters_of(whole);
    for (std::size_t i = 1; i < expected.size(); ++i) {
      EXPECT_EQ(static_cast<std::uint16_t>(expected[i - 1] + 1), expected[i]) << set << " #" << i;
    }
    for (const std::size_t chunk : {1U, 2U, 5U, 13U, 255U, 1000U}) {
      const auto r = feed(stream, chunk);
      EXPECT_EQ(counters_of(r), expected) << "set " << set << " chunk " << chunk;
      EXPECT_EQ(r.counters.rejected(), 0U);
    }
  }
}

TEST(XsensStream, EverySplitPoint) {
  const Bytes stream = cat({{0x00, 0xFA}, counter_frame(1), {0xFA, 0xFF, 0x36}, counter_frame(2), counter_frame(3)});
  for (std::size_t cut = 1; cut < stream.size(); ++cut) {
    StreamParser p;
    std::vector<StreamItem> out;
    p.push(ByteSpan(stream).first(cut), out);
    p.push(ByteSpan(stream).subspan(cut), out);
    p.finish(out);
    const Result r{std::move(out), p.counters()};
    EXPECT_EQ(counters_of(r), (std::vector<std::uint16_t>{1, 2, 3})) << "cut " << cut;
    EXPECT_EQ(r.counters.garbage_bytes, 5U) << "cut " << cut;
  }
}

TEST(XsensStream, OtherMessagesComeOutRaw) {
  const auto r = feed(cat({{0xFA, 0xFF, 0x31, 0x00, 0xD0}, counter_frame(7), {0xFA, 0xFF, 0x42, 0x01, 0x04, 0xBA}}));
  ASSERT_EQ(r.out.size(), 3U);
  ASSERT_TRUE(std::holds_alternative<RawMessage>(r.out[0]));
  EXPECT_EQ(std::get<RawMessage>(r.out[0]).mid, mid::kGoToConfigAck);
  const auto& err = std::get<RawMessage>(r.out[2]);
  EXPECT_EQ(err.mid, mid::kError);
  EXPECT_EQ(err.payload, (Bytes{0x04}));
  EXPECT_EQ(r.counters.other_messages, 2U);
  EXPECT_EQ(r.counters.messages, 3U);
}

TEST(XsensStream, AFalsePreambleDoesNotHideRealFrames) {
  // Garbage that looks like the start of a long frame, then real frames within its announced length: the
  // false one fails its checksum (or is cut off by the end of input) and the parser goes back for the real ones.
  const Bytes header = {0xFA, 0xFF, 0x36, 0xFF, 0x07, 0xD0};  // announces 2000 bytes
  const auto complete = feed(cat({header, counter_frame(1), counter_frame(2), Bytes(2100, 0x55), counter_frame(3)}));
  EXPECT_EQ(counters_of(complete), (std::vector<std::uint16_t>{1, 2, 3}));
  EXPECT_EQ(complete.counters.bad_checksum, 1U);
  const auto cut = feed(cat({header, counter_frame(1), counter_frame(2)}));
  EXPECT_EQ(counters_of(cut), (std::vector<std::uint16_t>{1, 2}));
  EXPECT_EQ(cut.counters.truncated_frame, 1U);
}

TEST(XsensStream, BoundedWhateverTheInput) {
  // Megabytes of noise full of preambles: nothing comes out, nothing grows, and a real frame after it decodes.
  std::mt19937 rng(3);
  Bytes noise(3 << 20);
  for (std::size_t i = 0; i < noise.size(); ++i) {
    noise[i] = i % 97 == 0 ? 0xFA : i % 97 == 1 ? 0xFF : static_cast<std::uint8_t>(rng() & 0xFFU);
  }
  const auto r = feed(cat({noise, counter_frame(9)}), 65536);
  ASSERT_FALSE(counters_of(r).empty());
  EXPECT_EQ(counters_of(r).back(), 9);
  EXPECT_GT(r.counters.garbage_bytes, noise.size() / 2);
}

// One kind of damage each, between two good messages.
struct Damage {
  const char* name;
  Bytes bytes;
  std::uint64_t StreamCounters::*counter;
  std::uint64_t count;
  std::size_t extra_messages = 0;  // good messages inside the damaged bytes
};

class XsensStreamMalformed : public ::testing::TestWithParam<Damage> {};

TEST_P(XsensStreamMalformed, IsCountedAndTheNeighboursSurvive) {
  const Damage& d = GetParam();
  for (const std::size_t chunk : {std::size_t{0}, std::size_t{1}, std::size_t{7}}) {
    const auto r = feed(cat({counter_frame(100), d.bytes, counter_frame(200)}), chunk);
    const auto c = counters_of(r);
    ASSERT_EQ(c.size(), 2U + d.extra_messages) << d.name << " chunk " << chunk;
    EXPECT_EQ(c.front(), 100);
    EXPECT_EQ(c.back(), 200);
    EXPECT_EQ(r.counters.*d.counter, d.count) << d.name << " chunk " << chunk;
  }
}

Bytes bad_checksum(Bytes f) {
  f.back() = static_cast<std::uint8_t>(f.back() + 1);
  return f;
}

INSTANTIATE_TEST_SUITE_P(
    Kinds, XsensStreamMalformed,
    ::testing::Values(
        Damage{"BadChecksumThenResync", bad_checksum(counter_frame(1)), &StreamCounters::bad_checksum, 1},
        Damage{"GarbageBeforeThePreamble", {0x00, 0x01, 0xFA, 0x02, 0xFF, 0x36}, &StreamCounters::garbage_bytes, 6},
        Damage{"TruncatedFrame", {0xFA, 0xFF, 0x36, 0x05, 0x10, 0x20}, &StreamCounters::bad_checksum, 1},
        Damage{"LengthOverTheCap", {0xFA, 0xFF, 0x36, 0xFF, 0xFF, 0xFF}, &StreamCounters::too_long, 1},
        Damage{"ExtendedLengthMessage",
               encode_frame(mid::kMtData2, cat({packet(0x1020, {0, 50}), packet(0xA080, Bytes(250, 1)),
                                                packet(0xA080, Bytes(250, 2))})),
               &StreamCounters::unknown_data_ids, 2, 1},
        Damage{"WrongSizeForADataId", encode_frame(mid::kMtData2, packet(0x2030, Bytes(8, 0))),
               &StreamCounters::bad_packet_size, 1},
        Damage{"PacketRunsPastThePayload", encode_frame(mid::kMtData2, Bytes{0x10, 0x20, 0x09, 0x00}),
               &StreamCounters::truncated_packet, 1},
        Damage{"UnknownDataIdsSkipped",
               encode_frame(mid::kMtData2, cat({packet(0x1020, {0, 150}), packet(0x7777, {1, 2, 3})})),
               &StreamCounters::unknown_data_ids, 1, 1}),
    [](const auto& tp) { return std::string(tp.param.name); });

TEST(XsensStream, FrameCutOffByTheEndOfInput) {
  Bytes f = counter_frame(5);
  f.pop_back();
  const auto r = feed(cat({counter_frame(4), f}));
  EXPECT_EQ(counters_of(r), (std::vector<std::uint16_t>{4}));
  EXPECT_EQ(r.counters.truncated_frame, 1U);
}

}  // namespace
}  // namespace fieldguard::xsens
