#pragma once
// Test support for the configuration loader's tests: find an issue by key, words and line; print them all.

#include <algorithm>
#include <string>

#include "fieldguard/config/config.hpp"

namespace fieldguard::app::testing {

// line -1: on any line.
inline bool has_issue(const LoadResult& r, const std::string& key, const std::string& words, int line = -1) {
  return std::any_of(r.issues.begin(), r.issues.end(), [&](const ConfigIssue& i) {
    return i.key_path == key && i.message.find(words) != std::string::npos && (line < 0 || i.line == line);
  });
}

inline std::string dump(const LoadResult& r) {
  std::string s;
  for (const auto& i : r.issues) s += i.to_string() + "\n";
  return s;
}

}  // namespace fieldguard::app::testing
