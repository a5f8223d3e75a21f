// RoboSense RS-32: one malformed input per DecodeError, each expected to yield exactly that error, through the
// free functions and through the stream's counters.
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "drivers/robosense_test_support.hpp"
#include "fieldguard/drivers/robosense_stream.hpp"

namespace fieldguard::robosense {
namespace {

enum class Port : std::uint8_t { Msop, Difop };

struct Case {
  std::string name;
  Port port;
  std::function<std::vector<std::uint8_t>()> make;
  DecodeError want;
  bool calibrated = true;  // the stream saw a good DIFOP first
};

std::vector<std::uint8_t> good_msop() {
  test::MsopBuilder m;
  m.azimuths(0, 20).all_channels(2000, 1);
  return m.bytes();
}

std::vector<std::uint8_t> good_difop() { return test::DifopBuilder{}.bytes(); }

template <typename F>
std::function<std::vector<std::uint8_t>()> edit(std::vector<std::uint8_t> (*base)(), F f) {
  return [base, f] {
    auto b = base();
    f(b);
    return b;
  };
}

std::vector<Case> cases() {
  using B = std::vector<std::uint8_t>;
  return {
      {"msop_short", Port::Msop, edit(good_msop, [](B& b) { b.pop_back(); }), DecodeError::BadLength},
      {"msop_long", Port::Msop, edit(good_msop, [](B& b) { b.push_back(0); }), DecodeError::BadLength},
      {"msop_empty", Port::Msop, [] { return B{}; }, DecodeError::BadLength},
      {"msop_magic", Port::Msop, edit(good_msop, [](B& b) { b[7] = 0xA1; }), DecodeError::BadMagic},
      {"msop_is_difop", Port::Msop, good_difop, DecodeError::BadMagic},
      {"msop_block_flag", Port::Msop, edit(good_msop, [](B& b) { b[42 + 5 * 100 + 1] = 0xEF; }),
       DecodeError::BadBlockFlag},
      {"msop_azimuth", Port::Msop, edit(good_msop, [](B& b) { test::put16(b, 42 + 3 * 100 + 2, 36000); }),
       DecodeError::BadAzimuth},
      {"msop_month", Port::Msop, edit(good_msop, [](B& b) { b[21] = 13; }), DecodeError::BadTimestamp},
      {"msop_microseconds", Port::Msop, edit(good_msop, [](B& b) { test::put16(b, 28, 1000); }),
       DecodeError::BadTimestamp},
      {"msop_before_difop", Port::Msop, good_msop, DecodeError::NoCalibration, false},
      {"difop_short", Port::Difop, edit(good_difop, [](B& b) { b.resize(1206); }), DecodeError::BadLength},
      {"difop_magic", Port::Difop, edit(good_difop, [](B& b) { b[4] = 0x12; }), DecodeError::BadMagic},
      {"difop_is_msop", Port::Difop, good_msop, DecodeError::BadMagic},
      {"difop_sign_byte", Port::Difop, edit(good_difop, [](B& b) { b[468 + 3 * 7] = 0x02; }),
       DecodeError::BadAngleTable},
      {"difop_horizontal_sign", Port::Difop, edit(good_difop, [](B& b) { b[564 + 3 * 4] = 0x80; }),
       DecodeError::BadAngleTable},
      {"difop_horizontal_unwritten", Port::Difop,
       edit(good_difop, [](B& b) { std::fill(b.begin() + 564, b.begin() + 660, 0xFF); }), DecodeError::BadAngleTable},
  };
}

class RoboSenseMalformed : public ::testing::TestWithParam<Case> {};

TEST_P(RoboSenseMalformed, YieldsItsError) {
  const Case& c = GetParam();
  const std::vector<std::uint8_t> bytes = c.make();
  if (c.port == Port::Msop) {
    Decoder d;
    if (c.calibrated) d.apply(*parse_difop(good_difop()));
    std::vector<LidarPoint> pts;
    const auto r = d.decode(bytes, pts);
    ASSERT_FALSE(r.has_value());
    EXPECT_EQ(r.error(), c.want) << to_string(r.error());
    EXPECT_TRUE(pts.empty());
  } else {
    const auto r = parse_difop(bytes);
    ASSERT_FALSE(r.has_value());
    EXPECT_EQ(r.error(), c.want) << to_string(r.error());
  }

  Stream s;
  if (c.calibrated) s.push_difop(good_difop());
  std::vector<LidarFrame> frames;
  if (c.port == Port::Msop) {
    s.push_msop(bytes, Stamp{1}, frames);
    EXPECT_EQ(s.counters().msop_errors[static_cast<std::size_t>(c.want)], 1U);
    EXPECT_EQ(s.counters().msop_rejected(), 1U);
    EXPECT_EQ(s.counters().msop_decoded, 0U);
  } else {
    s.push_difop(bytes);
    EXPECT_EQ(s.counters().difop_errors[static_cast<std::size_t>(c.want)], 1U);
    EXPECT_EQ(s.counters().difop_rejected(), 1U);
  }
  // A good packet afterwards still decodes: errors leave no state behind.
  s.push_difop(good_difop());
  s.push_msop(good_msop(), Stamp{2}, frames);
  EXPECT_EQ(s.counters().msop_decoded, 1U);
}

INSTANTIATE_TEST_SUITE_P(EveryErrorKind, RoboSenseMalformed, ::testing::ValuesIn(cases()),
                         [](const auto& param_info) { return param_info.param.name; });

TEST(RoboSenseMalformed, EveryErrorKindIsCovered) {
  std::vector<bool> seen(kDecodeErrorCount, false);
  for (const auto& c : cases()) seen[static_cast<std::size_t>(c.want)] = true;
  for (std::size_t i = 0; i < kDecodeErrorCount; ++i) {
    EXPECT_TRUE(seen[i]) << to_string(static_cast<DecodeError>(i));
    EXPECT_NE(to_string(static_cast<DecodeError>(i)), "unknown");
  }
}

}  // namespace
}  // namespace fieldguard::robosense
