// SCIP 2.0 character encodings, check code, command names and command encoders (protocols.md §3.2-§3.4).
#include <stdexcept>
#include <string>

#include "fieldguard/drivers/scip.hpp"

namespace fieldguard::scip {

namespace {

struct CommandForm {
  Command command;
  std::string_view name;
  std::size_t digits;  // fixed-width decimal parameters after the name in a command line / echo
};
constexpr std::array<CommandForm, 16> kForms = {{
    {Command::Scip20, "SCIP2.0", 0},
    {Command::VV, "VV", 0},
    {Command::PP, "PP", 0},
    {Command::II, "II", 0},
    {Command::BM, "BM", 0},
    {Command::QT, "QT", 0},
    {Command::RS, "RS", 0},
    {Command::RT, "RT", 0},
    {Command::RB, "RB", 0},
    {Command::TM, "TM", 1},
    {Command::MD, "MD", 13},
    {Command::ME, "ME", 13},
    {Command::MS, "MS", 13},
    {Command::GD, "GD", 10},
    {Command::GE, "GE", 10},
    {Command::GS, "GS", 10},
}};

bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_tag_char(char c) { return c >= 0x21 && c <= 0x7E && c != ';'; }

void check_tag(std::string_view tag) {
  if (tag.size() > kMaxTagLength) {
    throw std::invalid_argument("SCIP tag longer than 16 characters: " + std::string(tag));
  }
  for (char c : tag) {
    if (!is_tag_char(c)) throw std::invalid_argument("SCIP tag characters must be printable ASCII other than ';'");
  }
}

void append_number(std::string& out, unsigned value, std::size_t width, unsigned max, std::string_view what) {
  if (value > max) {
    throw std::invalid_argument("SCIP " + std::string(what) + " " + std::to_string(value) + " is above " +
                                std::to_string(max));
  }
  std::string digits = std::to_string(value);
  out.append(width - digits.size(), '0');
  out += digits;
}

std::string finish(std::string line, std::string_view tag) {
  check_tag(tag);
  if (!tag.empty()) {
    line += ';';
    line += tag;
  }
  line += '\n';
  return line;
}

}  // namespace

std::optional<std::uint32_t> decode_chars(std::string_view chars) {
  if (chars.empty() || chars.size() > 4) return std::nullopt;
  std::uint32_t v = 0;
  for (char c : chars) {
    if (c < kMinDataChar || c > kMaxDataChar) return std::nullopt;
    v = (v << 6) | static_cast<std::uint32_t>(c - kMinDataChar);
  }
  return v;
}

void encode_chars(std::uint32_t value, std::size_t width, std::string& out) {
  for (std::size_t i = width; i-- > 0;) {
    out += static_cast<char>(kMinDataChar + static_cast<char>((value >> (6 * i)) & 0x3F));
  }
}

char check_code(std::string_view bytes) {
  unsigned sum = 0;
  for (char c : bytes) sum += static_cast<unsigned char>(c);
  return static_cast<char>((sum & 0x3F) + 0x30);
}

std::string_view to_string(Command c) {
  for (const auto& f : kForms) {
    if (f.command == c) return f.name;
  }
  return "unknown";
}

Command command_of_echo(std::string_view echo) {
  for (const auto& f : kForms) {
    if (echo.substr(0, f.name.size()) != f.name) continue;
    const std::string_view rest = echo.substr(f.name.size());
    if (rest.size() < f.digits) return Command::Unknown;
    for (std::size_t i = 0; i < f.digits; ++i) {
      if (!is_digit(rest[i])) return Command::Unknown;
    }
    const std::string_view tail = rest.substr(f.digits);
    if (tail.empty()) return f.command;
    if (tail[0] != ';' || tail.size() < 2 || tail.size() > 1 + kMaxTagLength) return Command::Unknown;
    for (char c : tail.substr(1)) {
      if (!is_tag_char(c)) return Command::Unknown;
    }
    return f.command;
  }
  return Command::Unknown;
}

std::string encode_command(Command c, std::string_view tag) {
  switch (c) {
    case Command::Scip20:
    case Command::VV:
    case Command::PP:
    case Command::II:
    case Command::BM:
    case Command::QT:
    case Command::RS:
    case Command::RT:
    case Command::RB: return finish(std::string(to_string(c)), tag);
    default: break;
  }
  throw std::invalid_argument("encode_command: " + std::string(to_string(c)) +
                              " takes parameters; use encode_scan or encode_tm");
}

std::string encode_scan(Command c, const ScanRequest& r, std::string_view tag) {
  const bool continuous = c == Command::MD || c == Command::ME || c == Command::MS;
  const bool single = c == Command::GD || c == Command::GE || c == Command::GS;
  if (!continuous && !single) {
    throw std::invalid_argument("encode_scan: " + std::string(to_string(c)) + " is not a scan command");
  }
  if (r.last_step < r.first_step) throw std::invalid_argument("SCIP scan: last_step is before first_step");
  std::string line(to_string(c));
  append_number(line, r.first_step, 4, 9999, "first step");
  append_number(line, r.last_step, 4, 9999, "last step");
  append_number(line, r.cluster, 2, 99, "cluster count");
  if (continuous) {
    append_number(line, r.interval, 1, 9, "scan interval");
    append_number(line, r.scans, 2, 99, "number of scans");
  }
  return finish(std::move(line), tag);
}

std::string encode_tm(int mode, std::string_view tag) {
  if (mode < 0 || mode > 2) throw std::invalid_argument("SCIP TM mode must be 0, 1 or 2");
  std::string line = "TM";
  line += static_cast<char>('0' + mode);
  return finish(std::move(line), tag);
}

std::string_view to_string(Error e) {
  switch (e) {
    case Error::BadCheckCode: return "bad_check_code";
    case Error::MalformedLine: return "malformed_line";
    case Error::UnknownStatus: return "unknown_status";
    case Error::LineTooLong: return "line_too_long";
    case Error::ReplyTooLong: return "reply_too_long";
    case Error::NotThisReply: return "not_this_reply";
    case Error::BadEcho: return "bad_echo";
    case Error::BadCharacter: return "bad_character";
    case Error::BadDataLength: return "bad_data_length";
    case Error::BadField: return "bad_field";
  }
  return "unknown";
}

}  // namespace fieldguard::scip
