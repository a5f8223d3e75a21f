#include "drivers/nmea_sentence.hpp"

#include <algorithm>
#include <charconv>

namespace fieldguard::nmea::detail {
namespace {

[[nodiscard]] constexpr bool is_digit(char c) { return c >= '0' && c <= '9'; }

[[nodiscard]] bool all_digits(std::string_view s) {
  for (const char c : s) {
    if (!is_digit(c)) return false;
  }
  return true;
}

[[nodiscard]] std::optional<int> hex_digit(char c) {
  if (is_digit(c)) return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return std::nullopt;
}

// Printable ASCII without the NMEA reserved characters that cannot occur inside a sentence body.
[[nodiscard]] bool body_char_ok(char c) { return c >= 0x20 && c <= 0x7E && c != '$' && c != '*' && c != '!'; }

[[nodiscard]] std::string_view trim_blanks(std::string_view s) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  return s;
}

// "ddmm.mmmm" / "dddmm.mmmm" with at most max_deg_digits degree digits -> degrees (unsigned).
Field<double> angle(std::string_view value, std::size_t max_deg_digits, double max_deg) {
  if (value.empty()) return std::optional<double>{};
  const std::size_t int_len = std::min(value.find('.'), value.size());
  if (int_len < 3 || int_len - 2 > max_deg_digits) return Unexpected{Error::BadField};
  const std::string_view deg_text = value.substr(0, int_len - 2);
  if (!all_digits(deg_text)) return Unexpected{Error::BadField};
  const auto minutes = decimal(value.substr(int_len - 2));
  if (!minutes || !*minutes || **minutes < 0.0 || **minutes >= 60.0) return Unexpected{Error::BadField};
  int deg = 0;
  (void)std::from_chars(deg_text.data(), deg_text.data() + deg_text.size(), deg);  // <= 3 digits: no overflow
  const double result = deg + **minutes / 60.0;
  if (result > max_deg) return Unexpected{Error::BadField};
  return std::optional<double>{result};
}

Field<double> signed_angle(std::string_view value, std::string_view hemisphere, std::size_t max_deg_digits,
                           double max_deg, char positive, char negative) {
  auto a = angle(value, max_deg_digits, max_deg);
  if (!a || !*a) return a;
  if (hemisphere.size() != 1 || (hemisphere[0] != positive && hemisphere[0] != negative)) {
    return Unexpected{Error::BadField};
  }
  return std::optional<double>{hemisphere[0] == negative ? -**a : **a};
}

[[nodiscard]] constexpr int days_in_month(int month, int year) {
  constexpr std::array<int, 12> kDays = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
  return month == 2 && leap ? 29 : kDays[static_cast<std::size_t>(month - 1)];
}

}  // namespace

Expected<Frame, Error> frame(std::string_view text, bool require_checksum) {
  while (!text.empty() && (text.back() == '\r' || text.back() == '\n' || text.back() == '\0')) text.remove_suffix(1);
  if (text.empty() || text.front() != '$') return Unexpected{Error::NoStart};
  if (text.size() > kMaxSentenceLength) return Unexpected{Error::TooLong};

  // "*hh" must end the sentence; a '*' anywhere else is a damaged checksum.
  const std::size_t star = text.rfind('*');
  std::string_view body = text.substr(1);
  if (star == std::string_view::npos) {
    if (require_checksum) return Unexpected{Error::NoChecksum};
  } else {
    if (star + 3 != text.size()) return Unexpected{Error::BadChecksum};
    const auto hi = hex_digit(text[star + 1]);
    const auto lo = hex_digit(text[star + 2]);
    body = text.substr(1, star - 1);
    if (!hi || !lo || checksum(body) != static_cast<std::uint8_t>(*hi * 16 + *lo)) {
      return Unexpected{Error::BadChecksum};
    }
  }
  for (const char c : body) {
    if (!body_char_ok(c)) return Unexpected{Error::BadField};
  }

  Frame s;
  const std::size_t comma = body.find(',');
  const std::string_view address = body.substr(0, comma);
  if (address.size() == 5) {
    s.talker = address.substr(0, 2);
    s.type = address.substr(2);
  } else {
    s.type = address;
  }
  if (comma == std::string_view::npos) return s;
  std::string_view rest = body.substr(comma + 1);
  while (true) {
    const std::size_t next = s.field_count + 1 < kMaxFields ? rest.find(',') : std::string_view::npos;
    s.fields[s.field_count++] = trim_blanks(rest.substr(0, next));
    if (next == std::string_view::npos) break;
    rest.remove_prefix(next + 1);
  }
  return s;
}

