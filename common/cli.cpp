#include "common/cli.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace auvrl::cli {

namespace {

std::int64_t parse_integer(const std::string& name, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE) {
    throw UsageError("option --" + name + ": expected an integer, got '" + text + "'");
  }
  return value;
}

}  // namespace

CommandLine::CommandLine(std::string program, std::string summary)
    : program_(std::move(program)), summary_(std::move(summary)) {}

void CommandLine::add(Option option) { options_.push_back(std::move(option)); }

void CommandLine::flag(const std::string& name, bool* target, const std::string& help) {
  add({name, help, "", false, [target](const std::string&) { *target = true; }});
}

void CommandLine::option(const std::string& name, std::string* target, const std::string& help) {
  add({name, help, *target, true, [target](const std::string& v) { *target = v; }});
}

void CommandLine::option(const std::string& name, int* target, const std::string& help) {
  add({name, help, std::to_string(*target), true, [target, name](const std::string& v) {
         const std::int64_t value = parse_integer(name, v);
         if (value < INT32_MIN || value > INT32_MAX) {
           throw UsageError("option --" + name + ": " + v + " is out of range");
         }
         *target = static_cast<int>(value);
       }});
}

void CommandLine::option(const std::string& name, std::int64_t* target, const std::string& help) {
  add({name, help, std::to_string(*target), true,
       [target, name](const std::string& v) { *target = parse_integer(name, v); }});
}

void CommandLine::option(const std::string& name, double* target, const std::string& help) {
  std::ostringstream default_text;
  default_text << *target;
  add({name, help, default_text.str(), true, [target, name](const std::string& v) {
         char* end = nullptr;
         const double value = std::strtod(v.c_str(), &end);
         if (v.empty() || *end != '\0' || !std::isfinite(value)) {
           throw UsageError("option --" + name + ": expected a finite number, got '" + v + "'");
         }
         *target = value;
       }});
}

void CommandLine::custom_flag(const std::string& name, std::function<void()> set,
                              const std::string& help) {
  add({name, help, "", false, [set = std::move(set)](const std::string&) { set(); }});
}

void CommandLine::custom_option(const std::string& name,
                                std::function<void(const std::string&)> parse,
                                const std::string& default_text, const std::string& help) {
  add({name, help, default_text, true, [parse = std::move(parse), name](const std::string& v) {
         try {
           parse(v);
         } catch (const UsageError&) {
           throw;
         } catch (const std::exception& e) {
           throw UsageError("option --" + name + ": " + e.what());
         }
       }});
}

bool CommandLine::parse(int argc, const char* const* argv) {
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << usage();
      return false;
    }
    if (arg.rfind("--", 0) != 0) throw UsageError("unexpected argument '" + arg + "'");
    std::string name = arg.substr(2);
    std::string value;
    bool has_inline_value = false;
    if (const auto eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      has_inline_value = true;
    }
    const Option* match = nullptr;
    for (const Option& option : options_) {
      if (option.name == name) match = &option;
    }
    if (match == nullptr) {
      throw UsageError("unknown option --" + name + " (see " + program_ + " --help)");
    }
    if (match->takes_value && !has_inline_value) {
      if (i + 1 >= argc) throw UsageError("option --" + name + " needs a value");
      value = argv[++i];
    } else if (!match->takes_value && has_inline_value) {
      throw UsageError("option --" + name + " takes no value");
    }
    match->apply(value);
  }
  return true;
}

std::string CommandLine::find_value(int argc, const char* const* argv, const std::string& name) {
  const std::string flag = "--" + name;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == flag && i + 1 < argc) return argv[i + 1];
    if (arg.rfind(flag + "=", 0) == 0) return arg.substr(flag.size() + 1);
  }
  return "";
}

std::string CommandLine::usage() const {
  std::ostringstream out;
  out << "usage: " << program_ << " [options]\n" << summary_ << "\n\noptions:\n";
  for (const Option& option : options_) {
    std::string left = "  --" + option.name + (option.takes_value ? " VALUE" : "");
    out << left;
    out << std::string(left.size() < 30 ? 30 - left.size() : 1, ' ') << option.help;
    if (option.takes_value && !option.default_text.empty()) {
      out << " (default: " << option.default_text << ")";
    }
    out << '\n';
  }
  out << "  --help                      this text\n";
  return out.str();
}

}  // namespace auvrl::cli
