#include "fieldguard/app/cli.hpp"

namespace fieldguard::app {
int run_cli(int /*argc*/, char** /*argv*/) { return 0; }  // wired up in the next commit
}  // namespace fieldguard::app
