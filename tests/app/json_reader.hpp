#pragma once
// Test support: a small JSON reader for the lines `fieldguard inspect` prints (objects, arrays, numbers,
// strings without escapes beyond \" \\ \uXXXX, true/false/null). Numbers are read with std::from_chars, which
// gives back exactly the double that was printed in shortest form.

#include <charconv>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fieldguard::testing {

struct Json {
  enum class Kind { Null, Bool, Number, String, Array, Object };
  Kind kind = Kind::Null;
  bool boolean = false;
  double number = 0.0;
  std::string text;  // the string, or the number's own text
  std::vector<Json> items;
  std::map<std::string, Json> fields;

  [[nodiscard]] bool has(const std::string& k) const { return fields.count(k) != 0; }
  [[nodiscard]] const Json& operator[](const std::string& k) const {
    static const Json kNull;
    const auto it = fields.find(k);
    return it == fields.end() ? kNull : it->second;
  }
  [[nodiscard]] bool is_null() const { return kind == Kind::Null; }
  [[nodiscard]] std::optional<double> opt() const {
    return kind == Kind::Number ? std::optional<double>(number) : std::nullopt;
  }
  // Integers printed by inspect fit a double exactly (up to 2^53).
  [[nodiscard]] long long integer() const { return static_cast<long long>(number); }
  [[nodiscard]] std::vector<double> numbers() const {
    std::vector<double> v;
    for (const auto& i : items) v.push_back(i.number);
    return v;
  }
};

class JsonParser {
 public:
  explicit JsonParser(std::string_view s) : s_(s) {}

  // nullopt on a syntax error or trailing garbage.
  std::optional<Json> parse() {
    Json j;
    if (!value(j)) return std::nullopt;
    skip();
    if (pos_ != s_.size()) return std::nullopt;
    return j;
  }

 private:
  void skip() {
    while (pos_ < s_.size() && (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\r' || s_[pos_] == '\n')) ++pos_;
  }
  bool literal(std::string_view w) {
    if (s_.substr(pos_, w.size()) != w) return false;
    pos_ += w.size();
    return true;
  }
  bool string(std::string& out) {
    if (pos_ >= s_.size() || s_[pos_] != '"') return false;
    ++pos_;
    while (pos_ < s_.size() && s_[pos_] != '"') {
      char c = s_[pos_++];
      if (c == '\\') {
        if (pos_ >= s_.size()) return false;
        const char e = s_[pos_++];
        if (e == 'u') {
          if (pos_ + 4 > s_.size()) return false;
          unsigned code = 0;
          const auto r = std::from_chars(s_.data() + pos_, s_.data() + pos_ + 4, code, 16);
          if (r.ec != std::errc{}) return false;
          pos_ += 4;
          c = static_cast<char>(code & 0xFFU);
        } else {
          c = e == 'n' ? '\n' : e == 't' ? '\t' : e;
        }
      }
      out += c;
    }
    if (pos_ >= s_.size()) return false;
    ++pos_;
    return true;
  }
  bool value(Json& j) {
    skip();
    if (pos_ >= s_.size()) return false;
    const char c = s_[pos_];
    if (c == '{') {
      j.kind = Json::Kind::Object;
      ++pos_;
      skip();
      if (pos_ < s_.size() && s_[pos_] == '}') return ++pos_, true;
      while (true) {
        skip();
        std::string k;
        if (!string(k)) return false;
        skip();
        if (!literal(":")) return false;
        Json v;
        if (!value(v)) return false;
        j.fields[k] = std::move(v);
        skip();
        if (literal("}")) return true;
        if (!literal(",")) return false;
      }
    }
    if (c == '[') {
      j.kind = Json::Kind::Array;
      ++pos_;
      skip();
      if (pos_ < s_.size() && s_[pos_] == ']') return ++pos_, true;
      while (true) {
        Json v;
        if (!value(v)) return false;
        j.items.push_back(std::move(v));
        skip();
        if (literal("]")) return true;
        if (!literal(",")) return false;
      }
    }
    if (c == '"') {
      j.kind = Json::Kind::String;
      return string(j.text);
    }
    if (literal("null")) return true;
    if (literal("true") || literal("false")) {
      j.kind = Json::Kind::Bool;
      j.boolean = s_[pos_ - 1] == 'e' && s_[pos_ - 2] == 'u';
      return true;
    }
    const auto r = std::from_chars(s_.data() + pos_, s_.data() + s_.size(), j.number);
    if (r.ec != std::errc{}) return false;
    j.kind = Json::Kind::Number;
    j.text.assign(s_.data() + pos_, r.ptr);
    pos_ = static_cast<std::size_t>(r.ptr - s_.data());
    return true;
  }

  std::string_view s_;
  std::size_t pos_ = 0;
};

// The JSON objects among the lines of `output` (lines starting with '{'); summary lines are skipped.
inline std::vector<Json> json_lines(const std::string& output, std::size_t* bad_lines = nullptr) {
  std::vector<Json> out;
  std::size_t start = 0;
  while (start < output.size()) {
    std::size_t end = output.find('\n', start);
    if (end == std::string::npos) end = output.size();
    const std::string_view line(output.data() + start, end - start);
    if (!line.empty() && line.front() == '{') {
      auto j = JsonParser(line).parse();
      if (j) {
        out.push_back(std::move(*j));
      } else if (bad_lines != nullptr) {
        ++*bad_lines;
      }
    }
    start = end + 1;
  }
  return out;
}

}  // namespace fieldguard::testing
