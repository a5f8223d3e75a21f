#pragma once
// Test support: the JSON lines `fieldguard inspect` and `replay` print (and the simulator's truth), read with
// nlohmann/json. Look members up with .at(): a missing key throws, which gtest reports as the test's failure
// (const operator[] on a missing key is undefined behaviour in nlohmann/json).

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace fieldguard::testing {

using Json = nlohmann::json;

// The JSON objects among the lines of `output` (lines starting with '{'); summary lines are skipped. Lines that
// start with '{' but are not JSON are counted in `bad_lines`.
inline std::vector<Json> json_lines(const std::string& output, std::size_t* bad_lines = nullptr) {
  std::vector<Json> out;
  std::size_t start = 0;
  while (start < output.size()) {
    std::size_t end = output.find('\n', start);
    if (end == std::string::npos) end = output.size();
    const std::string_view line(output.data() + start, end - start);
    if (!line.empty() && line.front() == '{') {
      Json j = Json::parse(line, nullptr, /*allow_exceptions=*/false);
      if (!j.is_discarded()) {
        out.push_back(std::move(j));
      } else if (bad_lines != nullptr) {
        ++*bad_lines;
      }
    }
    start = end + 1;
  }
  return out;
}

// A string's text, or a number's as JSON writes it (nlohmann's shortest form that reads back the same double,
// which is how the writers print numbers): what a test compares with golden text.
inline std::string text(const Json& j) { return j.is_string() ? j.get<std::string>() : j.dump(); }

}  // namespace fieldguard::testing
