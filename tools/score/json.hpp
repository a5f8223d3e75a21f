#pragma once
// A small, strict JSON reader (RFC 8259) for the scorer's JSON lines: null, booleans, numbers, strings
// (all escapes, \u with surrogate pairs, written out as UTF-8), arrays and objects, nested at most 64 deep.
// Anything else is an error with the byte offset where it went wrong. Pure; thread-compatible.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fieldguard::score {

struct JsonValue {
  enum class Kind : std::uint8_t { Null, Bool, Number, String, Array, Object };
  Kind kind = Kind::Null;
  bool boolean = false;
  double number = 0.0;
  std::string string;
  std::vector<JsonValue> items;    // Array elements, or Object values
  std::vector<std::string> keys;   // Object keys (same order as items); a repeated key keeps its first value

  [[nodiscard]] bool is_number() const { return kind == Kind::Number; }
  [[nodiscard]] bool is_array() const { return kind == Kind::Array; }
  [[nodiscard]] bool is_object() const { return kind == Kind::Object; }
  // Member of an object, or nullptr (also when this is not an object).
  [[nodiscard]] const JsonValue* find(std::string_view key) const;
};

struct JsonError {
  std::size_t offset = 0;  // byte offset in the text
  std::string message;
};

struct JsonResult {
  std::optional<JsonValue> value;
  JsonError error;  // when !value
};

// Parses exactly one JSON value (surrounding whitespace allowed).
[[nodiscard]] JsonResult parse_json(std::string_view text);

}  // namespace fieldguard::score
