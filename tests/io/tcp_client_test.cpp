// The TCP sensor link against a real server on loopback: refused, reset, silent, and talking.

#include "fieldguard/io/tcp_client.hpp"

#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/write.hpp>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

namespace fieldguard::io {
namespace {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using namespace std::chrono_literals;

template <typename Pred>
bool run_until(asio::io_context& io, Pred done, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (!done() && std::chrono::steady_clock::now() < end) {
    io.restart();
    io.run_for(5ms);
  }
  return done();
}

std::uint16_t free_port() {
  asio::io_context io;
  tcp::acceptor a(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  return a.local_endpoint().port();
}

TcpClientOptions fast(std::uint16_t port) {
  TcpClientOptions o;
  o.host = "127.0.0.1";
  o.port = port;
  o.backoff_initial_s = 0.02;
  o.backoff_max_s = 0.1;
  o.silence_timeout_s = 0.3;
  return o;
}

TEST(TcpClient, RefusedThenServerAppearsThenResetThenSilence) {
  const std::uint16_t port = free_port();
  asio::io_context io;
  std::string got;
  std::vector<std::string> reasons;
  TcpClient* self = nullptr;
  TcpClient client(io, fast(port),
                   {.on_connected = [&] { self->send("BM\n"); },
                    .on_data = [&](ByteSpan b, Stamp) { got.append(b.begin(), b.end()); },
                    .on_state = [&](TcpState, const std::string& why) { reasons.push_back(why); }});
  self = &client;
  client.start();
  // Nobody listens yet: refused, backing off.
  ASSERT_TRUE(run_until(
      io, [&] { return client.stats().connect_failures.load() >= 2; }, 2000ms));
  EXPECT_EQ(client.stats().state.load(), TcpState::Backoff);

  // A server appears: the client connects, sends its command, receives a reply; then the server resets.
  std::string server_got;
  std::thread server([&] {
    asio::io_context sio;
    tcp::acceptor acc(sio, tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    {
      tcp::socket s(sio);
      acc.accept(s);
      std::array<char, 3> cmd{};
      asio::read(s, asio::buffer(cmd));
      server_got.assign(cmd.begin(), cmd.end());
      asio::write(s, asio::buffer(std::string("BM\n00P\n\n")));
      std::this_thread::sleep_for(200ms);                // let the reply be read before the reset discards it
      s.set_option(asio::socket_base::linger(true, 0));  // RST, as a sensor that reboots
    }
    // Second connection: accept and say nothing (silence).
    tcp::socket quiet(sio);
    acc.accept(quiet);
    std::this_thread::sleep_for(800ms);
  });
  ASSERT_TRUE(run_until(
      io, [&] { return got == "BM\n00P\n\n"; }, 3000ms))
      << got;
  ASSERT_TRUE(run_until(
      io, [&] { return client.stats().disconnects.load() >= 1; }, 2000ms));
  ASSERT_TRUE(run_until(
      io, [&] { return client.stats().silences.load() >= 1; }, 3000ms));
  server.join();
  client.stop();
  EXPECT_EQ(server_got, "BM\n");
  EXPECT_GE(client.stats().connects.load(), 2U);
  bool said_refused = false;
  bool said_silent = false;
  for (const auto& r : reasons) {
    said_refused = said_refused || r.find("cannot connect to 127.0.0.1:" + std::to_string(port)) != std::string::npos;
    said_silent = said_silent || r.find("no data from") != std::string::npos;
  }
  EXPECT_TRUE(said_refused);
  EXPECT_TRUE(said_silent);
  EXPECT_EQ(client.stats().state.load(), TcpState::Idle);
}

TEST(TcpClient, SendWhileDisconnectedIsRefused) {
  asio::io_context io;
  TcpClient client(io, fast(free_port()), {});
  EXPECT_FALSE(client.send("QT\n"));
}

}  // namespace
}  // namespace fieldguard::io
