#include "daemon/view_server.hpp"

#include <array>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <deque>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "daemon/view_page.hpp"
#include "fieldguard/sync/threads.hpp"

namespace fieldguard::app {
namespace {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;
using Json = nlohmann::json;

constexpr const char* kSubprotocol = "foxglove.websocket.v1";
constexpr std::chrono::seconds kPageWatch{5};  // a page that asked for a picture this recently is watching

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Sec-WebSocket-Protocol is a comma-separated list; ours must be among them.
bool offers_subprotocol(std::string_view header) {
  while (!header.empty()) {
    const auto comma = header.find(',');
    std::string_view item = header.substr(0, comma);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (item == std::string_view(kSubprotocol)) return true;
    if (comma == std::string_view::npos) break;
    header.remove_prefix(comma + 1);
  }
  return false;
}

}  // namespace

class WsClient;

struct ViewServer::Impl {
  ViewServerParams params;
  std::vector<ViewChannel> channels;
  std::string server_info;
  std::string advertise;
  net::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  std::vector<std::weak_ptr<WsClient>> clients;  // the server thread's only
  std::vector<std::atomic<int>> subscribers;     // per channel, subscriptions now
  struct {
    std::atomic<std::uint64_t> clients{0}, connections{0}, refused{0}, sent{0}, dropped{0}, bad{0}, http{0};
  } n;
  std::mutex page_mutex;
  std::string status_json = "{}";
  std::shared_ptr<const std::vector<std::uint8_t>> png;
  std::atomic<std::int64_t> page_asked_ns{0};
  std::thread thread;

  void accept();
  void serve(tcp::socket socket);
};

// One WebSocket client of the Foxglove protocol. Lives as long as its handlers hold it.
class WsClient : public std::enable_shared_from_this<WsClient> {
 public:
  WsClient(ViewServer::Impl& srv, beast::tcp_stream stream) : srv_(srv), ws_(std::move(stream)) {}

