// SCIP 2.0 client state machine: the start-up sequence, streaming, stop and reset, refusals.
#include "fieldguard/drivers/scip_client.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "drivers/scip_test_support.hpp"

namespace fieldguard::scip {
namespace {

// Feeds the sensor's bytes through a parser into the client and returns the events.
std::vector<ClientEvent> feed(Client& client, ReplyParser& parser, const std::string& bytes) {
  std::vector<Reply> replies;
  parser.push(bytes, replies);
  std::vector<ClientEvent> events;
  for (const auto& r : replies) events.push_back(client.on_reply(r));
  return events;
}

ClientEvent one(Client& client, ReplyParser& parser, const std::string& bytes) {
  auto events = feed(client, parser, bytes);
  EXPECT_EQ(events.size(), 1U);
  return events.empty() ? ClientEvent{} : events.front();
}

// Start, then the sensor's answers to SCIP2.0, VV, PP and II: the client asks for the laser next (BM).
void identify(Client& c, ReplyParser& p) {
  (void)c.start();
  (void)one(c, p, test::simple_reply("SCIP2.0", "00"));
  (void)one(c, p, test::utm_vv_reply());
  (void)one(c, p, test::utm_pp_reply());
  (void)one(c, p, test::utm_ii_reply());
}

// Runs the sequence up to Streaming; returns the command lines the client sent.
std::vector<std::string> start_up(Client& c, ReplyParser& p, const std::string& md_echo) {
  std::vector<std::string> sent = {c.start()};
  sent.push_back(one(c, p, test::simple_reply("SCIP2.0", "00")).send);
  sent.push_back(one(c, p, test::utm_vv_reply()).send);
  sent.push_back(one(c, p, test::utm_pp_reply()).send);
  sent.push_back(one(c, p, test::utm_ii_reply()).send);
  sent.push_back(one(c, p, test::simple_reply("BM", "00")).send);
  sent.push_back(one(c, p, test::simple_reply(md_echo, "00")).send);
  return sent;
}

TEST(ScipClient, StartUpStreamAndStop) {
  Client c;
  ReplyParser p;
  EXPECT_EQ(c.state(), ClientState::Idle);
  const auto sent = start_up(c, p, "MD0000108001000");
  EXPECT_EQ(sent, (std::vector<std::string>{"SCIP2.0\n", "VV\n", "PP\n", "II\n", "BM\n", "MD0000108001000\n", ""}));
  EXPECT_EQ(c.state(), ClientState::Streaming);
  EXPECT_EQ(c.version().at("PROD"), "SOKUIKI Sensor UTM-30LX-EW");
  ASSERT_TRUE(c.parameters().has_value());
  EXPECT_EQ(c.parameters()->afrt, 540U);
  EXPECT_EQ(c.sensor_state().at("LASR"), "OFF");
  EXPECT_DOUBLE_EQ(c.geometry().steps_per_turn, 1440.0);

  const auto ranges = test::range_pattern(kMaxSteps);
  auto e = one(c, p, test::scan_reply("MD0000108001000", "99", 4242, ranges));
  ASSERT_TRUE(e.scan.has_value());
  EXPECT_EQ(e.scan->ranges_mm, ranges);
  EXPECT_EQ(e.scan->timestamp_ms, 4242U);
  EXPECT_TRUE(e.send.empty());

  EXPECT_EQ(c.stop(), "QT\n");
  EXPECT_EQ(c.state(), ClientState::Stopping);
  e = one(c, p, test::scan_reply("MD0000108001000", "99", 4267, ranges));  // already on its way
  EXPECT_TRUE(e.scan.has_value());
  e = one(c, p, test::simple_reply("QT", "00"));
  EXPECT_FALSE(e.refused.has_value());
  EXPECT_EQ(c.state(), ClientState::Stopped);
  EXPECT_EQ(c.counters().scans, 2U);
  EXPECT_EQ(c.counters().unexpected_replies, 0U);
}

TEST(ScipClient, IntensityScansAndReset) {
  ClientConfig cfg;
  cfg.intensity = true;
  cfg.scan = ScanRequest{0, 1080, 0, 0, 0};
  Client c(cfg);
  ReplyParser p;
  const auto sent = start_up(c, p, "ME0000108000000");
  EXPECT_EQ(sent[5], "ME0000108000000\n");
  const auto ranges = test::range_pattern(kMaxSteps);
  auto e = one(c, p, test::scan_reply("ME0000108000000", "99", 1, ranges, ranges));
  ASSERT_TRUE(e.scan.has_value());
  EXPECT_EQ(e.scan->intensities, ranges);
  EXPECT_EQ(c.reset(), "RS\n");
  e = one(c, p, test::simple_reply("RS", "00"));
  EXPECT_EQ(c.state(), ClientState::Stopped);
}

TEST(ScipClient, Scip11AndScip20OnlySensorsBothProceed) {
  for (const std::string& reply : {std::string("SCIP2.0\n0\n\n"), test::simple_reply("SCIP2.0", "0E")}) {
    Client c;
    ReplyParser p;
    (void)c.start();
    const auto e = one(c, p, reply);
    EXPECT_EQ(e.send, "VV\n");
    EXPECT_EQ(c.state(), ClientState::ReadingVersion);
  }
}

TEST(ScipClient, LaserAlreadyOnIsFine) {
  Client c;
  ReplyParser p;
  identify(c, p);
  const auto e = one(c, p, test::simple_reply("BM", "02"));
  EXPECT_EQ(e.send, "MD0000108001000\n");
}

TEST(ScipClient, RefusalsSayWhichCommandAndStatus) {
  {
    Client c;
    ReplyParser p;
    identify(c, p);
    const auto e = one(c, p, test::simple_reply("BM", "01"));
    ASSERT_TRUE(e.refused.has_value());
    EXPECT_EQ(e.refused->command, Command::BM);
    EXPECT_EQ(e.refused->status, "01");
    EXPECT_EQ(e.refused->text, "laser could not be lit (unstable or abnormal condition)");
    EXPECT_TRUE(e.send.empty());
    EXPECT_EQ(c.state(), ClientState::Failed);
    EXPECT_TRUE(c.failure().has_value());
    // Nothing more happens until start() again.
    EXPECT_TRUE(one(c, p, test::simple_reply("BM", "00")).send.empty());
    EXPECT_EQ(c.counters().unexpected_replies, 1U);
    EXPECT_EQ(c.start(), "SCIP2.0\n");
    EXPECT_FALSE(c.failure().has_value());
  }
  {
    ReplyParser p;
    Client c2;
    (void)c2.start();
    (void)one(c2, p, test::simple_reply("SCIP2.0", "00"));
    (void)one(c2, p, test::utm_vv_reply());
    (void)one(c2, p, test::utm_pp_reply());
    (void)one(c2, p, test::utm_ii_reply());
    (void)one(c2, p, test::simple_reply("BM", "00"));
    const auto e = one(c2, p, test::simple_reply("MD0000108001000", "04"));
    ASSERT_TRUE(e.refused.has_value());
    EXPECT_EQ(e.refused->command, Command::MD);
    EXPECT_EQ(e.refused->text, "end step out of range");
  }
  {
    Client c;
    ReplyParser p;
    (void)c.start();
    const auto e = one(c, p, test::simple_reply("SCIP2.0", "0L"));
    ASSERT_TRUE(e.refused.has_value());
    EXPECT_EQ(e.refused->text, "sensor in an abnormal state");
  }
}

TEST(ScipClient, UnreadableParametersStopTheSequence) {
  Client c;
  ReplyParser p;
  (void)c.start();
  (void)one(c, p, test::simple_reply("SCIP2.0", "00"));
  (void)one(c, p, test::utm_vv_reply());
  const auto e = one(c, p, test::simple_reply("PP", "00", test::info_line("DMIN", "23")));
  ASSERT_TRUE(e.refused.has_value());
  EXPECT_EQ(e.refused->command, Command::PP);
  EXPECT_EQ(e.error, Error::BadField);
  EXPECT_EQ(c.state(), ClientState::Failed);
  EXPECT_EQ(c.counters().errors[static_cast<std::size_t>(Error::BadField)], 1U);
}

TEST(ScipClient, SensorTroubleStaleRepliesAndBadScans) {
  Client c;
  ReplyParser p;
  (void)start_up(c, p, "MD0000108001000");
  auto e = one(c, p, test::simple_reply("MD0000108001000", "55"));
  EXPECT_EQ(e.sensor_status, "55");
  e = one(c, p, test::simple_reply("MD0000108001000", "98"));
  EXPECT_EQ(e.sensor_status, "98");
  e = one(c, p, test::utm_vv_reply());  // not in flight
  EXPECT_FALSE(e.scan.has_value());
  e = one(c, p, test::scan_reply("MD0000108001000", "99", 1, {1, 2, 3}));  // too few values
  EXPECT_EQ(e.error, Error::BadDataLength);
  const auto& k = c.counters();
  EXPECT_EQ(k.sensor_trouble, 1U);
  EXPECT_EQ(k.resumed, 1U);
  EXPECT_EQ(k.unexpected_replies, 1U);
  EXPECT_EQ(k.errors[static_cast<std::size_t>(Error::BadDataLength)], 1U);
  EXPECT_EQ(c.state(), ClientState::Streaming);
}

TEST(ScipClient, ScansBeforeTheAcknowledgementStartTheStream) {
  Client c;
  ReplyParser p;
  identify(c, p);
  (void)one(c, p, test::simple_reply("BM", "00"));
  const auto e = one(c, p, test::scan_reply("MD0000108001000", "99", 1, test::range_pattern(kMaxSteps)));
  EXPECT_TRUE(e.scan.has_value());
  EXPECT_EQ(c.state(), ClientState::Streaming);
  EXPECT_EQ(to_string(c.state()), "streaming");
}

TEST(ScipClient, BadScanRequestThrows) {
  ClientConfig cfg;
  cfg.scan.cluster = 120;
  EXPECT_THROW(Client{cfg}, std::invalid_argument);
}

}  // namespace
}  // namespace fieldguard::scip
