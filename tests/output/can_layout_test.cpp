#include "fieldguard/output/can_layout.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "fieldguard/output/can_frame.hpp"

namespace fieldguard::output {
namespace {

using Data = std::array<std::uint8_t, 8>;

// J1939 ids of protocols.md §7.4's worked examples.
TEST(J1939Id, ComposesTheWorkedExamples) {
  EXPECT_EQ(j1939_id(6, 0xFF10, 0x80), 0x18FF1080U);
  EXPECT_EQ(j1939_id(3, 0xEF00, 0x80, 0x26), 0x0CEF2680U);
}

TEST(J1939Id, SplitsTheWorkedExamples) {
  const auto a = j1939_fields(0x18F0010BU);
  EXPECT_EQ(a.pgn, 61441U);
  EXPECT_EQ(a.source, 0x0B);
  EXPECT_EQ(a.priority, 6);
  const auto b = j1939_fields(0x0C820E0FU);
  EXPECT_EQ(b.pgn, 33280U);
  EXPECT_EQ(b.destination, 0x0E);
  EXPECT_EQ(b.source, 0x0F);
  EXPECT_EQ(b.priority, 3);
}

// Whole-table checks: what a hand edit of can_layout.cpp could get wrong.
TEST(CanLayout, SignalsFitTheirMessageAndDoNotOverlap) {
  for (const MessageLayout& m : message_layouts()) {
    SCOPED_TRACE(std::string(m.name));
    ASSERT_LE(m.dlc, 8);
    Data used{};
    std::set<std::string_view> names;
    for (const Signal& s : m.signals) {
      SCOPED_TRACE(std::string(s.name));
      EXPECT_TRUE(names.insert(s.name).second) << "duplicate signal name";
      // Mark the signal's bits by packing all ones into an empty frame.
      Data d{};
      put_raw(d, s, ~std::uint64_t{0});
      int bits = 0;
      for (std::size_t i = 0; i < 8; ++i) {
        bits += std::popcount(d[i]);
        EXPECT_EQ(d[i] & used[i], 0) << "overlaps another signal in byte " << i;
        used[i] = static_cast<std::uint8_t>(used[i] | d[i]);
        if (i >= m.dlc) {
          EXPECT_EQ(d[i], 0) << "beyond the DLC";
        }
      }
      EXPECT_EQ(bits, s.length);
    }
  }
}

TEST(CanLayout, RangesAndValueTablesAreRepresentable) {
  for (const MessageLayout& m : message_layouts()) {
    for (const Signal& s : m.signals) {
      SCOPED_TRACE(std::string(m.name) + "." + std::string(s.name));
      const double lo_raw = s.is_signed ? -std::ldexp(1.0, s.length - 1) : 0.0;
      const double hi_raw = s.is_signed ? std::ldexp(1.0, s.length - 1) - 1 : std::ldexp(1.0, s.length) - 1;
      EXPECT_GT(s.scale, 0.0);
      EXPECT_LE(s.min, s.max);
      EXPECT_GE(std::round((s.min - s.offset) / s.scale), lo_raw);
      EXPECT_LE(std::round((s.max - s.offset) / s.scale), hi_raw);
      for (const ValueName& v : s.values) {
        EXPECT_GE(static_cast<double>(v.raw), lo_raw);
        EXPECT_LE(static_cast<double>(v.raw), hi_raw);
      }
    }
  }
}

TEST(CanLayout, IdsUseProprietaryPgns) {
  std::set<std::uint32_t> pgns;
  for (const MessageLayout& m : message_layouts()) {
    EXPECT_TRUE(m.pgn == 0xEF00 || (m.pgn >= 0xFF00 && m.pgn <= 0xFFFF)) << m.name;
    EXPECT_LE(m.default_priority, 7);
    EXPECT_EQ(&layout(m.id), &m);
    EXPECT_TRUE(pgns.insert(m.pgn).second) << "two messages share PGN " << m.pgn;
  }
  EXPECT_EQ(layout(MessageId::StopRequest).pgn, 0xEF00U);  // addressed to the controller only
}

TEST(CanLayout, IntelPackingIsLittleEndianFromTheLsb) {
  const Signal s{"S", 8, 16};
  Data d{};
  put_raw(d, s, 0x1234);
  EXPECT_EQ(d, (Data{0x00, 0x34, 0x12, 0, 0, 0, 0, 0}));
  EXPECT_EQ(get_raw(d, s), 0x1234U);
}

// protocols.md §7.3: 7|16@0+ covers bytes 0-1 big-endian (12 34 -> 0x1234).
TEST(CanLayout, MotorolaPackingFollowsTheSawtoothNumbering) {
  const Signal s{"S", 7, 16, ByteOrder::Motorola};
  Data d{};
  put_raw(d, s, 0x1234);
  EXPECT_EQ(d, (Data{0x12, 0x34, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(get_raw(d, s), 0x1234U);
  // A 12-bit field with its MSB at bit 3 of byte 0: 4 bits there, then all 8 of byte 1.
  const Signal t{"T", 3, 12, ByteOrder::Motorola};
  Data e{0xF0, 0, 0, 0, 0, 0, 0, 0};
  put_raw(e, t, 0xABC);
  EXPECT_EQ(e, (Data{0xFA, 0xBC, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(get_raw(e, t), 0xABCU);
}

TEST(CanLayout, PackingLeavesOtherBitsAlone) {
  const Signal s{"S", 6, 11, ByteOrder::Intel, true};
  Data d;
  d.fill(0xFF);
  put_raw(d, s, 0);
  EXPECT_EQ(d, (Data{0x3F, 0x00, 0xFE, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}));
}

TEST(CanLayout, SignedSignalsSignExtend) {
  const Signal s{"X", 6, 11, ByteOrder::Intel, true, 0.1, 0, -102.4, 102.3, "m"};
  Data d{};
  EXPECT_TRUE(put_physical(d, s, -3.7));
  EXPECT_EQ(get_raw(d, s), 2048U - 37U);
  EXPECT_NEAR(get_physical(d, s), -3.7, 1e-9);
  EXPECT_TRUE(put_physical(d, s, -102.4));
  EXPECT_NEAR(get_physical(d, s), -102.4, 1e-9);
}

TEST(CanLayout, OutOfRangeValuesSaturateAndAreReported) {
  const Signal s{"D", 8, 16, ByteOrder::Intel, false, 0.01, 0, 0, 600, "m"};
  Data d{};
  EXPECT_TRUE(put_physical(d, s, 12.344));
  EXPECT_EQ(get_raw(d, s), 1234U);  // rounded to the nearest step
  EXPECT_TRUE(put_physical(d, s, 12.346));
  EXPECT_EQ(get_raw(d, s), 1235U);
  EXPECT_FALSE(put_physical(d, s, 700));
  EXPECT_EQ(get_raw(d, s), 60000U);
  EXPECT_FALSE(put_physical(d, s, -1));
  EXPECT_EQ(get_raw(d, s), 0U);
  EXPECT_FALSE(put_physical(d, s, std::numeric_limits<double>::quiet_NaN()));
  EXPECT_EQ(get_raw(d, s), 0U);
  EXPECT_FALSE(put_physical(d, s, std::numeric_limits<double>::infinity()));
  EXPECT_EQ(get_raw(d, s), 60000U);
  EXPECT_FALSE(put_physical(d, s, -1e300));
  EXPECT_EQ(get_raw(d, s), 0U);
}

TEST(CanLayout, CountersWrapInsteadOfSaturating) {
  const Signal s{"C", 0, 4, ByteOrder::Intel, false, 1, 0, 0, 15, "", "", {}, Overflow::Wrap};
  Data d{};
  EXPECT_TRUE(put_physical(d, s, 17));
  EXPECT_EQ(get_raw(d, s), 1U);
  EXPECT_FALSE(put_physical(d, s, std::numeric_limits<double>::infinity()));
  EXPECT_FALSE(put_physical(d, s, 1e30));
}

TEST(CanLayout, ASignalOutsideTheFrameIsRejectedNotWrittenPast) {
  Data d{};
  EXPECT_THROW(put_raw(d, Signal{"S", 60, 8}, 1), std::invalid_argument);
  EXPECT_THROW((void)get_raw(d, Signal{"S", 63, 16, ByteOrder::Motorola}), std::invalid_argument);
  EXPECT_THROW(put_raw(d, Signal{"S", 0, 0}, 1), std::invalid_argument);
  EXPECT_NO_THROW(put_raw(d, Signal{"S", 56, 8}, 1));
  EXPECT_NO_THROW(put_raw(d, Signal{"S", 63, 8, ByteOrder::Motorola}, 1));
}

}  // namespace
}  // namespace fieldguard::output
