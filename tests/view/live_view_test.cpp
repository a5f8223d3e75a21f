// The live view's threads together: frames handed over by a producer thread (the daemon's io thread), encoded and
// recorded on the view's thread, served by the server's thread to WebSocket clients on theirs. Run under
// ThreadSanitizer in CI (ctest label `view`). A Boost.Beast client speaks the Foxglove protocol as a viewer does.

#include "daemon/live_view.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "fieldguard/writers/mcap_recorder.hpp"

namespace fieldguard::app {
namespace {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;
using Json = nlohmann::json;
using namespace std::chrono_literals;

DetectedFrame frame(std::uint64_t i) {
  DetectedFrame d;
  d.frame.index = i;
  d.frame.host_stamp.ns = 1'700'000'000'000'000'000 + static_cast<std::int64_t>(i) * 100'000'000;
  d.frame.points.resize(3000);
  for (std::size_t k = 0; k < d.frame.points.size(); ++k) d.frame.points[k].x = static_cast<float>(k) * 0.01F;
  d.labelled.resize(500);
  perception::Obstacle o;
  o.min = {5.F, -0.3F, -0.9F};
  o.max = {5.4F, 0.3F, 0.8F};
  o.obb_length_m = 0.4F;
  o.obb_width_m = 0.6F;
  d.result.obstacles.push_back(o);
  return d;
}

output::safety::Decision decision(bool stop) {
  output::safety::Decision d;
  d.stop = stop;
  d.reason = stop ? output::safety::Reason::ObstacleInZone : output::safety::Reason::None;
  d.zone = {0.4, 12.0, 2.0, false};
  return d;
}

// A Foxglove client: connects with the subprotocol, subscribes to `topics`, counts MESSAGE_DATA frames.
class Client {
 public:
  Client(std::uint16_t port, std::vector<std::string> topics, bool read_data = true)
      : topics_(std::move(topics)), read_data_(read_data) {
    ws_.set_option(websocket::stream_base::decorator([](websocket::request_type& r) {
      r.set(beast::http::field::sec_websocket_protocol, "foxglove.websocket.v1");
    }));
    net::connect(ws_.next_layer(), tcp::resolver(io_).resolve("127.0.0.1", std::to_string(port)));
    ws_.handshake("127.0.0.1", "/");
    beast::flat_buffer b;
    ws_.read(b);  // serverInfo
    server_info_ = Json::parse(beast::buffers_to_string(b.data()));
    b.consume(b.size());
    ws_.read(b);  // advertise
    const Json adv = Json::parse(beast::buffers_to_string(b.data()));
    Json sub = {{"op", "subscribe"}, {"subscriptions", Json::array()}};
    for (const Json& ch : adv.at("channels")) {
      for (const auto& t : topics_) {
        if (ch.at("topic") == t) sub["subscriptions"].push_back({{"id", ch.at("id")}, {"channelId", ch.at("id")}});
      }
    }
    ws_.write(net::buffer(sub.dump()));
    if (read_data_) reader_ = std::thread([this] { read(); });
  }
  ~Client() {
    // Shut down (the reader's recv returns), join the reader, and only then close: closing a descriptor another
    // thread is reading is a race.
    beast::error_code ec;
    ws_.next_layer().shutdown(tcp::socket::shutdown_both, ec);
    if (reader_.joinable()) reader_.join();
    ws_.next_layer().close(ec);
  }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  [[nodiscard]] int messages() const { return messages_.load(); }
  [[nodiscard]] const Json& server_info() const { return server_info_; }

 private:
  void read() {
    beast::flat_buffer b;
    beast::error_code ec;
    while (!ec) {
      ws_.read(b, ec);
      if (!ec && !ws_.got_text() && b.size() >= 13 && static_cast<const char*>(b.data().data())[0] == 1) ++messages_;
      b.consume(b.size());
    }
  }

