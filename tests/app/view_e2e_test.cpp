// The live view of the real daemon (`view:`), fed by the simulator's pedestrian capture played over loopback UDP:
//   - a Node client built on @foxglove/ws-protocol (tests/interop/node/ws_client.mjs) subscribes to every
//     channel and gets messages that validate against @foxglove/schemas, with the decisions the daemon recorded;
//   - clients that send garbage or stop reading do not change a single decision (against a run without them);
//   - headless Chromium shows the status page red with STOP while the pedestrian is in the zone, green with GO
//     after it left.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app/child_process.hpp"
#include "app/json_reader.hpp"
#include "app/run_command.hpp"
#include "app/sim_can_support.hpp"
#include "fieldguard/writers/mcap_recorder.hpp"

namespace fieldguard {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using testing::free_udp_port;
using testing::Json;
using testing::Process;
using testing::replaced;
using testing::run_shell;
using testing::slurp;

const std::string kSource = FIELDGUARD_SOURCE_DIR;
const std::string kNode = kSource + "/tests/interop/node/";

// The shipped configuration with the LiDAR on `port`, no CAN bus, the view's server on a port the kernel chooses,
// and the stop zone `half_width` m to each side.
fs::path write_config(const fs::path& dir, std::uint16_t port, const std::string& half_width = "2.0") {
  std::string text = slurp(kSource + "/config/fieldguard.yaml");
  text = replaced(text, "data_port: 2368 ", "data_port: " + std::to_string(port) + " ");
  // model auto listens on the RS-32's ports too: free ones, for tests running side by side.
  text = replaced(text, "msop_port: 6699 ", "msop_port: " + std::to_string(testing::free_udp_port()) + " ");
  text = replaced(text, "difop_port: 7788 ", "difop_port: " + std::to_string(testing::free_udp_port()) + " ");
  text = replaced(text, "\n  sink: socketcan ", "\n  sink: none ");
  text = replaced(text, "\n    half_width_m: 2.0 ", "\n    half_width_m: " + half_width + " ");
  text = replaced(text, "\n    enabled: false               # true | false", "\n    enabled: true");
  text = replaced(text, "\n    port: 8765 ", "\n    port: 0 ");
  text = replaced(text, "\n    max_clients: 4 ", "\n    max_clients: 3 ");
  const auto p = dir / "run.yaml";
  std::ofstream(p) << text;
  return p;
}

// The port in the daemon's "live view on http://127.0.0.1:PORT/" line.
std::uint16_t view_port(const std::string& output) {
  std::smatch m;
  if (!std::regex_search(output, m, std::regex(R"(live view on http://127\.0\.0\.1:(\d+)/)"))) return 0;
  return static_cast<std::uint16_t>(std::stoi(m[1]));
}

// GET `path` from the daemon's server; the body, or "" when it does not answer.
std::string http_get(std::uint16_t port, const std::string& path) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return {};
  }
  const std::string req = "GET " + path + " HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n";
  if (::send(fd, req.data(), req.size(), 0) != static_cast<ssize_t>(req.size())) {
    ::close(fd);
    return {};
  }
  std::string got;
  char buf[4096];
  for (ssize_t n = 0; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;) got.append(buf, static_cast<std::size_t>(n));
  ::close(fd);
  const auto body = got.find("\r\n\r\n");
  return body == std::string::npos ? std::string() : got.substr(body + 4);
}

// "N <label>" on the summary's view line; -1 when it is not there.
long long view_count(const std::string& summary, const std::string& label) {
  const auto line = summary.find("\n  view ");
  std::smatch m;
  const std::string rest =
      line == std::string::npos ? std::string() : summary.substr(line, summary.find('\n', line + 1) - line);
  if (!std::regex_search(rest, m, std::regex("(\\d+) " + label))) return -1;
  return std::stoll(m[1]);
}

std::optional<bool> page_stop(std::uint16_t port) {
  const Json j = Json::parse(http_get(port, "/status.json"), nullptr, false);
  if (j.is_discarded() || !j.contains("stop")) return std::nullopt;
  return j["stop"].get<bool>();
}

