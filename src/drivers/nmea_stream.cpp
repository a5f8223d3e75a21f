#include "fieldguard/drivers/nmea_stream.hpp"

namespace fieldguard::nmea {

void StreamParser::push(std::span<const std::uint8_t> bytes, std::vector<Sentence>& out) {
  for (const std::uint8_t b : bytes) push_byte(static_cast<char>(b), out);
}

void StreamParser::push(std::string_view bytes, std::vector<Sentence>& out) {
  for (const char c : bytes) push_byte(c, out);
}

void StreamParser::finish(std::vector<Sentence>& out) {
  if (in_sentence_) end_sentence(out);
}

void StreamParser::push_byte(char c, std::vector<Sentence>& out) {
  if (c == '\r' || c == '\n') {
    if (in_sentence_) end_sentence(out);
    in_comment_ = false;
    at_line_start_ = true;
    return;
  }
  const bool line_start = at_line_start_;
  at_line_start_ = false;
  if (in_comment_ || (line_start && c == '#')) {
    in_comment_ = true;
    ++counters_.noise_bytes;
    return;
  }
  if (c == '$') {
    if (in_sentence_) {
      ++counters_.sentences;
      if (overflow_) {
        ++counters_.too_long;
      } else {
        ++counters_.interrupted;
      }
    }
    in_sentence_ = true;
    overflow_ = false;
    star_ = 0;
    buf_[0] = c;
    len_ = 1;
    return;
  }
  if (!in_sentence_) {
    ++counters_.noise_bytes;
    return;
  }
  if (len_ == buf_.size()) {
    overflow_ = true;
    return;
  }
  if (c == '*' && star_ == 0) star_ = len_;
  buf_[len_++] = c;
  // The two checksum digits end the sentence; anything after them on the line is noise.
  if (star_ != 0 && len_ == star_ + 3) end_sentence(out);
}

void StreamParser::end_sentence(std::vector<Sentence>& out) {
  in_sentence_ = false;
  ++counters_.sentences;
  if (overflow_) {
    ++counters_.too_long;
    return;
  }
  auto s = parse_sentence(std::string_view(buf_.data(), len_), ParseOptions{options_.require_checksum});
  if (s) {
    ++counters_.accepted;
    out.push_back(std::move(s).value());
    return;
  }
  switch (s.error()) {
    case Error::TooLong: ++counters_.too_long; break;
    case Error::BadChecksum: ++counters_.bad_checksum; break;
    case Error::NoChecksum: ++counters_.no_checksum; break;
    case Error::BadField: ++counters_.bad_field; break;
    case Error::Unsupported: ++counters_.unsupported; break;
    case Error::NoStart: ++counters_.bad_field; break;  // cannot happen: a sentence here starts with '$'
  }
}

}  // namespace fieldguard::nmea
