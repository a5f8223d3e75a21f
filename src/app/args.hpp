#pragma once
// A small command-line parser for the subcommands: --name value, --name=value, and flags.
// Private to the app module.

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace fieldguard::app {

class Args {
 public:
  // `with_value`: options that take a value; `flags`: options that do not. Anything else is an error.
  Args(const std::vector<std::string>& argv, const std::set<std::string>& with_value, const std::set<std::string>& flags);

  [[nodiscard]] bool ok() const { return error_.empty(); }
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] bool has(const std::string& name) const { return values_.count(name) != 0; }
  [[nodiscard]] std::optional<std::string> get(const std::string& name) const;
  [[nodiscard]] const std::vector<std::string>& positional() const { return positional_; }

 private:
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_;
  std::string error_;
};

}  // namespace fieldguard::app