// Each frame's decision (stop, reason) from an MCAP recording, as @mcap/core read it.
std::map<long long, std::pair<bool, std::string>> recorded_decisions(const std::string& mcap, const fs::path& dir) {
  const std::string dump = (dir / "decisions.jsonl").string();
  const auto r =
      run_shell("node '" + kNode + "mcap_check.mjs' '" + mcap + "' --dump /safety/decision '" + dump + "' 2>&1");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::map<long long, std::pair<bool, std::string>> out;
  std::ifstream in(dump);
  for (std::string line; std::getline(in, line);) {
    const Json j = Json::parse(line);
    if (j.at("on") != "frame") continue;  // the decisions taken on the clock between frames
    out[j.at("frame").get<long long>()] = {j.at("stop").get<bool>(), j.at("reason").get<std::string>()};
  }
  return out;
}

class ViewE2e : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    capture_ = std::make_unique<testing::PedestrianCapture>(120);
    ASSERT_TRUE(capture_->ok) << capture_->command;
  }
  static void TearDownTestSuite() { capture_.reset(); }

  // The daemon on `config`, recording to `mcap`; its view port once it listens.
  std::unique_ptr<Process> start_daemon(const fs::path& config, const std::string& mcap, const std::string& name,
                                        std::uint16_t& port) {
    auto d = std::make_unique<Process>(
        std::vector<std::string>{FIELDGUARD_BINARY, "run", "--config", config.string(), "--mcap-out", mcap},
        dir.path() / (name + ".out"));
    EXPECT_TRUE(d->wait_for("listening for the 3D LiDAR", 20s)) << d->output();
    port = view_port(d->output());
    EXPECT_NE(port, 0) << d->output();
    return d;
  }
  // SIGTERM and the summary.
  static std::string stop_daemon(Process& d) {
    ::kill(d.pid(), SIGTERM);
    EXPECT_EQ(d.exited(10s), std::optional<int>(0)) << d.output();
    return d.output();
  }
  Process player(std::uint16_t port, const std::string& name, const std::string& pcap = capture_->pcap) {
    return Process({FIELDGUARD_UDP_PLAYER, "--pcap", pcap, "--map", "2368:" + std::to_string(port)},
                   dir.path() / (name + ".player"));
  }

  testing::TempDir dir;
  static std::unique_ptr<testing::PedestrianCapture> capture_;
};
std::unique_ptr<testing::PedestrianCapture> ViewE2e::capture_;

TEST_F(ViewE2e, FoxgloveClientGetsEveryChannelValidAndTheRecordedDecisions) {
  const std::uint16_t lidar = free_udp_port();
  const std::string mcap = (dir.path() / "run.mcap").string();
  std::uint16_t port = 0;
  auto daemon = start_daemon(write_config(dir.path(), lidar), mcap, "daemon", port);
  ASSERT_NE(port, 0);
  Process play = player(lidar, "play");
  const std::string dump = (dir.path() / "ws_decisions.jsonl").string();
  const auto client = run_shell("node '" + kNode + "ws_client.mjs' ws://127.0.0.1:" + std::to_string(port) +
                                " --seconds 40 --until-topic /safety/decision:60 --until-topic /detection/points:60" +
                                " --dump /safety/decision '" + dump + "' 2>&1");
  EXPECT_EQ(play.exited(60s), std::optional<int>(0)) << play.output();
  const std::string summary = stop_daemon(*daemon);
  ASSERT_EQ(client.exit_code, 0) << "@foxglove/ws-protocol (tools/install-deps installs it): " << client.output;
  const Json s = Json::parse(client.output.substr(client.output.find('{')));
  EXPECT_EQ(s.at("serverInfo").at("name"), "fieldguard");
  for (const char* topic : {"/lidar/points", "/detection/points", "/detection/obstacles", "/detection/zones",
                            "/safety/decision", "/health"}) {
    EXPECT_GT(s.at("messages").value(topic, 0), 0) << topic << ": " << client.output;
  }
  // What the client decoded is what the daemon decided and recorded, frame by frame, and it saw a stop for the
  // pedestrian.
  // `run --mcap-out` writes a bounded series: its first file (one, at this length).
  const auto recorded = recorded_decisions(app::McapRecorder::numbered(mcap, 1), dir.path());
  std::ifstream in(dump);
  int compared = 0;
  bool obstacle_stop = false;
  for (std::string line; std::getline(in, line);) {
    const Json j = Json::parse(line);
    if (j.at("on") != "frame") continue;
    const long long frame = j.at("frame").get<long long>();
    const auto it = recorded.find(frame);
    ASSERT_NE(it, recorded.end()) << "frame " << frame << " not recorded";
    EXPECT_EQ(it->second.first, j.at("stop").get<bool>()) << line;
    EXPECT_EQ(it->second.second, j.at("reason").get<std::string>()) << line;
    obstacle_stop = obstacle_stop || j.at("reason") == "obstacle in zone";
    ++compared;
  }
  EXPECT_GE(compared, 50) << summary;  // the client stopped at 60 decisions, a few of them taken on the clock
  EXPECT_TRUE(obstacle_stop) << "no stop for the pedestrian among the decisions the client received";
  EXPECT_NE(summary.find("view              "), std::string::npos) << summary;
}

