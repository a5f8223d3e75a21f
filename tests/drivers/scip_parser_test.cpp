// SCIP 2.0 reply parsing and scan decoding: the §3.5 examples, chunked input, VV/PP/II, resynchronisation.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "drivers/scip_test_support.hpp"
#include "fieldguard/drivers/scip.hpp"
#include "fieldguard/drivers/scip_data.hpp"

namespace fieldguard::scip {
namespace {

// protocols.md §3.5 mini example, byte for byte.
constexpr std::string_view kGdMini = "GD0540054200\n00P\n4]J7B\n1Dh0CB>YPi\n\n";

void expect_mini(const std::vector<Reply>& replies) {
  ASSERT_EQ(replies.size(), 1U);
  const Reply& r = replies[0];
  EXPECT_EQ(r.echo, "GD0540054200");
  EXPECT_EQ(r.command, Command::GD);
  EXPECT_EQ(r.status, "00");
  ASSERT_EQ(r.lines.size(), 2U);
  const auto s = decode_scan(r);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->timestamp_ms, 1234567U);
  EXPECT_EQ(s->first_step, 540);
  EXPECT_EQ(s->last_step, 542);
  EXPECT_EQ(s->cluster, 1);
  EXPECT_EQ(s->ranges_mm, (std::vector<std::uint32_t>{5432, 1234, 60000}));
  EXPECT_TRUE(s->intensities.empty());
}

TEST(ScipParser, GdMiniExample) {
  ReplyParser p;
  expect_mini(test::parse_all(p, kGdMini));
  EXPECT_EQ(p.counters().replies, 1U);
  EXPECT_EQ(p.counters().rejected(), 0U);
}

TEST(ScipParser, GdMiniExampleSplitAtEveryPoint) {
  for (std::size_t i = 0; i <= kGdMini.size(); ++i) {
    for (std::size_t j = i; j <= kGdMini.size(); ++j) {
      ReplyParser p;
      std::vector<Reply> out;
      p.push(kGdMini.substr(0, i), out);
      p.push(kGdMini.substr(i, j - i), out);
      p.push(kGdMini.substr(j), out);
      expect_mini(out);
      ASSERT_EQ(p.counters().rejected(), 0U) << i << " " << j;
    }
  }
}

TEST(ScipScan, MiniExamplePoints) {
  ReplyParser p;
  const auto replies = test::parse_all(p, kGdMini);
  ASSERT_EQ(replies.size(), 1U);
  std::vector<Point2> pts;
  scan_to_points(*decode_scan(replies[0]), Geometry{}, pts);
  ASSERT_EQ(pts.size(), 3U);  // 60000 = DMAX is a distance
  EXPECT_NEAR(pts[0].x_m, 5.432, 1e-6);
  EXPECT_NEAR(pts[0].y_m, 0.0, 1e-6);
  EXPECT_EQ(pts[0].step, 540);
  const double a = 0.25 * std::numbers::pi / 180.0;  // step 541: 0.25 deg to the left
  EXPECT_NEAR(pts[1].x_m, 1.234 * std::cos(a), 1e-6);
  EXPECT_NEAR(pts[1].y_m, 1.234 * std::sin(a), 1e-6);
  EXPECT_GT(pts[1].y_m, 0.F);
  EXPECT_NEAR(pts[2].angle_rad, 2 * a, 1e-7);
}

TEST(ScipScan, StepAngles) {
  EXPECT_DOUBLE_EQ(step_angle_deg(0), -135.0);
  EXPECT_DOUBLE_EQ(step_angle_deg(540), 0.0);
  EXPECT_DOUBLE_EQ(step_angle_deg(541), 0.25);
  EXPECT_DOUBLE_EQ(step_angle_deg(1080), 135.0);
  EXPECT_NEAR(step_angle_rad(1080), 0.75 * std::numbers::pi, 1e-12);
  Parameters urg04;  // URG-04LX: ARES 1024, AFRT 384
  urg04.ares = 1024;
  urg04.afrt = 384;
  EXPECT_NEAR(step_angle_deg(384 + 256, Geometry::from(urg04)), 90.0, 1e-12);
}

std::string full_md_scan(std::uint32_t timestamp, const std::vector<std::uint32_t>& ranges) {
  return test::scan_reply("MD0000108000000", "99", timestamp, ranges);
}

TEST(ScipParser, FullMdScanIs3372BytesAndParsesExactly) {
  const auto ranges = test::range_pattern(kMaxSteps);
  const std::string bytes = full_md_scan(16'000'000, ranges);
  ASSERT_EQ(bytes.size(), 3372U);  // protocols.md §3.5
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    ReplyParser p;
    std::vector<Reply> out;
    for (std::size_t i = 0; i < bytes.size();) {
      const std::size_t n = std::min<std::size_t>(bytes.size() - i, 1 + rng() % (seed <= 10 ? 17 : 700));
      p.push(std::string_view(bytes).substr(i, n), out);
      i += n;
    }
    ASSERT_EQ(out.size(), 1U) << seed;
    ASSERT_EQ(out[0].lines.size(), 1U + 51U);  // timestamp, 50 full lines and one of 43
    EXPECT_EQ(out[0].lines.back().size(), 43U);
    const auto s = decode_scan(out[0]);
    ASSERT_TRUE(s.has_value()) << to_string(s.error());
    EXPECT_EQ(s->ranges_mm, ranges);
    EXPECT_EQ(s->timestamp_ms, 16'000'000U);
    EXPECT_EQ(s->status, "99");
    EXPECT_EQ(s->remaining_scans, 0);
    EXPECT_EQ(p.counters().rejected(), 0U);
  }
}