  std::vector<std::string> topics_;
  bool read_data_;
  net::io_context io_;
  websocket::stream<tcp::socket> ws_{io_};
  Json server_info_;
  std::atomic<int> messages_{0};
  std::thread reader_;
};

Config view_config(const std::filesystem::path& dir) {
  Config c;
  c.view.server = true;
  c.view.port = 0;
  c.view.max_clients = 4;
  c.view.client_queue = 8;
  c.view.mcap_path = (dir / "v.mcap").string();
  return c;
}

class LiveViewTest : public ::testing::Test {
 protected:
  std::filesystem::path dir_ =
      std::filesystem::temp_directory_path() /
      ("fg_view_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  void SetUp() override { std::filesystem::create_directories(dir_); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
};

TEST_F(LiveViewTest, FramesFromAnotherThreadReachTheRecordingAndAReadingClient) {
  const Config cfg = view_config(dir_);
  LiveViewCounts counts;
  {
    LiveView view(cfg);
    ASSERT_TRUE(view.port().has_value());
    Client client(*view.port(), {"/safety/decision", "/detection/obstacles"});
    EXPECT_EQ(client.server_info().at("name"), "fieldguard");
    std::thread producer([&view] {
      for (std::uint64_t i = 0; i < 60; ++i) {
        view.frame(frame(i), decision(i % 2 == 0));
        if (i % 10 == 0)
          view.status(decision(true), Stamp{static_cast<std::int64_t>(i)}, {{"lidar", "ok", 10.0}}, "line");
        std::this_thread::sleep_for(5ms);
      }
    });
    producer.join();
    // Waits, never a timing verdict: under ThreadSanitizer on a loaded machine the messages take their time.
    for (int k = 0; k < 3000 && client.messages() < 20; ++k) std::this_thread::sleep_for(10ms);
    EXPECT_GE(client.messages(), 20);
    // Every frame the view accepted is recorded once its thread has drained the ring (the counts lag until then).
    for (int k = 0; k < 3000; ++k) {
      counts = view.counts();
      if (counts.mcap.frames + counts.dropped == 60U) break;
      std::this_thread::sleep_for(10ms);
    }
  }
  EXPECT_EQ(counts.frames, 60U);
  EXPECT_GT(counts.mcap.frames, 0U);
  EXPECT_EQ(counts.mcap.frames + counts.dropped, 60U);
  // The recording was closed whole when the view went.
  std::ifstream in(McapRecorder::numbered(cfg.view.mcap_path, 1), std::ios::binary);
  const std::string f{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  ASSERT_GT(f.size(), 16U);
  EXPECT_EQ(f.substr(f.size() - 8), std::string("\x89MCAP0\r\n", 8));
}

TEST_F(LiveViewTest, AClientThatNeverReadsLosesItsOwnMessagesOnly) {
  const Config cfg = view_config(dir_);
  LiveView view(cfg);
  ASSERT_TRUE(view.port().has_value());
  Client stalled(*view.port(), {"/lidar/points", "/detection/points"}, false);
  Client reading(*view.port(), {"/safety/decision"});
  for (std::uint64_t i = 0; i < 200; ++i) {
    view.frame(frame(i), decision(false));
    std::this_thread::sleep_for(2ms);
  }
  for (int k = 0; k < 3000 && reading.messages() < 150; ++k) std::this_thread::sleep_for(10ms);
  const auto c = view.counts();
  EXPECT_GE(reading.messages(), 150) << "the reading client got " << reading.messages();
  EXPECT_GT(c.server.dropped, 0U) << "the stalled client's queue never overflowed";
  EXPECT_EQ(c.server.clients, 2U);
}

TEST_F(LiveViewTest, APortInUseIsAnErrorNamingIt) {
  Config cfg = view_config(dir_);
  LiveView first(cfg);
  cfg.view.port = *first.port();
  cfg.view.mcap_path.clear();
  try {
    LiveView second(cfg);
    FAIL() << "bound the same port twice";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("view.server: cannot listen on 127.0.0.1:" + std::to_string(cfg.view.port)),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace fieldguard::app
