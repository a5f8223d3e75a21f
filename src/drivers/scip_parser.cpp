// SCIP 2.0 push-style reply parser (protocols.md §3.3): framing, check codes, status, resynchronisation.
#include <numeric>

#include "fieldguard/drivers/scip.hpp"

namespace fieldguard::scip {

namespace {

// A payload line "<body><check>": the check covers the body, or, for "LABEL:value;" bodies, the body without its
// final ';' (VV/PP/II; hokuyolx and real captures), and urg_c accepts both variants.
bool check_ok(std::string_view body, char check) {
  if (check_code(body) == check) return true;
  return !body.empty() && body.back() == ';' && check_code(body.substr(0, body.size() - 1)) == check;
}

}  // namespace

std::uint64_t ParserCounters::rejected() const {
  return std::accumulate(errors.begin(), errors.end(), std::uint64_t{0});
}

void ReplyParser::reset() {
  state_ = State::Echo;
  line_.clear();
  line_overflow_ = false;
  reply_bytes_ = 0;
  current_ = Reply{};
}

void ReplyParser::fail(Error e) {
  ++counters_.errors[static_cast<std::size_t>(e)];
  state_ = State::Discard;
  reply_bytes_ = 0;
  current_ = Reply{};
}

void ReplyParser::push(std::string_view bytes, std::vector<Reply>& out) {
  push(ByteSpan(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), out);  // NOLINT
}

void ReplyParser::push(ByteSpan bytes, std::vector<Reply>& out) {
  for (const std::uint8_t b : bytes) {
    if (state_ != State::Discard && ++reply_bytes_ > kMaxReplyBytes) fail(Error::ReplyTooLong);
    if (state_ == State::Discard) ++counters_.discarded_bytes;
    if (b == '\n') {
      on_line(out);
      line_.clear();
      line_overflow_ = false;
      continue;
    }
    if (line_overflow_) continue;
    if (line_.size() >= kMaxLineLength) {
      line_overflow_ = true;
      if (state_ != State::Discard) fail(Error::LineTooLong);
      continue;
    }
    line_ += static_cast<char>(b);
  }
}

void ReplyParser::on_line(std::vector<Reply>& out) {
  const std::string_view line = line_;
  switch (state_) {
    case State::Discard:
      // Resynchronise at an empty line (the end of the reply we lost) or at a line that is a plausible echo.
      if (line.empty()) {
        state_ = State::Echo;
        reply_bytes_ = 0;
      } else if (!line_overflow_ && command_of_echo(line) != Command::Unknown) {
        current_ = Reply{};
        current_.echo = line;
        current_.command = command_of_echo(line);
        state_ = State::Status;
        reply_bytes_ = line.size() + 1;
      }
      return;

    case State::Echo:
      if (line.empty()) {  // a stray empty line between replies: nothing to do
        reply_bytes_ = 0;
        return;
      }
      current_ = Reply{};
      current_.command = command_of_echo(line);
      if (current_.command == Command::Unknown) {
        fail(Error::MalformedLine);
        return;
      }
      current_.echo = line;
      state_ = State::Status;
      return;

    case State::Status: {
      std::string_view code;
      if (line.size() == 3) {
        code = line.substr(0, 2);
        if (check_code(code) != line[2]) {
          fail(Error::BadCheckCode);
          return;
        }
      } else if (line == "0" && current_.command == Command::Scip20) {
        code = line;  // a SCIP 1.1 sensor answering SCIP2.0: one status character, no check (urg_c accepts it)
      } else {
        fail(Error::MalformedLine);
        return;
      }
      const auto category = classify_status(code);
      if (!category) {
        fail(Error::UnknownStatus);
        return;
      }
      current_.status = code;
      current_.category = *category;
      state_ = State::Payload;
      return;
    }

    case State::Payload:
      if (line.empty()) {
        ++counters_.replies;
        out.push_back(std::move(current_));
        current_ = Reply{};
        state_ = State::Echo;
        reply_bytes_ = 0;
        return;
      }
      if (line.size() < 2) {
        fail(Error::MalformedLine);
        return;
      }
      if (!check_ok(line.substr(0, line.size() - 1), line.back())) {
        fail(Error::BadCheckCode);
        return;
      }
      current_.lines.emplace_back(line.substr(0, line.size() - 1));
      return;
  }
}

}  // namespace fieldguard::scip
