#include "replay/recording.hpp"

#include <utility>

namespace fieldguard::app {

Expected<RecordingReader, std::string> RecordingReader::open(const std::string& pcap, std::vector<LogFile> logs) {
  auto p = io::PcapReader::open(pcap);
  if (!p) return Unexpected{p.error()};
  RecordingReader r(std::move(p).value());
  for (LogFile& l : logs) {
    auto b = io::ByteLogReader::open(l.path);
    if (!b) return Unexpected{b.error()};
    r.cursors_.push_back(Cursor{std::move(l), std::move(b).value(), std::nullopt, 0});
  }
  return r;
}

std::optional<RecordingEvent> RecordingReader::next() {
  if (!started_) {
    started_ = true;
    datagram_ = pcap_.next();
    for (Cursor& c : cursors_) c.next = c.reader.next();
  } else if (taken_ == -1) {
    datagram_ = pcap_.next();
  } else if (taken_ >= 0) {
    Cursor& c = cursors_[static_cast<std::size_t>(taken_)];
    c.next = c.reader.next();
  }
  int best = -1;
  for (std::size_t i = 0; i < cursors_.size(); ++i) {
    const Cursor& c = cursors_[i];
    if (c.next && (best < 0 || c.next->host_time.ns < cursors_[static_cast<std::size_t>(best)].next->host_time.ns)) {
      best = static_cast<int>(i);
    }
  }
  const bool capture =
      datagram_ && (best < 0 || datagram_->host_time.ns <= cursors_[static_cast<std::size_t>(best)].next->host_time.ns);
  if (capture) {
    taken_ = -1;
    return RecordingEvent{datagram_->host_time, &*datagram_, nullptr, LogKind::Scan2d};
  }
  if (best < 0) {
    taken_ = -2;
    return std::nullopt;
  }
  taken_ = best;
  Cursor& c = cursors_[static_cast<std::size_t>(best)];
  ++c.records;
  current_ = std::move(*c.next);
  c.next.reset();
  return RecordingEvent{current_.host_time, nullptr, &current_, c.file.kind};
}

std::vector<RecordingReader::LogStatus> RecordingReader::logs() const {
  std::vector<LogStatus> out;
  for (const Cursor& c : cursors_) {
    out.push_back({c.file, c.records, c.reader.source(), c.reader.truncated(), c.reader.error()});
  }
  return out;
}

bool RecordingReader::has(LogKind k) const {
  for (const Cursor& c : cursors_) {
    if (c.file.kind == k) return true;
  }
  return false;
}

}  // namespace fieldguard::app
