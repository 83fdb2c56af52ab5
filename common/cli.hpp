// Command-line parsing shared by every process, on CLI11: --name value options and --name flags,
// typed, positional arguments, repeatable options and subcommands, with CLI11's --help (defaults
// shown) and errors that name the option and what was expected.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace auvrl::cli {

/// A command line that could not be parsed; the message names the option.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace detail {

/// A CLI11 check that text converts to the number (or bool) T, so that a bad value is reported
/// as "expected an integer, got 'x'" (CLI11's own conversion error says less).
template <class T>
CLI::Validator type_check() {
  static_assert(std::is_arithmetic_v<T>);
  const std::string expected = std::is_same_v<T, bool> ? "true or false"
                               : std::is_integral_v<T> ? "an integer"
                                                       : "a finite number";
  return CLI::Validator(
      [expected](std::string& text) {
        T value{};
        bool ok = CLI::detail::lexical_cast(text, value);
        if constexpr (std::is_floating_point_v<T>) ok = ok && std::isfinite(value);
        return ok ? std::string() : "expected " + expected + ", got '" + text + "'";
      },
      "");
}

/// Adds type_check<T>() to an option of a number or bool; text needs none.
template <class T>
CLI::Option* checked(CLI::Option* option) {
  if constexpr (std::is_arithmetic_v<T>) option->check(type_check<T>());
  return option;
}

}  // namespace detail

/// A CLI11 check: a number >= min ("expected a number >= 8, got '4'").
CLI::Validator at_least(double min);
/// A CLI11 check: a number > 0.
CLI::Validator positive();

/// Declares options bound to variables (a target's value before parse() is its default), then
/// parses argv into them. Holds a CLI::App, reachable through app() for what this API lacks.
/// A subcommand is a CommandLine of its own, owned by its parent and parsed with it.
class CommandLine {
 public:
  CommandLine(std::string program, std::string summary);
  CommandLine(CommandLine&&) noexcept;
  CommandLine& operator=(CommandLine&&) noexcept;
  ~CommandLine();

  /// --name (no value) sets *target to true.
  void flag(const std::string& name, bool* target, const std::string& help);
  /// --name VALUE, converted to T (a number, bool or std::string); given twice, the last wins.
  template <class T>
  void option(const std::string& name, T* target, const std::string& help) {
    detail::checked<T>(app_->add_option("--" + name, *target, help));
  }
  /// --name (no value) calls set.
  void custom_flag(const std::string& name, std::function<void()> set, const std::string& help);
  /// --name VALUE handed to parse, which converts, checks and stores it; an exception it
  /// throws becomes a UsageError naming the option. default_text is shown in --help, and
  /// type_name as the value's kind (e.g. "number", "list").
  void custom_option(const std::string& name, std::function<void(const std::string&)> parse,
                     const std::string& default_text, const std::string& help,
                     const std::string& type_name = "TEXT");
  /// --name VALUE that may be given several times; every value is appended to *target.
  void repeatable(const std::string& name, std::vector<std::string>* target,
                  const std::string& help);
  /// Adds a CLI11 check (at_least(), positive(), CLI::ExistingFile, ...) to the declared option
  /// --name (or positional NAME).
  void check(const std::string& name, const CLI::Validator& validator);
  /// Restricts the declared option --name to one of values (CLI11's IsMember check).
  void choices(const std::string& name, const std::vector<std::string>& values);
  /// Makes the declared option --name (or positional NAME) required.
  void require(const std::string& name);
  /// The next positional argument (NAME in the usage line), converted to T as option() does.
  template <class T>
  void positional(const std::string& name, T* target, const std::string& help,
                  bool required = true) {
    detail::checked<T>(app_->add_option(name, *target, help))->required(required);
  }
  /// The remaining positional arguments, at least one when required.
  void positionals(const std::string& name, std::vector<std::string>* target,
                   const std::string& help, bool required = true);

  /// Declares the subcommand `program name`; its options go on the returned CommandLine (which
  /// lives as long as this one). After parse(), chosen() tells which subcommand was given.
  CommandLine& subcommand(const std::string& name, const std::string& summary);
  /// The subcommand declared as name (std::out_of_range if none).
  CommandLine& subcommand(const std::string& name);
  /// A command line without a subcommand is a UsageError.
  void require_subcommand();
  /// The name of the subcommand given ("" if none), after parse().
  std::string chosen() const;
  /// Leaves every argument after this subcommand's name unparsed, for a subcommand that parses
  /// them itself (its own CommandLine): see rest(). Its --help is then the handler's too.
  void pass_on_rest();
  /// With pass_on_rest(): the arguments after the subcommand's name, argv-style, argv()[0]
  /// being "program name".
  struct Rest {
    Rest() = default;
    Rest(const Rest&) = delete;  // pointers point into args
    Rest(Rest&&) = default;
    std::vector<std::string> args;
    std::vector<const char*> pointers;
    int argc() const { return static_cast<int>(pointers.size()); }
    const char* const* argv() const { return pointers.data(); }
  };
  Rest rest() const;

  /// Parses argv. Returns false when --help was given (usage printed to stdout); throws
  /// UsageError on an unknown option, a missing or malformed value.
  bool parse(int argc, const char* const* argv);

  /// The --help text (of the chosen subcommand after parse() has chosen one).
  std::string usage() const;

  /// The value of --name in argv ("" if absent), before parse(): for a --config file whose
  /// values the other options then override.
  static std::string find_value(int argc, const char* const* argv, const std::string& name);

  /// The CLI11 application, for what this API lacks.
  CLI::App& app() { return *app_; }
  const CLI::App& app() const { return *app_; }

 private:
  /// The declared option --name, or else positional NAME.
  CLI::Option* find(const std::string& name);
  /// A subcommand's CommandLine on app, owned by its parent.
  CommandLine(CLI::App* app, std::string program);

  std::unique_ptr<CLI::App> owned_;  // null for a subcommand (its parent's App owns it)
  CLI::App* app_;
  std::string program_;  // "auv_log list" for a subcommand
  std::vector<std::unique_ptr<CommandLine>> subcommands_;
};

}  // namespace auvrl::cli