TEST(ScipParser, AcknowledgementThenScansInRandomChunks) {
  std::string bytes = test::simple_reply("MD0000108000000", "00");
  std::vector<std::vector<std::uint32_t>> scans;
  for (std::uint32_t k = 0; k < 6; ++k) {
    scans.push_back(test::range_pattern(kMaxSteps, k));
    bytes += full_md_scan(1000 + 25 * k, scans.back());
  }
  std::mt19937 rng(99);
  ReplyParser p;
  std::vector<Reply> out;
  for (std::size_t i = 0; i < bytes.size();) {
    const std::size_t n = std::min<std::size_t>(bytes.size() - i, 1 + rng() % 4096);
    p.push(std::string_view(bytes).substr(i, n), out);
    i += n;
  }
  ASSERT_EQ(out.size(), 7U);
  EXPECT_EQ(out[0].status, "00");
  EXPECT_TRUE(out[0].lines.empty());
  EXPECT_EQ(decode_scan(out[0]).error(), Error::NotThisReply);  // the acknowledgement is no scan
  for (std::size_t k = 0; k < 6; ++k) {
    const auto s = decode_scan(out[k + 1]);
    ASSERT_TRUE(s.has_value());
    EXPECT_EQ(s->ranges_mm, scans[k]);
    EXPECT_EQ(s->timestamp_ms, 1000 + 25 * k);
  }
}

TEST(ScipParser, MeScanWithIntensities) {
  const auto ranges = test::range_pattern(kMaxSteps, 3);
  std::vector<std::uint32_t> intens(kMaxSteps);
  for (std::size_t i = 0; i < kMaxSteps; ++i) intens[i] = static_cast<std::uint32_t>((i * 37) % 262144);
  const std::string bytes = test::scan_reply("ME0000108000000", "99", 77, ranges, intens);
  ReplyParser p;
  const auto out = test::parse_all(p, bytes);
  ASSERT_EQ(out.size(), 1U);
  ASSERT_EQ(out[0].lines.size(), 1U + 102U);  // 6486 characters: 101 full lines and one of 22
  EXPECT_EQ(out[0].lines.back().size(), 22U);
  EXPECT_LT(bytes.size(), kMaxReplyBytes);
  const auto s = decode_scan(out[0]);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->ranges_mm, ranges);
  EXPECT_EQ(s->intensities, intens);
  std::vector<Point2> pts;
  scan_to_points(*s, Geometry{}, pts);
  std::size_t valid = 0;
  for (std::size_t i = 0; i < kMaxSteps; ++i) valid += (ranges[i] >= 23 && ranges[i] <= 60000) ? 1U : 0U;
  ASSERT_EQ(pts.size(), valid);
  EXPECT_EQ(pts.front().intensity, intens[pts.front().step]);
}

