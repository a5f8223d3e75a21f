// Xbus frames: the worked frames of protocols.md §5.4 (the GoToConfig/GoToMeasurement ones match MT Manager
// captures), extended length, and the ways a frame is refused.

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "fieldguard/drivers/xsens.hpp"

namespace fieldguard::xsens {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(XsensFrame, WorkedFrames) {
  struct Case {
    Bytes frame;
    std::uint8_t mid;
    std::size_t payload;
  };
  const std::vector<Case> cases = {
      {{0xFA, 0xFF, 0x30, 0x00, 0xD1}, mid::kGoToConfig, 0},
      {{0xFA, 0xFF, 0x10, 0x00, 0xF1}, mid::kGoToMeasurement, 0},
      {{0xFA, 0xFF, 0x00, 0x00, 0x01}, mid::kReqDeviceId, 0},
      {{0xFA, 0xFF, 0x31, 0x00, 0xD0}, mid::kGoToConfigAck, 0},                          // MT Manager capture
      {{0xFA, 0xFF, 0x03, 0x04, 0x03, 0x70, 0x03, 0xF8, 0x8C}, mid::kInitMtResults, 4},  // MT Manager capture
      {{0xFA, 0xFF, 0xC0, 0x18, 0x10, 0x20, 0xFF, 0xFF, 0x10, 0x60, 0xFF, 0xFF, 0x20, 0x30, 0x00,
        0x64, 0x40, 0x20, 0x00, 0x64, 0x80, 0x20, 0x00, 0x64, 0xE0, 0x20, 0xFF, 0xFF, 0x13},
       mid::kSetOutputConfiguration,
       24},
  };
  for (const auto& c : cases) {
    const auto m = decode_frame(c.frame);
    ASSERT_TRUE(m) << to_string(m.error());
    EXPECT_EQ(m->mid, c.mid);
    EXPECT_EQ(m->payload.size(), c.payload);
    EXPECT_EQ(m->frame_size, c.frame.size());
    EXPECT_EQ(encode_frame(c.mid, m->payload), c.frame);
  }
  EXPECT_EQ(message_name(mid::kMtData2), "MTData2");
  EXPECT_EQ(message_name(0x91), "");
}

TEST(XsensFrame, ExtendedLength) {
  // protocols.md §5.4: a 300-byte payload starts FA FF 36 FF 01 2C.
  Bytes payload(300);
  for (std::size_t i = 0; i < payload.size(); ++i) payload[i] = static_cast<std::uint8_t>(i * 7);
  const Bytes f = encode_frame(mid::kMtData2, payload);
  ASSERT_EQ(f.size(), 6U + 300U + 1U);
  EXPECT_EQ((Bytes{f.begin(), f.begin() + 6}), (Bytes{0xFA, 0xFF, 0x36, 0xFF, 0x01, 0x2C}));
  const auto m = decode_frame(f);
  ASSERT_TRUE(m) << to_string(m.error());
  EXPECT_EQ(m->payload.size(), 300U);
  EXPECT_EQ(m->payload[299], payload[299]);
  // 254 bytes still fit the short form; 255 need the extended one.
  EXPECT_EQ(encode_frame(mid::kMtData2, Bytes(254))[3], 254);
  EXPECT_EQ(encode_frame(mid::kMtData2, Bytes(255))[3], 0xFF);
  EXPECT_TRUE(decode_frame(encode_frame(mid::kMtData2, Bytes(255))));
  EXPECT_TRUE(decode_frame(encode_frame(mid::kMtData2, Bytes(kMaxPayload))));
}

TEST(XsensFrame, TrailingBytesAreNotPartOfTheFrame) {
  const Bytes f = {0xFA, 0xFF, 0x30, 0x00, 0xD1, 0xFA, 0xFF};
  const auto m = decode_frame(f);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->frame_size, 5U);
}

struct BadFrame {
  const char* name;
  Bytes bytes;
  Error error;
};

class XsensFrameMalformed : public ::testing::TestWithParam<BadFrame> {};

TEST_P(XsensFrameMalformed, GivesTheRightError) {
  const auto m = decode_frame(GetParam().bytes);
  ASSERT_FALSE(m);
  EXPECT_EQ(m.error(), GetParam().error) << to_string(m.error());
}

Bytes oversized() {
  Bytes f = encode_frame(mid::kMtData2, Bytes(kMaxPayload + 1));
  return f;
}

INSTANTIATE_TEST_SUITE_P(
    Frames, XsensFrameMalformed,
    ::testing::Values(
        BadFrame{"Empty", {}, Error::TooShort}, BadFrame{"OnlyPreamble", {0xFA}, Error::TooShort},
        BadFrame{"NoBusId", {0xFA, 0x01, 0x30, 0x00, 0xD1}, Error::BadPreamble},
        BadFrame{"NotAPreamble", {0xFB, 0xFF, 0x30, 0x00, 0xD1}, Error::BadPreamble},
        BadFrame{"HeaderOnly", {0xFA, 0xFF, 0x30}, Error::TooShort},
        BadFrame{"PayloadCut", {0xFA, 0xFF, 0x36, 0x04, 0x10, 0x20}, Error::TooShort},
        BadFrame{"ChecksumMissing", {0xFA, 0xFF, 0x30, 0x00}, Error::TooShort},
        BadFrame{"ExtendedLengthCut", {0xFA, 0xFF, 0x36, 0xFF, 0x01}, Error::TooShort},
        BadFrame{"BadChecksum", {0xFA, 0xFF, 0x30, 0x00, 0xD2}, Error::BadChecksum},
        BadFrame{"FlippedPayloadBit", {0xFA, 0xFF, 0x03, 0x04, 0x03, 0x71, 0x03, 0xF8, 0x8C}, Error::BadChecksum},
        BadFrame{"LengthOverTheCap", oversized(), Error::TooLong}),
    [](const auto& tp) { return std::string(tp.param.name); });

}  // namespace
}  // namespace fieldguard::xsens