Field<double> decimal(std::string_view f) {
  if (f.empty()) return std::optional<double>{};
  std::string_view digits = f;
  if (digits.front() == '+' || digits.front() == '-') digits.remove_prefix(1);
  const std::size_t dot = digits.find('.');
  const std::string_view int_part = digits.substr(0, dot);
  const std::string_view frac_part = dot == std::string_view::npos ? std::string_view{} : digits.substr(dot + 1);
  if (int_part.size() + frac_part.size() == 0 || !all_digits(int_part) || !all_digits(frac_part)) {
    return Unexpected{Error::BadField};
  }
  const std::string_view number = f.front() == '+' ? f.substr(1) : f;  // from_chars takes '-' but not '+'
  double v = 0.0;
  const auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), v, std::chars_format::fixed);
  if (ec != std::errc{} || end != number.data() + number.size()) return Unexpected{Error::BadField};
  return std::optional<double>{v};
}

Field<int> integer(std::string_view f) {
  if (f.empty()) return std::optional<int>{};
  if (!all_digits(f)) return Unexpected{Error::BadField};
  int v = 0;
  const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
  if (ec != std::errc{} || end != f.data() + f.size()) return Unexpected{Error::BadField};
  return std::optional<int>{v};
}

Field<char> letter(std::string_view f) {
  if (f.empty()) return std::optional<char>{};
  if (f.size() != 1 || f[0] < 'A' || f[0] > 'Z') return Unexpected{Error::BadField};
  return std::optional<char>{f[0]};
}

Field<double> time_of_day(std::string_view f) {
  if (f.empty()) return std::optional<double>{};
  if (f.size() < 6 || !all_digits(f.substr(0, 6)) || (f.size() > 6 && f[6] != '.')) return Unexpected{Error::BadField};
  const int hh = (f[0] - '0') * 10 + (f[1] - '0');
  const int mm = (f[2] - '0') * 10 + (f[3] - '0');
  const auto ss = decimal(f.substr(4));
  // 60.x is a leap second.
  if (hh > 23 || mm > 59 || !ss || !*ss || **ss >= 61.0) return Unexpected{Error::BadField};
  return std::optional<double>{hh * 3600.0 + mm * 60.0 + **ss};
}

Field<double> latitude(std::string_view value, std::string_view hemisphere) {
  return signed_angle(value, hemisphere, 2, 90.0, 'N', 'S');
}

Field<double> longitude(std::string_view value, std::string_view hemisphere) {
  return signed_angle(value, hemisphere, 3, 180.0, 'E', 'W');
}

Field<Date> date_ddmmyy(std::string_view f) {
  if (f.empty()) return std::optional<Date>{};
  if (f.size() != 6 || !all_digits(f)) return Unexpected{Error::BadField};
  Date d;
  d.day = (f[0] - '0') * 10 + (f[1] - '0');
  d.month = (f[2] - '0') * 10 + (f[3] - '0');
  const int yy = (f[4] - '0') * 10 + (f[5] - '0');
  d.year = yy >= 80 ? 1900 + yy : 2000 + yy;
  if (d.month < 1 || d.month > 12 || d.day < 1 || d.day > days_in_month(d.month, d.year)) {
    return Unexpected{Error::BadField};
  }
  return std::optional<Date>{d};
}

}  // namespace fieldguard::nmea::detail
