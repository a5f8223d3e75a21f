#pragma once
// The live view's server (`view.server`): one TCP port, Boost.Beast, its own thread and io_context, so no client
// can hold up the daemon's io thread. On it:
//   - the Foxglove WebSocket protocol (subprotocol foxglove.websocket.v1, as @foxglove/ws-protocol speaks it):
//     serverInfo and the channels advertised on connect, subscribe / unsubscribe, each message as a binary
//     MESSAGE_DATA frame (opcode 1, subscription id, log time, the JSON message);
//   - GET /             the status page (a browser on a tablet): the decision, the sensors, the bird's-eye view
//   - GET /status.json  what the page shows, as JSON
//   - GET /bev.png      the newest bird's-eye picture
// A slow or hostile client never slows anything but itself: each client has a bounded queue whose oldest
// messages are dropped (counted) when it is full; a client over max_clients is refused (HTTP 503); a message
// the server cannot use is answered with an error status (op "status", level 2) and never ends anything but,
// past kMaxBadMessages, that client's connection.
// Thread-safe: publish(), set_page() and counts() may be called from any thread.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace fieldguard::app {

struct ViewServerParams {
  std::string address = "127.0.0.1";
  std::uint16_t port = 8765;  // 0: the kernel chooses (port() tells)
  int max_clients = 4;
  int client_queue = 64;
};

struct ViewChannel {
  std::string topic;
  std::string schema_name;
  std::string schema;  // JSON Schema text
};

struct ViewServerCounts {
  std::uint64_t clients = 0;        // connected now (WebSocket)
  std::uint64_t connections = 0;    // WebSocket connections accepted, ever
  std::uint64_t refused = 0;        // over max_clients, or without the subprotocol
  std::uint64_t sent = 0;           // messages written to clients
  std::uint64_t dropped = 0;        // messages a client's full queue dropped
  std::uint64_t bad_messages = 0;   // client messages answered with an error status
  std::uint64_t http_requests = 0;  // plain HTTP requests served
};

class ViewServer {
 public:
  // Binds and starts the thread. Throws std::system_error when the address cannot be bound.
  ViewServer(const ViewServerParams& params, std::vector<ViewChannel> channels);
  ~ViewServer();  // closes every connection and joins the thread
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;

  [[nodiscard]] std::uint16_t port() const;

  // Whether any client subscribes to `channel` now: a message nobody wants is not even built.
  [[nodiscard]] bool subscribed(std::size_t channel) const;
  // A message on channel `channel` (index into the channels given) to every client subscribed to it.
  void publish(std::size_t channel, std::uint64_t log_time_ns, std::shared_ptr<const std::string> json);
  // What the page shows: status.json's body and the bird's-eye picture (empty: none yet).
  void set_page(std::string status_json, std::shared_ptr<const std::vector<std::uint8_t>> png);
  // True when the page asked for a picture within the last few seconds: the picture is drawn only then.
  [[nodiscard]] bool page_watched() const;
  [[nodiscard]] ViewServerCounts counts() const;

  static constexpr int kMaxBadMessages = 100;

  struct Impl;  // named here so that view_server.cpp's connection classes can hold it; defined there only

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldguard::app
