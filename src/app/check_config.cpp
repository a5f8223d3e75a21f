#include <cstdio>

#include "app/args.hpp"
#include "app/commands.hpp"
#include "fieldguard/core/exit_code.hpp"
#include "fieldguard/config/config.hpp"

namespace fieldguard::app {

int cmd_check_config(const std::vector<std::string>& argv) {
  constexpr const char* kHelp =
      "usage: fieldguard check-config FILE\n"
      "\n"
      "Loads FILE as a fieldguard configuration and reports every problem at once, each as\n"
      "FILE:LINE: key.path: what is wrong and what to do. Exit code 0 when valid, 2 otherwise.\n";
  const Args args(argv, {}, {"help"});
  if (args.has("help")) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  if (!args.ok() || args.positional().size() != 1) {
    std::fprintf(stderr, "fieldguard check-config: %s\n%s",
                 args.ok() ? "give exactly one configuration file" : args.error().c_str(), kHelp);
    return kExitBadInput;
  }
  const auto result = load_config_file(args.positional().front());
  for (const auto& issue : result.issues) std::fprintf(stderr, "%s\n", issue.to_string().c_str());
  if (!result.ok()) {
    std::fprintf(stderr, "%zu problem%s in %s\n", result.issues.size(), result.issues.size() == 1 ? "" : "s",
                 args.positional().front().c_str());
    return kExitBadInput;
  }
  std::printf("%s: valid\n", args.positional().front().c_str());
  return kExitOk;
}

}  // namespace fieldguard::app
