#pragma once
// One JSON object on one line, built field by field (private to the app module). Numbers: integers as they
// are, doubles in the shortest form that reads back to the same double (std::to_chars), non-finite as null.

#include <array>
#include <charconv>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace fieldguard::app {

class JsonLine {
 public:
  JsonLine() : s_("{") {}

  JsonLine& null(std::string_view k) {
    key(k);
    s_ += "null";
    return *this;
  }
  JsonLine& field(std::string_view k, double v) {
    key(k);
    number(v);
    return *this;
  }
  template <std::integral T>
  JsonLine& field(std::string_view k, T v) {
    key(k);
    std::array<char, 24> buf{};
    const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
    s_.append(buf.data(), r.ptr);
    return *this;
  }
  JsonLine& field(std::string_view k, std::string_view v) {
    key(k);
    string(v);
    return *this;
  }
  JsonLine& field(std::string_view k, const char* v) { return field(k, std::string_view(v)); }
  template <typename T>
  JsonLine& field(std::string_view k, const std::optional<T>& v) {
    return v ? field(k, *v) : null(k);
  }
  JsonLine& boolean(std::string_view k, bool v) {
    key(k);
    s_ += v ? "true" : "false";
    return *this;
  }
  // A one-letter code ('A', 'D', ...) as a string; null for 0 (absent).
  JsonLine& letter(std::string_view k, char c) { return c == 0 ? null(k) : field(k, std::string_view(&c, 1)); }
  JsonLine& array(std::string_view k, std::span<const double> v) {
    key(k);
    s_ += '[';
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (i > 0) s_ += ',';
      number(v[i]);
    }
    s_ += ']';
    return *this;
  }
  // A value that is already JSON (a nested object or array).
  JsonLine& raw(std::string_view k, std::string_view json) {
    key(k);
    s_ += json;
    return *this;
  }

  // The object, closed; the JsonLine is spent.
  [[nodiscard]] std::string str() && {
    s_ += '}';
    return std::move(s_);
  }

  static std::string format(double v) {
    if (!std::isfinite(v)) return "null";
    std::array<char, 32> buf{};
    const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
    return std::string(buf.data(), r.ptr);
  }

 private:
  void key(std::string_view k) {
    if (s_.size() > 1) s_ += ',';
    string(k);
    s_ += ':';
  }
  void number(double v) { s_ += format(v); }
  void string(std::string_view v) {
    s_ += '"';
    for (const char c : v) {
      const auto u = static_cast<unsigned char>(c);
      if (c == '"' || c == '\\') {
        s_ += '\\';
        s_ += c;
      } else if (u < 0x20 || u >= 0x7F) {
        constexpr std::string_view kHex = "0123456789abcdef";
        s_ += "\\u00";
        s_ += kHex[u >> 4];
        s_ += kHex[u & 0x0F];
      } else {
        s_ += c;
      }
    }
    s_ += '"';
  }

  std::string s_;
};

}  // namespace fieldguard::app
