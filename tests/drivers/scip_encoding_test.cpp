// SCIP 2.0 encodings, check codes, command lines, echoes and status codes (protocols.md §3.2-§3.4).
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "drivers/scip_test_support.hpp"
#include "fieldguard/drivers/scip.hpp"

namespace fieldguard::scip {
namespace {

TEST(ScipEncoding, WorkedExamples) {
  EXPECT_EQ(decode_chars("1Dh"), 5432U);
  EXPECT_EQ(decode_chars("0CB"), 1234U);
  EXPECT_EQ(decode_chars(">YP"), 60000U);
  EXPECT_EQ(decode_chars("4]J7"), 1234567U);
  EXPECT_EQ(decode_chars("0"), 0U);
  EXPECT_EQ(decode_chars("o"), 63U);
  EXPECT_EQ(decode_chars("oooo"), 16'777'215U);
  std::string s;
  encode_chars(5432, 3, s);
  EXPECT_EQ(s, "1Dh");
  s.clear();
  encode_chars(1234567, 4, s);
  EXPECT_EQ(s, "4]J7");
}

TEST(ScipEncoding, RejectsCharactersOutsideTheRange) {
  EXPECT_FALSE(decode_chars("").has_value());
  EXPECT_FALSE(decode_chars("00000").has_value());
  EXPECT_FALSE(decode_chars("1Dp").has_value());  // 'p' = 0x70
  EXPECT_FALSE(decode_chars("/00").has_value());  // '/' = 0x2F
  EXPECT_FALSE(decode_chars("&00").has_value());  // multi-echo marker
}

TEST(ScipEncoding, RoundTrip) {
  std::mt19937 rng(42);
  for (int i = 0; i < 1000; ++i) {
    for (int width = 1; width <= 4; ++width) {
      const auto v = static_cast<std::uint32_t>(rng() & ((1U << (6 * width)) - 1));
      std::string s;
      encode_chars(v, static_cast<std::size_t>(width), s);
      ASSERT_EQ(s, test::enc(v, width));
      ASSERT_EQ(decode_chars(s), v);
    }
  }
}

TEST(ScipCheckCode, DocumentedExamples) {
  EXPECT_EQ(check_code("00"), 'P');
  EXPECT_EQ(check_code("99"), 'b');
  EXPECT_EQ(check_code("DMIN:23"), '7');
  EXPECT_EQ(check_code("DMAX:60000"), 'J');
  EXPECT_EQ(check_code("ARES:1440"), '^');
  EXPECT_EQ(check_code("AMIN:0"), '?');
  EXPECT_EQ(check_code("AMAX:1080"), 'Z');
  EXPECT_EQ(check_code("AFRT:540"), '0');
  EXPECT_EQ(check_code("SCAN:2400"), 'U');
  EXPECT_EQ(check_code("MODL:UTM-30LX-EW"), 'I');
  EXPECT_EQ(check_code("4]J7"), 'B');
  EXPECT_EQ(check_code("1Dh0CB>YP"), 'i');
  EXPECT_EQ(check_code("0E"), 'e');  // urg_c's "0Ee"
}

TEST(ScipCommands, Lines) {
  EXPECT_EQ(encode_command(Command::Scip20), "SCIP2.0\n");
  EXPECT_EQ(encode_command(Command::VV), "VV\n");
  EXPECT_EQ(encode_command(Command::PP), "PP\n");
  EXPECT_EQ(encode_command(Command::II), "II\n");
  EXPECT_EQ(encode_command(Command::BM), "BM\n");
  EXPECT_EQ(encode_command(Command::QT), "QT\n");
  EXPECT_EQ(encode_command(Command::RS), "RS\n");
  EXPECT_EQ(encode_command(Command::VV, "abc"), "VV;abc\n");
  EXPECT_EQ(encode_scan(Command::MD, ScanRequest{0, 1080, 0, 0, 0}), "MD0000108000000\n");  // §3.5
  EXPECT_EQ(encode_scan(Command::GD, ScanRequest{540, 542, 0, 0, 0}), "GD0540054200\n");    // §3.5 mini example
  EXPECT_EQ(encode_scan(Command::ME, ScanRequest{44, 725, 3, 1, 99}, "t1"), "ME0044072503199;t1\n");
  EXPECT_EQ(encode_scan(Command::MD, ScanRequest{}), "MD0000108001000\n");
  EXPECT_EQ(encode_tm(1), "TM1\n");
}

TEST(ScipCommands, MisuseThrows) {
  EXPECT_THROW((void)encode_scan(Command::MD, ScanRequest{10, 5, 1, 0, 0}), std::invalid_argument);
  EXPECT_THROW((void)encode_scan(Command::MD, ScanRequest{0, 10000, 1, 0, 0}), std::invalid_argument);
  EXPECT_THROW((void)encode_scan(Command::MD, ScanRequest{0, 1080, 100, 0, 0}), std::invalid_argument);
  EXPECT_THROW((void)encode_scan(Command::MD, ScanRequest{0, 1080, 1, 10, 0}), std::invalid_argument);
  EXPECT_THROW((void)encode_scan(Command::MD, ScanRequest{0, 1080, 1, 0, 100}), std::invalid_argument);
  EXPECT_THROW((void)encode_scan(Command::VV, ScanRequest{}), std::invalid_argument);
  EXPECT_THROW((void)encode_command(Command::MD), std::invalid_argument);
  EXPECT_THROW((void)encode_command(Command::VV, "01234567890123456"), std::invalid_argument);
  EXPECT_THROW((void)encode_command(Command::VV, "a;b"), std::invalid_argument);
  EXPECT_THROW((void)encode_command(Command::VV, "a b"), std::invalid_argument);
  EXPECT_THROW((void)encode_tm(3), std::invalid_argument);
  EXPECT_NO_THROW((void)encode_command(Command::VV, "0123456789abcdef"));
}

TEST(ScipCommands, EchoForms) {
  EXPECT_EQ(command_of_echo("SCIP2.0"), Command::Scip20);
  EXPECT_EQ(command_of_echo("VV"), Command::VV);
  EXPECT_EQ(command_of_echo("VV;abc"), Command::VV);
  EXPECT_EQ(command_of_echo("MD0000108000000"), Command::MD);
  EXPECT_EQ(command_of_echo("ME0000108001000;0123456789abcdef"), Command::ME);
  EXPECT_EQ(command_of_echo("GD0540054200"), Command::GD);
  EXPECT_EQ(command_of_echo("TM1"), Command::TM);
  EXPECT_EQ(command_of_echo("MD000010800000"), Command::Unknown);    // one digit short
  EXPECT_EQ(command_of_echo("MD00001080000001"), Command::Unknown);  // one too many
  EXPECT_EQ(command_of_echo("MD0000108000000;"), Command::Unknown);
  EXPECT_EQ(command_of_echo("ME0000108001000;0123456789abcdefg"), Command::Unknown);
  EXPECT_EQ(command_of_echo("VVX"), Command::Unknown);
  EXPECT_EQ(command_of_echo("XX"), Command::Unknown);
  EXPECT_EQ(command_of_echo(""), Command::Unknown);
  EXPECT_EQ(command_of_echo("1Dh0CB>YPi"), Command::Unknown);
}

TEST(ScipStatus, Categories) {
  EXPECT_EQ(classify_status("00"), StatusCategory::Ok);
  EXPECT_EQ(classify_status("99"), StatusCategory::DataFollows);
  EXPECT_EQ(classify_status("01"), StatusCategory::ParameterError);
  EXPECT_EQ(classify_status("07"), StatusCategory::ParameterError);
  EXPECT_EQ(classify_status("0E"), StatusCategory::CommandRejected);
  EXPECT_EQ(classify_status("0L"), StatusCategory::CommandRejected);
  EXPECT_EQ(classify_status("10"), StatusCategory::CommandRejected);
  EXPECT_EQ(classify_status("21"), StatusCategory::Stopped);
  EXPECT_EQ(classify_status("49"), StatusCategory::Stopped);
  EXPECT_EQ(classify_status("50"), StatusCategory::HardwareTrouble);
  EXPECT_EQ(classify_status("97"), StatusCategory::HardwareTrouble);
  EXPECT_EQ(classify_status("98"), StatusCategory::Resumed);
  EXPECT_EQ(classify_status("0"), StatusCategory::Scip11Ok);
  EXPECT_FALSE(classify_status("11").has_value());
  EXPECT_FALSE(classify_status("20").has_value());
  EXPECT_FALSE(classify_status("0Z").has_value());
  EXPECT_FALSE(classify_status("AB").has_value());
  EXPECT_FALSE(classify_status("000").has_value());
  EXPECT_EQ(status_text(Command::BM, "01"), "laser could not be lit (unstable or abnormal condition)");
  EXPECT_EQ(status_text(Command::BM, "02"), "laser already on");
  EXPECT_EQ(status_text(Command::MD, "04"), "end step out of range");
  EXPECT_EQ(status_text(Command::VV, "0E"), "command not defined");
  EXPECT_EQ(status_text(Command::MD, "55"), "hardware trouble (laser, motor, ...)");
  EXPECT_EQ(status_text(Command::MD, "ZZ"), "unknown status");
  for (std::size_t i = 0; i < kErrorCount; ++i) EXPECT_NE(to_string(static_cast<Error>(i)), "unknown");
}

}  // namespace
}  // namespace fieldguard::scip
