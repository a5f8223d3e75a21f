// SCIP 2.0: one malformed input per Error, each expected to yield exactly that error (from the parser's counters
// or from the decoder named by the case), and the parser back in step for the good reply that follows.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "drivers/scip_test_support.hpp"
#include "fieldguard/drivers/scip.hpp"
#include "fieldguard/drivers/scip_data.hpp"

namespace fieldguard::scip {
namespace {

enum class Decode : std::uint8_t { None, Scan, Parameters, Info };

struct Case {
  std::string name;
  std::string bytes;
  Error want;
  Decode decode = Decode::None;  // None: a framing error the parser counts
};

std::string gd(std::string_view data) {
  return "GD0540054200\n" + test::line("00") + test::line("4]J7") + test::data_lines(data) + "\n";
}

std::string too_long_scan() {
  std::string s = "MD0000108000000\n" + test::line("99") + test::line("0000");
  for (int i = 0; i < 110; ++i) s += test::line(std::string(64, '0'));
  return s + "\n";
}

std::vector<Case> cases() {
  return {
      {"status_check", "VV\n00Q\n\n", Error::BadCheckCode},
      {"info_check", "PP\n00P\nDMIN:23;8\n\n", Error::BadCheckCode},
      {"data_check", "GD0540054200\n00P\n4]J7B\n1Dh0CB>YPj\n\n", Error::BadCheckCode},
      {"echo_unknown", "HELLO\n00P\n\n", Error::MalformedLine},
      {"echo_binary", std::string("\x00\xff\x10", 3) + "\n", Error::MalformedLine},
      {"status_two_chars", "VV\n00\n\n", Error::MalformedLine},
      {"status_missing", "VV\n\n", Error::MalformedLine},
      {"payload_one_char", "VV\n00P\nA\n\n", Error::MalformedLine},
      {"status_unknown_letter", "VV\n" + test::line("0Z") + "\n", Error::UnknownStatus},
      {"status_unknown_number", "VV\n" + test::line("15") + "\n", Error::UnknownStatus},
      {"line_too_long", "VV\n00P\n" + std::string(200, 'A') + "\n\n", Error::LineTooLong},
      {"garbage_without_lf", std::string(5000, 'x') + "\n\n", Error::LineTooLong},
      {"reply_too_long", too_long_scan(), Error::ReplyTooLong},
      {"md_acknowledgement", test::simple_reply("MD0000108000000", "00"), Error::NotThisReply, Decode::Scan},
      {"md_error_status", test::simple_reply("MD0000108000000", "04"), Error::NotThisReply, Decode::Scan},
      {"vv_as_pp", test::utm_vv_reply(), Error::NotThisReply, Decode::Parameters},
      {"bm_as_info", test::simple_reply("BM", "00"), Error::NotThisReply, Decode::Info},
      {"echo_end_before_start", test::scan_reply("MD1080000000000", "99", 1, {1, 2, 3}), Error::BadEcho, Decode::Scan},
      {"data_char_p", gd("1Dp0CB>YP"), Error::BadCharacter, Decode::Scan},
      {"timestamp_char", "GD0540054200\n00P\n" + test::line("4]J~") + test::data_lines("1Dh0CB>YP") + "\n",
       Error::BadCharacter, Decode::Scan},
      {"too_few_values", gd("1Dh0CB"), Error::BadDataLength, Decode::Scan},
      {"not_whole_values", gd("1Dh0CB>Y"), Error::BadDataLength, Decode::Scan},
      {"short_inner_line", "GD0000002100\n00P\n4]J7B\n" + test::line(std::string(63, '1')) + test::line("111") + "\n",
       Error::BadDataLength, Decode::Scan},
      {"timestamp_short", "GD0540054200\n00P\n" + test::line("4]J") + test::data_lines("1Dh0CB>YP") + "\n",
       Error::BadDataLength, Decode::Scan},
      {"pp_missing_dmax",
       test::simple_reply("PP", "00", test::info_line("DMIN", "23") + test::info_line("ARES", "1440")), Error::BadField,
       Decode::Parameters},
      {"pp_not_a_number", test::simple_reply("PP", "00", test::info_line("DMIN", "2x3")), Error::BadField,
       Decode::Parameters},
      {"info_without_colon", test::simple_reply("VV", "00", test::line("VEND Hokuyo")), Error::BadField, Decode::Info},
  };
}

class ScipMalformed : public ::testing::TestWithParam<Case> {};

TEST_P(ScipMalformed, YieldsItsErrorAndResynchronises) {
  const Case& c = GetParam();
  ReplyParser p;
  std::vector<Reply> out;
  p.push(c.bytes, out);
  if (c.decode == Decode::None) {
    EXPECT_TRUE(out.empty());
    EXPECT_EQ(p.counters().errors[static_cast<std::size_t>(c.want)], 1U) << to_string(c.want);
    EXPECT_EQ(p.counters().rejected(), 1U);
  } else {
    EXPECT_EQ(p.counters().rejected(), 0U);
    ASSERT_EQ(out.size(), 1U);
    std::optional<Error> got;
    if (c.decode == Decode::Scan) {
      if (auto s = decode_scan(out[0]); !s) got = s.error();
    } else if (c.decode == Decode::Parameters) {
      if (auto s = decode_parameters(out[0]); !s) got = s.error();
    } else if (auto s = decode_info(out[0]); !s) {
      got = s.error();
    }
    ASSERT_TRUE(got.has_value());
    EXPECT_EQ(*got, c.want) << to_string(*got);
  }
  // The next good reply is parsed.
  out.clear();
  p.push(test::utm_pp_reply(), out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_TRUE(decode_parameters(out[0]).has_value());
}

INSTANTIATE_TEST_SUITE_P(EveryErrorKind, ScipMalformed, ::testing::ValuesIn(cases()),
                         [](const auto& param_info) { return param_info.param.name; });

TEST(ScipMalformed, EveryErrorKindIsCovered) {
  std::vector<bool> seen(kErrorCount, false);
  for (const auto& c : cases()) seen[static_cast<std::size_t>(c.want)] = true;
  for (std::size_t i = 0; i < kErrorCount; ++i) EXPECT_TRUE(seen[i]) << to_string(static_cast<Error>(i));
}

TEST(ScipMalformed, HandMadeReplyWithABadEcho) {
  Reply r;
  r.echo = "MD12";
  r.command = Command::MD;
  r.status = "99";
  r.lines = {"0000", "000"};
  EXPECT_EQ(decode_scan(r).error(), Error::BadEcho);
}

}  // namespace
}  // namespace fieldguard::scip
