// The command lines of every tool (tools/cli/cli.hpp): --help on stdout with exit code 0, and a bad command
// line on stderr, naming the option and what it takes, with exit code 2.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "tools/tools_test_support.hpp"

namespace fieldguard::tools_test {
namespace {

struct Tool {
  const char* binary;
  const char* name;
  const char* options;  // enough of the rest of a command line that only the bad option is wrong
};

const std::vector<Tool>& tools() {
  static const std::vector<Tool> all = {
      {FIELDGUARD_SIM, "fieldguard-sim", "--scene flat --pcap /nonexistent/x.pcap"},
      {FIELDGUARD_SCORE, "fieldguard-score", "--detections /nonexistent/d --truth /nonexistent/t"},
      {FIELDGUARD_DBC, "fieldguard-dbc", ""},
      {FIELDGUARD_SERIAL_EMULATOR, "fieldguard-serial-emulator", "--file /nonexistent/f"},
      {FIELDGUARD_SCIP_EMULATOR, "fieldguard-scip-emulator", ""},
      {FIELDGUARD_UDP_PLAYER, "fieldguard-udp-player", "--pcap /nonexistent/p"},
      {FIELDGUARD_NAV_EMULATOR, "fieldguard-nav-emulator", ""},
  };
  return all;
}

TEST(ToolCli, HelpGoesToStdoutWithExitZero) {
  for (const Tool& t : tools()) {
    for (const char* flag : {"--help", "-h"}) {
      const auto r = run(t.binary, flag);
      EXPECT_EQ(r.exit_code, 0) << t.name << " " << flag << "\n" << r.errors;
      EXPECT_EQ(r.output.rfind(std::string("usage: ") + t.name, 0), 0U) << r.output;
      EXPECT_NE(r.output.find("--help"), std::string::npos) << r.output;
      EXPECT_TRUE(r.errors.empty()) << r.errors;
    }
  }
}

TEST(ToolCli, UnknownOptionsAreNamedWithExitTwo) {
  for (const Tool& t : tools()) {
    for (const std::string& extra : {std::string("--bogus"), std::string("--bogus 1")}) {
      const auto r = run(t.binary, std::string(t.options) + " " + extra);
      EXPECT_EQ(r.exit_code, 2) << t.name << " " << extra;
      EXPECT_EQ(r.errors.rfind(std::string(t.name) + ": unknown option '--bogus'", 0), 0U) << r.errors;
      EXPECT_TRUE(r.output.empty()) << r.output;
    }
  }
}

TEST(ToolCli, ValuesOutOfRangeNameTheOptionAndTheRange) {
  struct Case {
    const char* binary;
    const char* args;
    const char* message;  // the start of stderr
  };
  const Case cases[] = {
      {FIELDGUARD_SIM, "--scene flat --pcap x.pcap --rate 40",
       "fieldguard-sim: --rate: wants a number of Hz from 5 to 20 (the HDL-32E's range), not '40'"},
      {FIELDGUARD_SIM, "--scene flat --pcap x.pcap --threads 65",
       "fieldguard-sim: --threads: wants a whole number from 0 to 64, not '65'"},
      {FIELDGUARD_SIM, "--scene flat --pcap x.pcap --seed -1",
       "fieldguard-sim: --seed: wants a whole number >= 0, not '-1'"},
      {FIELDGUARD_SIM, "--scene flat --pcap x.pcap --rotations 0x10",
       "fieldguard-sim: --rotations: wants a whole number >= 1, not '0x10'"},
      {FIELDGUARD_SCORE, "--detections d --truth t --min-overlap 1.5",
       "fieldguard-score: --min-overlap: wants a fraction from 0 to 1, not '1.5'"},
      {FIELDGUARD_SCORE, "--detections d --truth t --tolerance nan",
       "fieldguard-score: --tolerance: wants seconds > 0, not 'nan'"},
      {FIELDGUARD_DBC, "--source-address 0x100",
       "fieldguard-dbc: --source-address: wants an address 0..255 (decimal or 0x hex), not '0x100'"},
      {FIELDGUARD_SERIAL_EMULATOR, "--file f --hold-open 90000",
       "fieldguard-serial-emulator: --hold-open: wants a number from 0 to 86400, not '90000'"},
      {FIELDGUARD_SERIAL_EMULATOR, "--file f --loop 0",
       "fieldguard-serial-emulator: --loop: wants a whole number from 1 to 1000000, not '0'"},
      {FIELDGUARD_SCIP_EMULATOR, "--port 70000",
       "fieldguard-scip-emulator: --port: wants a whole number from 0 to 65535, not '70000'"},
      {FIELDGUARD_SCIP_EMULATOR, "--scene tree",
       "fieldguard-scip-emulator: --scene: wants wall or obstacle, not 'tree'"},
      {FIELDGUARD_UDP_PLAYER, "--pcap p --map 1:0",
       "fieldguard-udp-player: --map: wants FROM:TO ports (FROM 0..65535, TO 1..65535), not '1:0'"},
      {FIELDGUARD_UDP_PLAYER, "--pcap p --speed 2000",
       "fieldguard-udp-player: --speed: wants a number from 0 to 1000, not '2000'"},
      {FIELDGUARD_NAV_EMULATOR, "--gnss-rate 0",
       "fieldguard-nav-emulator: --gnss-rate: wants a number from 0.1 to 100, not '0'"},
      {FIELDGUARD_NAV_EMULATOR, "--fine-start 4294967296",
       "fieldguard-nav-emulator: --fine-start: wants a whole number from 0 to 4294967295, not '4294967296'"},
      {FIELDGUARD_NAV_EMULATOR, "--lat -90",
       "fieldguard-nav-emulator: --lat: wants a number from -89 to 89, not '-90'"},
  };
  for (const Case& c : cases) {
    const auto r = run(c.binary, c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args;
    EXPECT_EQ(r.errors.rfind(c.message, 0), 0U) << c.args << "\n" << r.errors;
  }
}

TEST(ToolCli, NegativeNumbersAreValues) {
  // Only the unknown option is wrong: -33.5, -20 and -1 are taken as the values they are.
  auto r = run(FIELDGUARD_NAV_EMULATOR, "--lat -33.5 --geoid -20 --bogus");
  EXPECT_EQ(r.errors.rfind("fieldguard-nav-emulator: unknown option '--bogus'", 0), 0U) << r.errors;
  r = run(FIELDGUARD_SCIP_EMULATOR, "--drop-after -1 --bogus");
  EXPECT_EQ(r.errors.rfind("fieldguard-scip-emulator: unknown option '--bogus'", 0), 0U) << r.errors;
}

TEST(ToolCli, AnOptionGivenTwiceCountsTheLastTimeAndEachIsChecked) {
  auto r = run(FIELDGUARD_SCORE, "--detections /nonexistent/d --truth /nonexistent/t --truth /nonexistent/u");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.errors.find("cannot open /nonexistent/u"), std::string::npos) << r.errors;  // the truth is read first
  // (--gnss-baud 300 is too slow for the epochs: the emulator stops there, should the check let 400 pass.)
  r = run(FIELDGUARD_NAV_EMULATOR, "--heading 400 --heading 10 --gnss-baud 300");
  EXPECT_EQ(r.errors.rfind("fieldguard-nav-emulator: --heading: wants a number from 0 to 360, not '400'", 0), 0U)
      << r.errors;
}

TEST(ToolCli, AMissingValueIsNamed) {
  const std::pair<const char*, const char*> cases[] = {{FIELDGUARD_SIM, "--scene"},
                                                       {FIELDGUARD_SCORE, "--detections"},
                                                       {FIELDGUARD_DBC, "--source-address"},
                                                       {FIELDGUARD_SERIAL_EMULATOR, "--file"},
                                                       {FIELDGUARD_SCIP_EMULATOR, "--port"},
                                                       {FIELDGUARD_UDP_PLAYER, "--pcap"},
                                                       {FIELDGUARD_NAV_EMULATOR, "--gnss-link"}};
  for (const auto& [binary, option] : cases) {
    const auto r = run(binary, option);
    EXPECT_EQ(r.exit_code, 2) << binary << " " << option;
    EXPECT_NE(r.errors.find(std::string(": ") + option + ": "), std::string::npos) << r.errors;
  }
}

}  // namespace
}  // namespace fieldguard::tools_test