TEST(ScipParser, ValueStraddlingTwoLines) {
  // 22 values = 66 characters: the 22nd value's first character ends line 1, the other two start line 2.
  std::vector<std::uint32_t> ranges(22);
  for (std::size_t i = 0; i < ranges.size(); ++i) ranges[i] = 1000 + static_cast<std::uint32_t>(i) * 4001;
  ReplyParser p;
  const auto out = test::parse_all(p, test::scan_reply("GD0000002100", "00", 5, ranges));
  ASSERT_EQ(out.size(), 1U);
  ASSERT_EQ(out[0].lines.size(), 3U);
  EXPECT_EQ(out[0].lines[1].size(), 64U);
  EXPECT_EQ(out[0].lines[2].size(), 2U);
  EXPECT_EQ(decode_scan(out[0])->ranges_mm, ranges);
}

TEST(ScipParser, ClusteredAndTwoCharacterScans) {
  // MD 0..1080 with cluster 3: ceil(1081 / 3) = 361 values, the step of value i is 3 i.
  const auto ranges = test::range_pattern(361, 5);
  ReplyParser p;
  auto out = test::parse_all(p, test::scan_reply("MD0000108003005", "99", 9, ranges));
  ASSERT_EQ(out.size(), 1U);
  const auto s = decode_scan(out[0]);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->cluster, 3);
  EXPECT_EQ(s->remaining_scans, 5);
  EXPECT_EQ(s->step_of(360), 1080);
  EXPECT_EQ(s->ranges_mm, ranges);

  std::vector<std::uint32_t> short_ranges = {0, 100, 4095};
  out = test::parse_all(p, test::scan_reply("GS0100010200", "00", 9, short_ranges, {}, 2));
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(decode_scan(out[0])->ranges_mm, short_ranges);
  EXPECT_EQ(values_in_scan(0, 1080, 0), 1081U);
  EXPECT_EQ(values_in_scan(0, 1080, 2), 541U);
}

TEST(ScipParser, ParametersVersionAndState) {
  ReplyParser p;
  const auto out = test::parse_all(p, test::utm_vv_reply() + test::utm_pp_reply() + test::utm_ii_reply());
  ASSERT_EQ(out.size(), 3U);
  EXPECT_EQ(p.counters().rejected(), 0U);
  // The PP lines are the documented ones, check characters included.
  EXPECT_EQ(test::utm_pp_reply().find("DMIN:23;7\n") != std::string::npos, true);
  EXPECT_EQ(test::utm_pp_reply().find("MODL:UTM-30LX-EW;I\n") != std::string::npos, true);
  const auto pp = decode_parameters(out[1]);
  ASSERT_TRUE(pp.has_value());
  EXPECT_EQ(pp->model, "UTM-30LX-EW");
  EXPECT_EQ(pp->dmin_mm, 23U);
  EXPECT_EQ(pp->dmax_mm, 60000U);
  EXPECT_EQ(pp->ares, 1440U);
  EXPECT_EQ(pp->amin, 0U);
  EXPECT_EQ(pp->amax, 1080U);
  EXPECT_EQ(pp->afrt, 540U);
  EXPECT_EQ(pp->scan_rpm, 2400U);
  const auto vv = decode_info(out[0]);
  ASSERT_TRUE(vv.has_value());
  EXPECT_EQ(vv->at("VEND"), "Hokuyo Automatic Co.,Ltd.");
  EXPECT_EQ(vv->at("PROT"), "SCIP 2.0");
  const auto ii = decode_info(out[2]);
  ASSERT_TRUE(ii.has_value());
  EXPECT_EQ(ii->at("STAT"), "Stable 000 no error.");
  EXPECT_EQ(decode_parameters(out[0]).error(), Error::NotThisReply);
}

