#include "fieldguard/writers/mcap_recorder.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "fieldguard/core/version.hpp"
#include "fieldguard/writers/foxglove_json.hpp"

namespace fieldguard::app {

McapRecorder::McapRecorder(const Config& cfg) : encoder_(cfg) {}

std::string McapRecorder::numbered(const std::string& path, std::uint64_t index) {
  const std::filesystem::path p(path);
  char n[24];
  std::snprintf(n, sizeof n, "_%04llu", static_cast<unsigned long long>(index));
  return (p.parent_path() / (p.stem().string() + n + p.extension().string())).string();
}

bool McapRecorder::open(const McapRecording& recording) {
  rec_ = recording;
  if (rec_.options.library.empty()) rec_.options.library = std::string("fieldguard ") + version_string();
  return open_next();
}

bool McapRecorder::open_next() {
  if (writer_) {
    if (!writer_->close()) error_ = writer_->error();
    done_.messages += writer_->stats().messages;
    done_.bytes += writer_->stats().file_bytes;
    writer_.reset();
    if (!error_.empty()) return false;
  }
  ++done_.files;
  current_ = rec_.max_bytes == 0 ? rec_.path : numbered(rec_.path, done_.files);
  writer_ = std::make_unique<McapWriter>();
  if (!writer_->open(current_, rec_.options)) {
    error_ = writer_->error();
    return false;
  }
  // Only the newest max_files stay: the one max_files before this one goes now.
  if (rec_.max_bytes != 0 && rec_.max_files > 0 && done_.files > static_cast<std::uint64_t>(rec_.max_files)) {
    std::error_code ec;
    if (std::filesystem::remove(numbered(rec_.path, done_.files - static_cast<std::uint64_t>(rec_.max_files)), ec))
      ++done_.removed;
  }
  // One schema record per schema, however many channels use it.
  std::vector<std::uint16_t> schema_ids(foxglove::schemas().size(), 0);
  channels_.clear();
  for (const FrameChannel& c : kFrameChannels) {
    for (std::size_t i = 0; i < foxglove::schemas().size(); ++i) {
      const foxglove::Schema& s = foxglove::schemas()[i];
      if (s.name != c.schema) continue;
      if (schema_ids[i] == 0) schema_ids[i] = writer_->add_schema(s.name, "jsonschema", s.json);
      channels_.push_back(writer_->add_channel(schema_ids[i], c.topic, "json"));
    }
  }
  if (!writer_->error().empty()) error_ = writer_->error();
  return error_.empty();
}

bool McapRecorder::frame(const LidarFrame& frame, const perception::FrameResult& result,
                         std::span<const perception::LabeledPoint> points, const FusionInfo* fusion,
                         const output::safety::Decision* decision) {
  if (!begin_frame()) return false;
  encoder_.encode(frame, result, points, fusion, decision,
                  [this](Topic topic, std::int64_t t, std::string_view json) { message(topic, t, json); });
  if (!writer_->error().empty()) error_ = writer_->error();
  return error_.empty();
}

bool McapRecorder::begin_frame() {
  if (!error_.empty() || !writer_) return false;
  // A bounded recording starts its next file at a frame, so that each file holds whole frames.
  if (rec_.max_bytes != 0 && writer_->size_bound() >= rec_.max_bytes && !open_next()) return false;
  ++frames_;
  return true;
}

void McapRecorder::message(Topic topic, std::int64_t stamp_ns, std::string_view json) {
  if (!error_.empty() || !writer_) return;
  if (!writer_->write(channels_[static_cast<std::size_t>(topic)],
                      static_cast<std::uint64_t>(std::max<std::int64_t>(stamp_ns, 0)), json)) {
    error_ = writer_->error();
  }
}

bool McapRecorder::close() {
  if (!writer_) return error_.empty();
  if (!writer_->close() && error_.empty()) error_ = writer_->error();
  done_.messages += writer_->stats().messages;
  done_.bytes += writer_->stats().file_bytes;
  writer_.reset();
  return error_.empty();
}

McapRecorderStats McapRecorder::stats() const {
  McapRecorderStats s = done_;
  s.frames = frames_;
  if (writer_) {
    s.messages += writer_->stats().messages;
    s.bytes += writer_->stats().file_bytes;
  }
  return s;
}

}  // namespace fieldguard::app
