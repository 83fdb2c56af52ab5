#include "logger/command_line.hpp"

#include <iostream>

namespace auvrl::logger {

ToolCommandLine::ToolCommandLine(std::string program, std::string summary,
                                 std::string positional_help)
    : program_(program),
      positional_help_(std::move(positional_help)),
      command_line_(std::move(program), std::move(summary)) {}

void ToolCommandLine::flag(const std::string& name, bool* target, const std::string& help) {
  command_line_.flag(name, target, help);
}

void ToolCommandLine::repeatable(const std::string& name, std::vector<std::string>* target,
                                 const std::string& help) {
  repeatable_[name] = target;
  repeatable_help_[name] = help;
}

bool ToolCommandLine::parse(int argc, const char* const* argv, int first) {
  std::vector<std::string> rest{program_};
  for (int i = first; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << usage();
      return false;
    }
    if (arg.rfind("--", 0) != 0 || arg == "--") {
      positional_.push_back(arg);
      continue;
    }
    const auto eq = arg.find('=');
    const std::string name = arg.substr(2, eq == std::string::npos ? std::string::npos : eq - 2);
    if (const auto it = repeatable_.find(name); it != repeatable_.end()) {
      if (eq != std::string::npos) {
        it->second->push_back(arg.substr(eq + 1));
      } else if (i + 1 < argc) {
        it->second->push_back(argv[++i]);
      } else {
        throw cli::UsageError("option --" + name + " needs a value");
      }
      continue;
    }
    rest.push_back(arg);
    // The value of a value-taking option is not a positional argument.
    if (eq == std::string::npos && value_options_.count(name) != 0 && i + 1 < argc) {
      rest.push_back(argv[++i]);
    }
  }
  std::vector<const char*> args;
  for (const std::string& a : rest) args.push_back(a.c_str());
  return command_line_.parse(static_cast<int>(args.size()), args.data());
}

std::string ToolCommandLine::usage() const {
  std::string text = command_line_.usage();
  if (!positional_help_.empty()) {
    const auto line_end = text.find('\n');
    text.insert(line_end, " " + positional_help_);
  }
  std::string repeatable;
  for (const auto& [name, help] : repeatable_help_) {
    std::string left = "  --" + name + " VALUE";
    left += std::string(left.size() < 30 ? 30 - left.size() : 1, ' ');
    repeatable += left + help + " (repeatable)\n";
  }
  // Before the "--help" line, which CommandLine writes last.
  const auto help_line = text.rfind("  --help");
  text.insert(help_line == std::string::npos ? text.size() : help_line, repeatable);
  return text;
}

}  // namespace auvrl::logger