  void run(const http::request<http::string_body>& req) {
    beast::get_lowest_layer(ws_).expires_never();
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& res) {
      res.set(http::field::sec_websocket_protocol, kSubprotocol);
      res.set(http::field::server, "fieldguard");
    }));
    ws_.read_message_max(1U << 16U);  // a client sends subscriptions, never anything large
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) {
        self->gone();
        return;
      }
      self->opened();
    });
  }

  // A message on `channel` to each of this client's subscriptions to it.
  void send(std::size_t channel, std::uint64_t t, const std::shared_ptr<const std::string>& body) {
    if (closed_) return;
    for (const auto& [sub, ch] : subs_) {
      if (ch != channel) continue;
      std::string head(13, '\0');
      head[0] = 1;  // MESSAGE_DATA
      for (std::size_t i = 0; i < 4; ++i) head[1 + i] = static_cast<char>((sub >> (8 * i)) & 0xFFU);
      for (std::size_t i = 0; i < 8; ++i) head[5 + i] = static_cast<char>((t >> (8 * i)) & 0xFFU);
      enqueue({std::move(head), body, false});
    }
  }

  void close() {
    if (closed_) return;
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ec);
    beast::get_lowest_layer(ws_).socket().close(ec);
    gone();
  }

 private:
  struct Out {
    std::string head;
    std::shared_ptr<const std::string> body;
    bool text = false;
  };

  void opened() {
    ++srv_.n.connections;
    srv_.clients.push_back(weak_from_this());
    enqueue({{}, std::make_shared<const std::string>(srv_.server_info), true});
    enqueue({{}, std::make_shared<const std::string>(srv_.advertise), true});
    read();
  }

  void read() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        self->gone();
        return;
      }
      self->received();
      self->read();
    });
  }

  void received() {
    const std::string text = beast::buffers_to_string(in_.data());
    in_.consume(in_.size());
    if (!ws_.got_text()) return refuse("binary client messages are not supported (no clientPublish)");
    const Json j = Json::parse(text, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("op") || !j["op"].is_string())
      return refuse("not a JSON object with an \"op\"");
    const std::string op = j["op"].get<std::string>();
    if (op == "subscribe") {
      if (!j.contains("subscriptions") || !j["subscriptions"].is_array()) return refuse("subscribe: no subscriptions");
      for (const Json& s : j["subscriptions"]) {
        if (!s.is_object() || !s.contains("id") || !s["id"].is_number_unsigned() || !s.contains("channelId") ||
            !s["channelId"].is_number_unsigned() || s["id"].get<std::uint64_t>() > 0xFFFFFFFFU) {
          refuse("subscribe: each subscription needs an id and a channelId (unsigned integers)");
          continue;
        }
        const auto id = s["id"].get<std::uint32_t>();
        const auto ch = s["channelId"].get<std::uint64_t>();
        if (ch == 0 || ch > srv_.channels.size()) {
          refuse("subscribe: no channel " + std::to_string(ch));
          continue;
        }
        if (subs_.contains(id)) {
          refuse("subscribe: subscription id " + std::to_string(id) + " is in use");
          continue;
        }
        subs_[id] = ch - 1;
        ++srv_.subscribers[ch - 1];
      }
    } else if (op == "unsubscribe") {
      if (!j.contains("subscriptionIds") || !j["subscriptionIds"].is_array())
        return refuse("unsubscribe: no subscriptionIds");
      for (const Json& id : j["subscriptionIds"]) {
        // Range-checked as subscribe checks it: 2^32 + 7 is not subscription 7.
        const bool valid = id.is_number_unsigned() && id.get<std::uint64_t>() <= 0xFFFFFFFFU;
        const auto it = valid ? subs_.find(static_cast<std::uint32_t>(id.get<std::uint64_t>())) : subs_.end();
        if (it == subs_.end()) {
          refuse("unsubscribe: no such subscription");
          continue;
        }
        --srv_.subscribers[it->second];
        subs_.erase(it);
      }
    } else {
      refuse("unsupported op \"" + op + "\"");
    }
  }

  // An error status back to the client; a client that keeps sending what cannot be used is closed.
  void refuse(const std::string& why) {
    ++srv_.n.bad;
    if (++bad_ > ViewServer::kMaxBadMessages) {
      close();
      return;
    }
    const Json status = {{"op", "status"}, {"level", 2}, {"message", why}};
    enqueue({{}, std::make_shared<const std::string>(status.dump()), true});
  }

  // Bounded: when full, the oldest waiting message goes. The one being written is not in the queue (in_flight_),
  // so dropping never moves the memory an async_write is reading.
  void enqueue(Out o) {
    if (closed_) return;
    if (queue_.size() >= static_cast<std::size_t>(srv_.params.client_queue)) {
      queue_.pop_front();
      ++srv_.n.dropped;
    }
    queue_.push_back(std::move(o));
    if (!in_flight_) write_next();
  }

  void write_next() {
    in_flight_ = std::move(queue_.front());
    queue_.pop_front();
    ws_.text(in_flight_->text);
    const std::array<net::const_buffer, 2> buffers{net::buffer(in_flight_->head), net::buffer(*in_flight_->body)};
    ws_.async_write(buffers, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->in_flight_.reset();
      if (ec) {
        self->gone();
        return;
      }
      ++self->srv_.n.sent;
      if (!self->queue_.empty() && !self->closed_) self->write_next();
    });
  }

  void gone() {
    if (closed_) return;
    closed_ = true;
    --srv_.n.clients;
    for (const auto& [sub, ch] : subs_) --srv_.subscribers[ch];
    subs_.clear();
    queue_.clear();
  }

  ViewServer::Impl& srv_;
  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer in_;
  std::deque<Out> queue_;                      // waiting
  std::optional<Out> in_flight_;               // being written
  std::map<std::uint32_t, std::size_t> subs_;  // subscription id -> channel index
  int bad_ = 0;
  bool closed_ = false;
};

namespace {

// One HTTP request: a WebSocket upgrade becomes a WsClient; anything else is answered and the connection closed.
class HttpRequest : public std::enable_shared_from_this<HttpRequest> {
 public:
  HttpRequest(ViewServer::Impl& srv, tcp::socket socket) : srv_(srv), stream_(std::move(socket)) {}

  void run() {
    stream_.expires_after(std::chrono::seconds(10));
    parser_.body_limit(1U << 14U);
    parser_.header_limit(1U << 14U);
    http::async_read(stream_, buffer_, parser_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (!ec) self->handle();
    });
  }

