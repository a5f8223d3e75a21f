#pragma once
// One JSON object on one line, built field by field on nlohmann::ordered_json (private to the inspect module).
// Keys stay in the order they are added. Numbers: integers as they are, doubles in nlohmann's shortest form
// that reads back to the same double (a whole number keeps its ".0": 90.0), non-finite as null. Strings are
// bytes out of a capture, not text: each byte is one character (ISO 8859-1), so whatever is not printable
// ASCII comes out escaped (\u00XX, \n, ...) and reads back as the same byte, and the line is always valid JSON.

#include <concepts>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>

namespace fieldguard::app {

class JsonLine {
 public:
  using Json = nlohmann::ordered_json;

  JsonLine& null(std::string_view k) { return set(k, nullptr); }
  JsonLine& field(std::string_view k, double v) { return set(k, v); }
  template <std::integral T>
  requires(!std::same_as<T, bool>) JsonLine& field(std::string_view k, T v) { return set(k, v); }
  JsonLine& field(std::string_view k, std::string_view v) { return set(k, bytes(v)); }
  JsonLine& field(std::string_view k, const char* v) { return field(k, std::string_view(v)); }
  template <typename T>
  JsonLine& field(std::string_view k, const std::optional<T>& v) {
    return v ? field(k, *v) : null(k);
  }
  JsonLine& boolean(std::string_view k, bool v) { return set(k, v); }
  // A one-letter code ('A', 'D', ...) as a string; null for 0 (absent).
  JsonLine& letter(std::string_view k, char c) { return c == 0 ? null(k) : field(k, std::string_view(&c, 1)); }
  JsonLine& array(std::string_view k, std::span<const double> v) {
    Json a = Json::array();
    for (const double x : v) a.push_back(x);
    return set(k, std::move(a));
  }
  // A nested object, built with its own JsonLine.
  JsonLine& object(std::string_view k, JsonLine&& v) { return set(k, std::move(v.j_)); }
  // Any other value (arrays of integers, arrays of arrays), built with nlohmann directly. Strings in it are
  // taken as UTF-8: pass capture bytes through bytes() first.
  JsonLine& value(std::string_view k, Json v) { return set(k, std::move(v)); }

  // The object as one line, without the newline; the JsonLine is spent.
  [[nodiscard]] std::string str() && { return j_.dump(-1, ' ', /*ensure_ascii=*/true); }

  // Capture bytes as a JSON string's UTF-8: byte b is the character U+00bb.
  static std::string bytes(std::string_view v) {
    std::string s;
    s.reserve(v.size());
    for (const char c : v) {
      const auto u = static_cast<unsigned char>(c);
      if (u < 0x80) {
        s += c;
      } else {
        s += static_cast<char>(0xC0 | (u >> 6));
        s += static_cast<char>(0x80 | (u & 0x3F));
      }
    }
    return s;
  }

 private:
  JsonLine& set(std::string_view k, Json v) {
    j_[bytes(k)] = std::move(v);  // keys too: SCIP info labels come from the sensor
    return *this;
  }

  Json j_ = Json::object();
};

}  // namespace fieldguard::app
