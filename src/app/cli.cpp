#include "fieldguard/app/cli.hpp"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "fieldguard/core/exit_code.hpp"
#include "fieldguard/core/version.hpp"

namespace fieldguard::app {
namespace {

constexpr const char* kUsage = "fieldguard <command> [options]";
constexpr const char* kAbout =
    "Obstacle detection for autonomous tractors: LiDAR, GNSS and AHRS in, obstacles and a stop request out.\n";

// Help as `fieldguard` has always printed it: "usage: <synopsis>", the command's options, then the text that
// explains it (the footer), so that the synopsis is the first line a user reads.
class Formatter final : public CLI::Formatter {
 public:
  void usage(const CLI::App* app, std::string synopsis) { usage_[app] = std::move(synopsis); }

  std::string make_help(const CLI::App* app, std::string name, CLI::AppFormatMode mode) const override {
    std::string out = "usage: ";
    const auto it = usage_.find(app);
    out += it != usage_.end() ? it->second : name;
    out += "\n";
    if (app->get_parent() == nullptr) out += std::string("\n") + kAbout;
    out += make_positionals(app);
    out += make_groups(app, mode);
    out += make_subcommands(app, mode);
    const std::string footer = app->get_footer();
    if (!footer.empty()) out += "\n" + footer;
    return out;
  }

 private:
  std::map<const CLI::App*, std::string> usage_;
};

}  // namespace

int run_cli(int argc, char** argv) {
  CLI::App top(kAbout, "fieldguard");
  auto formatter = std::make_shared<Formatter>();
  formatter->column_width(24);
  top.formatter(formatter);
  top.set_help_flag("--help,-h", "this text; `fieldguard <command> --help` for a command's options");
  bool version = false;
  top.add_flag("--version", version, "print the version");
  top.allow_extras();
  top.require_subcommand(0, 1);
  formatter->usage(&top, kUsage);
  std::vector<Command> commands;
  commands.push_back(add_replay(top));
  commands.push_back(add_check_config(top));
  commands.push_back(add_inspect(top));
  commands.push_back(add_record(top));
  commands.push_back(add_run(top));
  for (const auto& c : commands) formatter->usage(c.app, c.usage);

  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    std::fputs(top.help().c_str(), stderr);
    return kExitBadInput;
  }
  if (args.front() == "help") {
    std::fputs(top.help().c_str(), stdout);
    return kExitOk;
  }
  try {
    top.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return top.exit(e);
  } catch (const CLI::ParseError& e) {
    for (const auto& c : commands) {
      if (c.app->parsed()) return usage_error(*c.app, e.what());
    }
    std::fprintf(stderr, "fieldguard: %s\n\n%s", e.what(), top.help().c_str());
    return kExitBadInput;
  }
  if (version) {
    std::printf("%s\n", version_string());
    return kExitOk;
  }
  for (const auto& c : commands) {
    if (!c.app->parsed()) continue;
    try {
      return c.run();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "fieldguard %s: internal error: %s\n", c.app->get_name().c_str(), e.what());
      return kExitFailure;
    }
  }
  const auto rest = top.remaining();
  const std::string what = rest.empty() ? std::string() : rest.front();
  std::fprintf(stderr, "fieldguard: unknown command '%s'\n\n%s", what.c_str(), top.help().c_str());
  return kExitBadInput;
}

}  // namespace fieldguard::app
