#include "inspect/inspect_byte_log.hpp"

#include <algorithm>
#include <cctype>
#include <string_view>
#include <utility>

#include "fieldguard/io/byte_log.hpp"

namespace fieldguard::app::inspect {
namespace {

constexpr std::string_view kMagic(io::kByteLogMagic, sizeof io::kByteLogMagic - 1);
constexpr std::size_t kMaxSourceLine = 4096;  // as io::ByteLogReader

}  // namespace

bool starts_with_byte_log(ByteSpan head) {
  return head.size() >= kMagic.size() && std::equal(kMagic.begin(), kMagic.end(), head.begin());
}

std::string byte_log_source(ByteSpan head) {
  std::string source;
  if (!starts_with_byte_log(head)) return source;
  for (std::size_t i = kMagic.size(); i < head.size() && head[i] != '\n'; ++i) {
    source += static_cast<char>(std::tolower(head[i]));
  }
  return source;
}

void ByteLogFeed::push(ByteSpan chunk) {
  std::size_t i = 0;
  while (i < chunk.size() && state_ != State::Stopped) {
    switch (state_) {
      case State::Magic:
        header_ += static_cast<char>(chunk[i++]);
        if (header_.size() == kMagic.size()) {
          if (header_ != kMagic) return stop("not a fieldguard byte log (no FGBYTELOG1 header)", true);
          state_ = State::Source;
        }
        break;
      case State::Source: {
        const char c = static_cast<char>(chunk[i++]);
        if (c == '\n') {
          state_ = State::RecordHeader;
        } else if (source_.size() >= kMaxSourceLine) {
          return stop("the byte log's header line is too long", true);
        } else {
          source_ += c;
        }
        break;
      }
      case State::RecordHeader:
        record_header_[filled_++] = chunk[i++];
        if (filled_ == kRecordHeaderSize) start_record();
        break;
      case State::RecordBody: {
        const std::size_t n = std::min<std::size_t>(remaining_, chunk.size() - i);
        if (from_sensor_) {
          sensor_bytes_(chunk.subspan(i, n), time_);
        } else {
          to_sensor_bytes_ += n;
        }
        i += n;
        remaining_ -= static_cast<std::uint32_t>(n);  // n <= remaining_
        if (remaining_ == 0) end_record();
        break;
      }
      case State::Stopped: break;
    }
  }
}

void ByteLogFeed::finish(Summary& summary) {
  summary.extra.emplace_back("log_records", records_);
  summary.extra.emplace_back("to_sensor_bytes", to_sensor_bytes_);
  if (state_ == State::Magic || state_ == State::Source) {
    if (!unusable_) summary.unusable = "the byte log's header is cut short";
  } else if ((state_ == State::RecordHeader && filled_ > 0) || state_ == State::RecordBody) {
    summary.notes.emplace_back("truncated", "the file ends inside a record (a log cut short)");
  }
  if (unusable_) summary.unusable = stopped_;
  if (!unusable_ && !stopped_.empty()) summary.notes.emplace_back("stopped", stopped_);
  summary.notes.emplace_back("source", "byte log \"" + source_ + "\"");
}

void ByteLogFeed::stop(std::string why, bool unusable) {
  stopped_ = std::move(why);
  unusable_ = unusable;
  state_ = State::Stopped;
}

void ByteLogFeed::start_record() {
  filled_ = 0;
  const ByteSpan h(record_header_);
  time_ = Stamp{static_cast<std::int64_t>(static_cast<std::uint64_t>(load_le32(h, 0)) |
                                          (static_cast<std::uint64_t>(load_le32(h, 4)) << 32))};
  remaining_ = load_le32(h, 8);
  const std::uint8_t direction = record_header_[12];
  if (remaining_ > io::kByteLogMaxRecord || direction > 1) {
    return stop("corrupt record " + std::to_string(records_ + 1) + " (length " + std::to_string(remaining_) +
                    ", direction " + std::to_string(direction) + "): the rest of the file is not read",
                false);
  }
  from_sensor_ = direction == static_cast<std::uint8_t>(io::Direction::FromSensor);
  state_ = State::RecordBody;
  if (remaining_ == 0) end_record();
}

void ByteLogFeed::end_record() {
  ++records_;
  state_ = State::RecordHeader;
}

SensorBytes::SensorBytes(Sink sink)
    : sink_(std::move(sink)), feed_([this](ByteSpan bytes, Stamp host_time) { sink_(bytes, host_time); }) {}

void SensorBytes::read(Capture& in) {
  bool first = true;
  in.for_each_chunk([&](ByteSpan chunk) {
    if (first) byte_log_ = starts_with_byte_log(chunk);  // the first chunk is the head the format was guessed from
    first = false;
    if (byte_log_) {
      feed_.push(chunk);
    } else {
      sink_(chunk, std::nullopt);
    }
  });
}

void SensorBytes::finish(Summary& summary) {
  if (byte_log_) feed_.finish(summary);
}

}  // namespace fieldguard::app::inspect