TEST_F(ViewE2e, HostileAndStalledClientsChangeNoDecision) {
  // The same capture twice: alone, then with a client that sends garbage (and one over the size limit), one that
  // subscribes to everything and stops reading, and more connections than max_clients. Frame by frame, the
  // decisions are the same.
  std::map<long long, std::pair<bool, std::string>> decisions[2];
  std::string summaries[2];
  for (int run = 0; run < 2; ++run) {
    const std::uint16_t lidar = free_udp_port();
    const fs::path sub = dir.path() / std::to_string(run);
    fs::create_directories(sub);
    const std::string mcap = (sub / "run.mcap").string();
    std::uint16_t port = 0;
    auto daemon = start_daemon(write_config(sub, lidar), mcap, "daemon" + std::to_string(run), port);
    ASSERT_NE(port, 0);
    const std::string url = "ws://127.0.0.1:" + std::to_string(port);
    std::vector<std::unique_ptr<Process>> clients;
    if (run == 1) {
      for (const char* mode : {"stall", "garbage"}) {
        clients.push_back(std::make_unique<Process>(
            std::vector<std::string>{"/usr/bin/env", "node", kNode + "ws_hostile.mjs", url, mode, "--seconds", "15"},
            sub / (std::string(mode) + ".out")));
      }
      std::this_thread::sleep_for(1s);  // connected before the first rotation
    }
    Process play = player(lidar, "play" + std::to_string(run));
    if (run == 1) {
      const auto flood = run_shell("node '" + kNode + "ws_hostile.mjs' " + url + " flood-connect 6 2>&1");
      EXPECT_EQ(flood.exit_code, 0) << flood.output;
    }
    EXPECT_EQ(play.exited(60s), std::optional<int>(0)) << play.output();
    for (auto& c : clients) {
      EXPECT_EQ(c->exited(30s), std::optional<int>(0)) << c->output();
    }
    summaries[run] = stop_daemon(*daemon);
    decisions[run] = recorded_decisions(app::McapRecorder::numbered(mcap, 1), sub);
  }
  ASSERT_GE(decisions[0].size(), 100U) << summaries[0];
  EXPECT_EQ(decisions[0], decisions[1]) << summaries[0] << "\n" << summaries[1];
  // The hostile clients were there and were answered: bad messages counted, the stalled client's queue dropped.
  const std::string& s = summaries[1];
  EXPECT_GT(view_count(s, "bad client messages"), 0) << s;
  EXPECT_GT(view_count(s, "refused"), 0) << s;
  EXPECT_GT(view_count(s, "dropped"), 0) << s;
}

