#pragma once
// The tools' command lines (fieldguard-sim, fieldguard-score, fieldguard-dbc and the bench emulators): CLI11,
// with the conventions every tool keeps.
//  - `--help` (or -h) prints "usage: SYNOPSIS", what the tool does, its options and the footer on stdout;
//    exit code 0.
//  - A bad command line prints "PROGRAM: WHAT" on stderr, WHAT naming the option, then the tool's hint or its
//    help; exit code 2 (kExitBadCommandLine).
//  - Numbers are decimal and the whole text (std::from_chars: no hex or octal, no '+' or blanks); a check
//    (a CLI11 validator) holds them to their range, and its message says the range.
//  - An option given twice counts the last time.
// Header-only; the target fieldguard_tool_cli (tools/CMakeLists.txt) brings it and CLI11.

#include <CLI/CLI.hpp>
#include <array>
#include <charconv>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

namespace fieldguard::tools::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitBadCommandLine = 2;

// The whole of `text` as a decimal number of type T (integers: whole numbers only).
template <typename T>
[[nodiscard]] bool parse_number(std::string_view text, T& out) {
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, out);
  return !text.empty() && ec == std::errc{} && ptr == end;
}

// A number as a person writes it: 0.1, 4000000, 10000000 (not 1e+07): the shortest fixed-notation text that
// reads back the same.
template <typename T>
[[nodiscard]] std::string number_text(T v) {
  std::array<char, 400> buf{};  // room for the fixed notation of any double
  std::to_chars_result r{};
  if constexpr (std::is_floating_point_v<T>) {
    r = std::to_chars(buf.data(), buf.data() + buf.size(), v, std::chars_format::fixed);
  } else {
    r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  }
  return {buf.data(), r.ptr};
}

// The range [min, max] of a numeric option; what() words it for the messages.
template <typename T>
struct Between {
  T min;
  T max;
  [[nodiscard]] bool operator()(T v) const { return v >= min && v <= max; }  // false for NaN
  [[nodiscard]] std::string what() const {
    return std::string(std::is_integral_v<T> ? "a whole number" : "a number") + " from " + number_text(min) + " to " +
           number_text(max);
  }
};

// An option whose text `parse` turns into a T that `ok` accepts; anything else fails with
// "NAME: wants WHAT, not 'TEXT'". The check is a CLI11 validator; the value reaches `out` only when it passes.
template <typename T, typename Parse, typename Ok>
CLI::Option* checked(CLI::App& app, const std::string& name, T& out, Parse parse, Ok ok, const std::string& what,
                     const std::string& help) {
  CLI::Option* opt = app.add_option_function<std::string>(
      name,
      [&out, parse](const std::string& text) {
        T v{};
        if (parse(text, v)) out = v;
      },
      help);
  opt->check(CLI::Validator(
      [parse, ok, what](std::string& text) -> std::string {
        T v{};
        if (parse(text, v) && ok(v)) return {};
        return "wants " + what + ", not '" + text + "'";
      },
      ""));
  return opt;
}

// A number option held to a rule of its own, worded by `what` ("metres >= 0").
template <typename T, typename Ok>
CLI::Option* number(CLI::App& app, const std::string& name, T& out, Ok ok, const std::string& what,
                    const std::string& help) {
  return checked(
      app, name, out, [](std::string_view s, T& v) { return parse_number(s, v); }, ok, what, help);
}

// A number option that may be left out: `out` stays nullopt unless it is given.
template <typename T, typename Ok>
CLI::Option* number(CLI::App& app, const std::string& name, std::optional<T>& out, Ok ok, const std::string& what,
                    const std::string& help) {
  return checked(
      app, name, out,
      [](std::string_view s, std::optional<T>& v) {
        T x{};
        if (!parse_number(s, x)) return false;
        v = x;
        return true;
      },
      [ok](const std::optional<T>& v) { return ok(*v); }, what, help);
}

// A number option in [min, max].
template <typename T>
CLI::Option* number(CLI::App& app, const std::string& name, T& out, Between<T> range, const std::string& help) {
  return number(app, name, out, range, range.what(), help);
}

// Help as the tools have always printed it: "usage: SYNOPSIS", the description, the options (their texts may
// hold line breaks: continuation lines are indented to the text column), then the footer.
class Formatter final : public CLI::Formatter {
 public:
  explicit Formatter(std::string synopsis) : synopsis_(std::move(synopsis)) {}

  std::string make_help(const CLI::App* app, std::string /*name*/, CLI::AppFormatMode mode) const override {
    std::string out = "usage: " + synopsis_ + "\n";
    const std::string& about = app->get_description();
    if (!about.empty()) out += "\n" + about + "\n";
    out += make_groups(app, mode);
    const std::string& footer = app->get_footer();
    if (!footer.empty()) out += "\n" + footer + "\n";
    return out;
  }

 private:
  std::string synopsis_;
};

// One tool's command line: a CLI11 app with the conventions above.
class Tool {
 public:
  // `synopsis`: the usage line(s) without "usage: "; `about`: what the tool does; `footer`: what follows the
  // options (definitions, exit codes). A bad command line is followed by `hint` on stderr, or by the whole
  // help when `hint` is empty.
  Tool(std::string program, std::string synopsis, std::string about, std::string footer = "", std::string hint = "")
      : program_(std::move(program)), hint_(std::move(hint)), app_(std::move(about), program_) {
    auto formatter = std::make_shared<Formatter>(std::move(synopsis));
    formatter->column_width(22);
    app_.formatter(formatter);
    app_.footer(std::move(footer));
    app_.set_help_flag("-h,--help", "print this help and exit");
    app_.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    app_.allow_extras();  // reported by parse() as an unknown option, in our words
  }

  [[nodiscard]] CLI::App& app() { return app_; }

  // Parses the command line. nullopt: go on; otherwise the exit code to return at once: 0 after the help,
  // 2 after a bad command line (the message is printed).
  [[nodiscard]] std::optional<int> parse(int argc, char** argv) {
    try {
      app_.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
      std::fputs(app_.help().c_str(), stdout);
      return kExitOk;
    } catch (const CLI::ParseError& e) {
      // An unknown option is the likelier cause of whatever else went wrong: name it first.
      if (!app_.remaining().empty()) return unknown(app_.remaining().front());
      return fail(e.what());
    }
    if (!app_.remaining().empty()) return unknown(app_.remaining().front());
    return std::nullopt;
  }

  // Prints "PROGRAM: WHY" and the hint (or the help) on stderr; returns 2.
  int fail(const std::string& why) const {
    std::fprintf(stderr, "%s: %s\n%s", program_.c_str(), why.c_str(),
                 hint_.empty() ? app_.help().c_str() : (hint_ + "\n").c_str());
    return kExitBadCommandLine;
  }

 private:
  int unknown(const std::string& arg) const {
    return fail((arg.starts_with("-") ? "unknown option '" : "unexpected argument '") + arg + "'");
  }

  std::string program_;
  std::string hint_;
  CLI::App app_;
};

}  // namespace fieldguard::tools::cli
