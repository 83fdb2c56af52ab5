// common/cli's CommandLine with what the log tools also need: positional arguments (the log
// files) and repeatable options (--throttle, --where). Both are taken out of argv before the
// rest goes to CommandLine, which keeps the typing, the errors and --help.
#pragma once

#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/cli.hpp"

namespace auvrl::logger {

/// A command line of named options (as common/cli), positional arguments and repeatable
/// string options.
class ToolCommandLine {
 public:
  ToolCommandLine(std::string program, std::string summary, std::string positional_help = "");

  void flag(const std::string& name, bool* target, const std::string& help);
  template <class T>
  void option(const std::string& name, T* target, const std::string& help) {
    command_line_.option(name, target, help);
    value_options_.insert(name);
  }
  /// As cli::CommandLine::custom_flag.
  void custom_flag(const std::string& name, std::function<void()> set, const std::string& help) {
    command_line_.custom_flag(name, std::move(set), help);
  }
  /// As cli::CommandLine::custom_option.
  void custom_option(const std::string& name, std::function<void(const std::string&)> parse,
                     const std::string& default_text, const std::string& help) {
    command_line_.custom_option(name, std::move(parse), default_text, help);
    value_options_.insert(name);
  }
  /// --name VALUE that may be given several times; every value is appended to *target.
  void repeatable(const std::string& name, std::vector<std::string>* target,
                  const std::string& help);

  /// Parses argv[first..]. Returns false when --help was given (usage printed); throws
  /// cli::UsageError on a bad command line.
  bool parse(int argc, const char* const* argv, int first = 1);

  /// Arguments that are not options, in order.
  const std::vector<std::string>& positional() const { return positional_; }
  std::string usage() const;

 private:
  std::string program_;
  std::string positional_help_;
  cli::CommandLine command_line_;
  std::set<std::string> value_options_;
  std::map<std::string, std::vector<std::string>*> repeatable_;
  std::map<std::string, std::string> repeatable_help_;
  std::vector<std::string> positional_;
};

}  // namespace auvrl::logger