 private:
  void handle() {
    const auto& req = parser_.get();
    if (websocket::is_upgrade(req)) {
      const auto offered = req[http::field::sec_websocket_protocol];
      if (!offers_subprotocol(std::string_view(offered.data(), offered.size()))) {
        ++srv_.n.refused;
        return reply(http::status::bad_request, "text/plain", "WebSocket subprotocol foxglove.websocket.v1 required\n");
      }
      if (srv_.n.clients.load() >= static_cast<std::uint64_t>(srv_.params.max_clients)) {
        ++srv_.n.refused;
        return reply(http::status::service_unavailable, "text/plain",
                     "too many clients (view.server.max_clients " + std::to_string(srv_.params.max_clients) + ")\n");
      }
      ++srv_.n.clients;  // counted from here, so a burst of upgrades cannot pass the limit together
      std::make_shared<WsClient>(srv_, std::move(stream_))->run(req);
      return;
    }
    ++srv_.n.http;
    const std::string target(req.target());
    const std::string path = target.substr(0, target.find('?'));
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      return reply(http::status::method_not_allowed, "text/plain", "GET only\n");
    }
    if (path == "/" || path == "/index.html") return reply(http::status::ok, "text/html; charset=utf-8", kStatusPage);
    if (path == "/status.json") {
      std::string body;
      {
        const std::lock_guard lock(srv_.page_mutex);
        body = srv_.status_json;
      }
      return reply(http::status::ok, "application/json", std::move(body));
    }
    if (path == "/bev.png") {
      srv_.page_asked_ns = steady_ns();
      std::shared_ptr<const std::vector<std::uint8_t>> png;
      {
        const std::lock_guard lock(srv_.page_mutex);
        png = srv_.png;
      }
      if (!png || png->empty()) return reply(http::status::not_found, "text/plain", "no picture yet\n");
      return reply(http::status::ok, "image/png", std::string(png->begin(), png->end()));
    }
    reply(http::status::not_found, "text/plain", "not found\n");
  }

  void reply(http::status status, const char* type, std::string body) {
    auto res = std::make_shared<http::response<http::string_body>>(status, parser_.get().version());
    res->set(http::field::server, "fieldguard");
    res->set(http::field::content_type, type);
    res->set(http::field::cache_control, "no-store");
    res->keep_alive(false);
    res->body() = std::move(body);
    res->prepare_payload();
    http::async_write(stream_, *res, [self = shared_from_this(), res](beast::error_code, std::size_t) {
      beast::error_code ec;
      self->stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
    });
  }

  ViewServer::Impl& srv_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  http::request_parser<http::string_body> parser_;
};

}  // namespace

void ViewServer::Impl::accept() {
  acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (ec == net::error::operation_aborted) return;
    if (!ec) std::make_shared<HttpRequest>(*this, std::move(socket))->run();
    accept();
  });
}

ViewServer::ViewServer(const ViewServerParams& params, std::vector<ViewChannel> channels)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.params = params;
  m.channels = std::move(channels);
  m.subscribers = std::vector<std::atomic<int>>(m.channels.size());
  m.server_info = Json{{"op", "serverInfo"},
                       {"name", "fieldguard"},
                       {"capabilities", Json::array()},
                       {"supportedEncodings", Json::array()},
                       {"metadata", Json::object()}}
                      .dump();
  Json adv = {{"op", "advertise"}, {"channels", Json::array()}};
  for (std::size_t i = 0; i < m.channels.size(); ++i) {
    adv["channels"].push_back({{"id", i + 1},
                               {"topic", m.channels[i].topic},
                               {"encoding", "json"},
                               {"schemaName", m.channels[i].schema_name},
                               {"schema", m.channels[i].schema},
                               {"schemaEncoding", "jsonschema"}});
  }
  m.advertise = adv.dump();
  const tcp::endpoint ep(net::ip::make_address(params.address), params.port);
  m.acceptor.open(ep.protocol());
  m.acceptor.set_option(net::socket_base::reuse_address(true));
  m.acceptor.bind(ep);
  m.acceptor.listen();
  m.accept();
  m.thread = std::thread([&m] {
    static_cast<void>(sync::apply_to_this_thread({"fg-view-server", sync::SchedPolicy::Other, 0, {}}));
    m.ioc.run();
  });
}

ViewServer::~ViewServer() {
  net::post(impl_->ioc, [m = impl_.get()] {
    beast::error_code ec;
    m->acceptor.close(ec);
    for (auto& w : m->clients) {
      if (auto c = w.lock()) c->close();
    }
    m->ioc.stop();
  });
  impl_->thread.join();
}

std::uint16_t ViewServer::port() const { return impl_->acceptor.local_endpoint().port(); }

bool ViewServer::subscribed(std::size_t channel) const {
  return channel < impl_->channels.size() && impl_->subscribers[channel].load() > 0;
}

void ViewServer::publish(std::size_t channel, std::uint64_t log_time_ns, std::shared_ptr<const std::string> json) {
  if (!subscribed(channel)) return;
  net::post(impl_->ioc, [m = impl_.get(), channel, log_time_ns, json = std::move(json)] {
    std::erase_if(m->clients, [](const std::weak_ptr<WsClient>& w) { return w.expired(); });
    for (auto& w : m->clients) {
      if (auto c = w.lock()) c->send(channel, log_time_ns, json);
    }
  });
}

void ViewServer::set_page(std::string status_json, std::shared_ptr<const std::vector<std::uint8_t>> png) {
  const std::lock_guard lock(impl_->page_mutex);
  impl_->status_json = std::move(status_json);
  if (png) impl_->png = std::move(png);
}

bool ViewServer::page_watched() const {
  const std::int64_t asked = impl_->page_asked_ns.load();
  return asked != 0 && steady_ns() - asked < std::chrono::nanoseconds(kPageWatch).count();
}

ViewServerCounts ViewServer::counts() const {
  const auto& n = impl_->n;
  return {n.clients.load(), n.connections.load(), n.refused.load(), n.sent.load(),
          n.dropped.load(), n.bad.load(),         n.http.load()};
}

}  // namespace fieldguard::app