TEST(ScipParser, CheckCharacterWithOrWithoutTheSemicolon) {
  ReplyParser p;
  const std::string reply =
      test::simple_reply("PP", "00", test::info_line("DMIN", "23", true) + test::info_line("DMAX", "60000"));
  const auto out = test::parse_all(p, reply);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(p.counters().rejected(), 0U);
  EXPECT_EQ(decode_info(out[0])->at("DMIN"), "23");
}

TEST(ScipParser, TagsAndScip11Status) {
  ReplyParser p;
  const auto out = test::parse_all(p, "SCIP2.0\n0\n\nVV;abc\n00P\n\n");
  ASSERT_EQ(out.size(), 2U);
  EXPECT_EQ(out[0].status, "0");
  EXPECT_EQ(out[0].category, StatusCategory::Scip11Ok);
  EXPECT_EQ(out[1].echo, "VV;abc");
  EXPECT_EQ(out[1].command, Command::VV);
}

TEST(ScipParser, ResynchronisesAfterGarbageAndAtAPlausibleEcho) {
  ReplyParser p;
  // Noise, a scan cut short (its empty line lost), then two good replies.
  std::string bytes = "\x01\x02 noise\n";
  const std::string scan = full_md_scan(1, test::range_pattern(kMaxSteps));
  std::string cut = scan.substr(0, 1000);
  cut[200] = static_cast<char>(cut[200] == '0' ? '1' : '0');  // breaks a check character
  bytes += cut + "\n" + scan + test::utm_pp_reply();
  const auto out = test::parse_all(p, bytes);
  ASSERT_EQ(out.size(), 2U);
  EXPECT_EQ(out[0].command, Command::MD);
  EXPECT_TRUE(decode_scan(out[0]).has_value());
  EXPECT_EQ(out[1].command, Command::PP);
  EXPECT_EQ(p.counters().errors[static_cast<std::size_t>(Error::MalformedLine)], 1U);
  EXPECT_EQ(p.counters().errors[static_cast<std::size_t>(Error::BadCheckCode)], 1U);
  EXPECT_GT(p.counters().discarded_bytes, 0U);
}

TEST(ScipParser, ResetForgetsAPartialReply) {
  ReplyParser p;
  std::vector<Reply> out;
  p.push(std::string_view(test::utm_pp_reply()).substr(0, 20), out);
  p.reset();
  p.push(test::utm_pp_reply(), out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(p.counters().rejected(), 0U);
}

TEST(ScipTimestamp, UnwrapsThe24BitClock) {
  TimestampUnwrapper u;
  EXPECT_EQ(u.unwrap(16'777'000), 16'777'000U);
  EXPECT_EQ(u.unwrap(16'777'215), 16'777'215U);
  EXPECT_EQ(u.unwrap(9), 16'777'216U + 9);
  EXPECT_EQ(u.unwrap(5), 16'777'216U + 5);  // a small step back is not a wrap
  EXPECT_EQ(u.unwrap(8'000'000), 16'777'216U + 8'000'000);
  EXPECT_EQ(u.unwrap(16'777'215), 16'777'216U + 16'777'215);
  EXPECT_EQ(u.unwrap(0), 2 * 16'777'216U);
  EXPECT_EQ(u.wraps(), 2U);
}

}  // namespace
}  // namespace fieldguard::scip
