// config/fieldguard.dbc read by an independent DBC library, Debian's python3-canmatrix
// (tests/interop/dbc_canmatrix.py): it decodes a replay's CAN log, FG_OBSTACLE multiplexed on Index, to the
// obstacles of the same replay's JSONL, several per frame on the simulator's farmyard.

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "app/json_reader.hpp"
#include "app/run_command.hpp"
#include "app/sim_can_support.hpp"

namespace fieldguard {
namespace {

using testing::Json;
using testing::run_fieldguard;
using testing::run_shell;

const std::string kSource = FIELDGUARD_SOURCE_DIR;

TEST(DbcInterop, CanmatrixDecodesTheLogToTheReplaysObstacles) {
  testing::TempDir dir;
  const std::string pcap = (dir.path() / "farm.pcap").string();
  ASSERT_EQ(std::system(
                ("'" + std::string(FIELDGUARD_SIM) + "' --scene farmyard --rotations 12 --quiet --pcap '" + pcap + "'")
                    .c_str()),
            0);
  const std::string log = (dir.path() / "can.log").string();
  const std::string jsonl = (dir.path() / "o.jsonl").string();
  const auto r = run_fieldguard("replay --quiet --config '" + kSource + "/config/fieldguard.yaml' --pcap '" + pcap +
                                "' --can-log '" + log + "' --obstacles-out '" + jsonl + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto c = run_shell("/usr/bin/python3 '" + kSource + "/tests/interop/dbc_canmatrix.py' '" + kSource +
                           "/config/fieldguard.dbc' '" + log + "' '" + jsonl + "' 2>/dev/null");
  ASSERT_EQ(c.exit_code, 0) << "python3-canmatrix (tools/install-deps installs it): " << c.output;
  const Json s = Json::parse(c.output);
  EXPECT_GE(s.at("summaries").get<int>(), 10);
  // More obstacle messages than frames: indexes past 0, each decoded under its own multiplexed names.
  EXPECT_GT(s.at("obstacles").get<int>(), s.at("summaries").get<int>());
}

}  // namespace
}  // namespace fieldguard
