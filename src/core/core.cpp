// The core module is mostly header-only value types; this unit anchors the library target.
#include "fieldguard/core/version.hpp"
#include "fieldguard/core/version_config.hpp"

namespace fieldguard {
const char* version_string() { return FIELDGUARD_VERSION_STRING; }
}  // namespace fieldguard
