#pragma once

namespace fieldguard {
// "fieldguard X.Y.Z"
[[nodiscard]] const char* version_string();
}  // namespace fieldguard
