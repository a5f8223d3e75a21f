#include "daemon/live_view.hpp"

#include <chrono>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "fieldguard/engine/logging.hpp"
#include "fieldguard/sync/threads.hpp"
#include "fieldguard/writers/bev.hpp"
#include "fieldguard/writers/foxglove_json.hpp"

namespace fieldguard::app {
namespace {

constexpr std::int64_t kPictureEvery_ns = 500'000'000;  // the page's picture: at most twice a second

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::vector<ViewChannel> view_channels() {
  std::vector<ViewChannel> out;
  for (const FrameChannel& c : kFrameChannels) {
    const foxglove::Schema& s = foxglove::schema(c.schema);
    out.push_back({std::string(c.topic), std::string(s.name), std::string(s.json)});
  }
  return out;
}

}  // namespace

LiveView::LiveView(const Config& cfg)
    : cfg_(cfg),
      slots_(static_cast<std::size_t>(cfg.view.queue_frames) + 1),
      ready_(slots_.size()),
      free_(slots_.size()),
      encoder_(cfg_) {
  for (std::size_t i = 0; i < slots_.size(); ++i) free_.push(i);
  if (!cfg_.view.mcap_path.empty()) {
    McapRecording rec;
    rec.path = cfg_.view.mcap_path;
    rec.options.compression = mcap_compression(cfg_.view.mcap_compression).value_or(McapCompression::Zstd);
    rec.max_bytes = static_cast<std::uint64_t>(cfg_.view.mcap_max_mb) * 1'000'000U;
    rec.max_files = cfg_.view.mcap_max_files;
    mcap_.emplace(cfg_);
    if (!mcap_->open(rec)) throw std::runtime_error("view.mcap: " + mcap_->error());
  }
  if (cfg_.view.server) {
    ViewServerParams p;
    p.address = cfg_.view.address;
    p.port = cfg_.view.port;
    p.max_clients = cfg_.view.max_clients;
    p.client_queue = cfg_.view.client_queue;
    try {
      server_ = std::make_unique<ViewServer>(p, view_channels());
    } catch (const std::exception& e) {
      throw std::runtime_error("view.server: cannot listen on " + p.address + ":" + std::to_string(p.port) + ": " +
                               e.what());
    }
  }
  thread_ = std::thread([this] { loop(); });
}

LiveView::~LiveView() {
  stop_ = true;
  wake_.release();
  thread_.join();
  if (mcap_ && !mcap_failed_) {
    if (!mcap_->close()) logger("view")->error("view.mcap: {}", mcap_->error());
  }
  server_.reset();
}

void LiveView::frame(const DetectedFrame& d, const output::safety::Decision& decision) {
  ++frames_;
  std::size_t i = 0;
  if (!free_.pop(i)) {
    ++dropped_;
    return;
  }
  Slot& s = slots_[i];
  // Copy-assignments into the slot's own buffers: once they are large enough, nothing is allocated.
  s.frame = d.frame;
  s.obstacles = d.result.obstacles;
  s.labelled = d.labelled;
  s.fusion = d.fusion;
  s.decision = decision;
  ready_.push(i);
  wake_.release();
}

void LiveView::status(const output::safety::Decision& decision, Stamp now, std::vector<ViewSensor> sensors,
                      std::string status_line) {
  {
    const std::lock_guard lock(status_mutex_);
    status_decision_ = decision;
    status_stamp_ = now;
    sensors_ = std::move(sensors);
    status_line_ = std::move(status_line);
    status_pending_ = true;
  }
  wake_.release();
}

void LiveView::show_status() {
  std::string health;
  {
    const std::lock_guard lock(status_mutex_);
    if (!status_pending_) return;
    status_pending_ = false;
    page_decision_ = status_decision_;
    page_stamp_ = status_stamp_;
    foxglove::health(health, page_stamp_.ns, sensors_, status_line_);
  }
  // On the timeline too: a recording and a viewer see the stop a silent sensor caused between frames.
  foxglove::decision(message_, page_stamp_.ns, page_frame_, page_decision_, cfg_.safety.clear_frames, true);
  last_decision_ns_ = std::max(page_stamp_.ns, last_decision_ns_);
  const bool recording = mcap_ && !mcap_failed_;
  send(Topic::Decision, last_decision_ns_, message_, recording);
  send(Topic::Health, page_stamp_.ns, health, recording);  // the sensors too, on their own channel
  if (server_) server_->set_page(page_json(), nullptr);
}

void LiveView::send(Topic topic, std::int64_t t, std::string_view json, bool record) {
  if (record) mcap_->message(topic, t, json);
  const auto ch = static_cast<std::size_t>(topic);
  // A message nobody subscribes to is not even copied.
  if (server_ && server_->subscribed(ch)) {
    server_->publish(ch, static_cast<std::uint64_t>(std::max<std::int64_t>(t, 0)),
                     std::make_shared<const std::string>(json));
  }
}

void LiveView::loop() {
  // Normal priority whatever the io thread that started it runs at: the view must never compete with detection.
  static_cast<void>(sync::apply_to_this_thread({"fg-view", sync::SchedPolicy::Other, 0, {}}));
  while (true) {
    wake_.acquire();
    std::size_t i = 0;
    while (ready_.pop(i)) {
      show(slots_[i]);
      free_.push(i);
    }
    show_status();
    if (stop_) return;
  }
}

void LiveView::show(Slot& s) {
  perception::FrameResult result;
  result.obstacles.swap(s.obstacles);  // back into the slot below
  const FusionInfo* fusion = s.fusion ? &*s.fusion : nullptr;
  const bool recording = mcap_ && !mcap_failed_ && mcap_->begin_frame();
  encoder_.encode(s.frame, result, s.labelled, fusion, &s.decision,
                  [&](Topic topic, std::int64_t t, std::string_view json) {
                    // A decision taken on the clock may be later than the next frame's stamp (its first packet):
                    // the channel's log times still never go back.
                    if (topic == Topic::Decision) t = last_decision_ns_ = std::max(t, last_decision_ns_);
                    send(topic, t, json, recording);
                  });
  if (mcap_ && !mcap_failed_) {
    if (!mcap_->error().empty()) {
      // The recording stops; detection goes on. Said once.
      mcap_error_ = mcap_->error();
      mcap_failed_ = true;
      logger("view")->error("view.mcap: {}; recording stopped (detection goes on)", mcap_error_);
    }
    const auto st = mcap_->stats();
    mcap_frames_ = st.frames;
    mcap_messages_ = st.messages;
    mcap_bytes_ = st.bytes;
    mcap_files_ = st.files;
  }
  if (server_) {
    std::shared_ptr<const std::vector<std::uint8_t>> png;
    const std::int64_t now = steady_ns();
    if (server_->page_watched() && now - last_picture_ns_ >= kPictureEvery_ns) {
      last_picture_ns_ = now;
      const BevCaption caption{s.frame.index, s.frame.host_stamp, s.frame.partial, &s.decision,
                               cfg_.safety.clear_frames};
      png = std::make_shared<const std::vector<std::uint8_t>>(
          render_bev(s.labelled, result.obstacles, cfg_.perception, stop_zone_box(s.decision.zone), caption).png());
    }
    page_decision_ = s.decision;
    page_frame_ = s.frame.index;
    page_stamp_ = s.frame.host_stamp;
    page_obstacles_ = result.obstacles.size();
    server_->set_page(page_json(), std::move(png));
  }
  s.obstacles.swap(result.obstacles);
}

std::string LiveView::page_json() {
  nlohmann::json j;
  j["stop"] = page_decision_.stop;
  j["headline"] = output::safety::headline(page_decision_, cfg_.safety.clear_frames);
  j["reason"] = output::safety::to_string(page_decision_.reason);
  j["frame"] = page_frame_;
  j["stamp"] = page_stamp_.seconds();
  j["obstacles"] = page_obstacles_;
  {
    const std::lock_guard lock(status_mutex_);
    j["status"] = status_line_;
    j["sensors"] = nlohmann::json::array();
    for (const ViewSensor& v : sensors_) {
      j["sensors"].push_back({{"name", v.name}, {"state", v.state}, {"rate_hz", v.rate_hz}});
    }
  }
  j["view"] = {{"frames", frames_.load()}, {"dropped", dropped_.load()}};
  return j.dump();
}

LiveViewCounts LiveView::counts() const {
  LiveViewCounts c;
  c.frames = frames_;
  c.dropped = dropped_;
  c.mcap.frames = mcap_frames_;
  c.mcap.messages = mcap_messages_;
  c.mcap.bytes = mcap_bytes_;
  c.mcap.files = mcap_files_;
  c.mcap_errors = mcap_failed_ ? 1 : 0;
  if (server_) c.server = server_->counts();
  return c;
}

std::optional<std::uint16_t> LiveView::port() const {
  if (!server_) return std::nullopt;
  return server_->port();
}

}  // namespace fieldguard::app
