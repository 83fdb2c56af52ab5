// Command-line parsing shared by every process: --name value options and --name flags, typed,
// with a generated --help and errors that name the option and what was expected.
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace auvrl::cli {

/// A command line that could not be parsed; the message names the option.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Declares options bound to variables, then parses argv into them.
class CommandLine {
 public:
  CommandLine(std::string program, std::string summary);

  /// --name (no value) sets *target to true.
  void flag(const std::string& name, bool* target, const std::string& help);
  /// --name VALUE, converted to the target's type; the target's current value is the default.
  void option(const std::string& name, std::string* target, const std::string& help);
  void option(const std::string& name, int* target, const std::string& help);
  void option(const std::string& name, std::int64_t* target, const std::string& help);
  void option(const std::string& name, double* target, const std::string& help);
  /// --name (no value) calls set.
  void custom_flag(const std::string& name, std::function<void()> set, const std::string& help);
  /// --name VALUE handed to parse, which converts, checks and stores it; an exception it
  /// throws becomes a UsageError naming the option. default_text is shown in --help.
  void custom_option(const std::string& name, std::function<void(const std::string&)> parse,
                     const std::string& default_text, const std::string& help);

  /// Parses argv. Returns false when --help was given (usage printed to stdout); throws
  /// UsageError on an unknown option, a missing or malformed value.
  bool parse(int argc, const char* const* argv);

  std::string usage() const;

  /// The value of --name in argv ("" if absent), before parse(): for a --config file whose
  /// values the other options then override.
  static std::string find_value(int argc, const char* const* argv, const std::string& name);

 private:
  struct Option {
    std::string name;
    std::string help;
    std::string default_text;
    bool takes_value = true;
    std::function<void(const std::string&)> apply;
  };
  void add(Option option);

  std::string program_;
  std::string summary_;
  std::vector<Option> options_;
};

}  // namespace auvrl::cli