TEST_F(ViewE2e, StatusPageInChromiumIsStopWhileThePedestrianIsInTheZoneAndGoAfter) {
  // A longer capture, so that a crossing's stop and go each last seconds: a wide zone (8 m) that the pedestrian
  // needs about 3 s to cross, at 5 m, 10 m, ... ahead.
  testing::PedestrianCapture capture(360);
  ASSERT_TRUE(capture.ok) << capture.command;
  const std::uint16_t lidar = free_udp_port();
  std::uint16_t port = 0;
  auto daemon =
      start_daemon(write_config(dir.path(), lidar, "4.0"), (dir.path() / "run.mcap").string(), "daemon", port);
  ASSERT_NE(port, 0);
  Process play = player(lidar, "play", capture.pcap);
  const std::string url = "http://127.0.0.1:" + std::to_string(port) + "/";
  // For each state: wait for it in status.json, screenshot the page, and keep the shot only if the daemon was in
  // that state before and after it (a state may end while Chromium draws).
  for (const bool stop : {true, false}) {
    bool shown = false;
    for (int attempt = 0; attempt < 12 && !shown; ++attempt) {
      const auto until = std::chrono::steady_clock::now() + 20s;
      while (page_stop(port) != std::optional<bool>(stop) && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(50ms);
      ASSERT_EQ(page_stop(port), std::optional<bool>(stop)) << "the daemon never decided " << (stop ? "STOP" : "GO");
      const std::string shot = (dir.path() / (std::string(stop ? "stop" : "go") + ".png")).string();
      const auto r = run_shell(
          "chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=800,1000 "
          "--virtual-time-budget=1500 --screenshot='" +
          shot + "' '" + url + "' 2>&1");
      ASSERT_EQ(r.exit_code, 0) << "Debian's chromium (tools/install-deps installs it): " << r.output;
      if (page_stop(port) != std::optional<bool>(stop)) continue;
      // The decision band across the top of the page: red for STOP, green for GO.
      const auto c = run_shell("python3 '" + kSource + "/tests/interop/png_region.py' '" + shot + "' 100 20 700 80");
      ASSERT_EQ(c.exit_code, 0) << c.output;
      int r8 = 0, g8 = 0, b8 = 0;
      std::istringstream(c.output) >> r8 >> g8 >> b8;
      if (stop) {
        EXPECT_GT(r8, 150) << c.output;
        EXPECT_LT(g8, 90) << c.output;
      } else {
        EXPECT_GT(g8, 100) << c.output;
        EXPECT_LT(r8, 90) << c.output;
      }
      shown = true;
    }
    EXPECT_TRUE(shown) << "the daemon never stayed " << (stop ? "STOP" : "GO") << " long enough for a screenshot";
  }
  // The page's text, as Chromium leaves it after its script ran: the decision and each sensor.
  const auto dom = run_shell("chromium --headless --no-sandbox --disable-gpu --virtual-time-budget=1500 --dump-dom '" +
                             url + "' 2>/dev/null");
  EXPECT_NE(dom.output.find("<td>lidar</td>"), std::string::npos) << dom.output;
  EXPECT_NE(dom.output.find("<td class=\"off\">off</td>"), std::string::npos) << dom.output;
  EXPECT_TRUE(std::regex_search(dom.output, std::regex(R"re(id="decision" class="(stop|go)">(STOP|GO))re")))
      << dom.output;
  // The player stopped, the LiDAR falls silent: the page says STOP with no frame to carry the news.
  ::kill(play.pid(), SIGTERM);
  std::string headline;
  for (const auto until = std::chrono::steady_clock::now() + 10s;
       headline.find("lidar silent") == std::string::npos && std::chrono::steady_clock::now() < until;) {
    std::this_thread::sleep_for(100ms);
    const Json j = Json::parse(http_get(port, "/status.json"), nullptr, false);
    if (!j.is_discarded() && j.contains("headline")) headline = j["headline"].get<std::string>();
  }
  EXPECT_EQ(headline.rfind("STOP lidar silent", 0), 0U) << headline;
  stop_daemon(*daemon);
}

}  // namespace
}  // namespace fieldguard
