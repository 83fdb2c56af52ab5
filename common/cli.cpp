#include "common/cli.hpp"

#include <fmt/format.h>

#include <iostream>
#include <utility>

namespace auvrl::cli {

namespace {

/// What every option of a command line shares: --help shows the target's value before parse()
/// as the default; an option given twice keeps the last value (launchers append overrides).
void configure(CLI::App& app) {
  app.option_defaults()->always_capture_default()->multi_option_policy(
      CLI::MultiOptionPolicy::TakeLast);
  app.get_formatter()->column_width(34);
}

/// Whether app declares subcommands and none was given.
bool subcommand_missing(const CLI::App& app) {
  return app.get_subcommands().empty() &&
         !app.get_subcommands([](const CLI::App*) { return true; }).empty();
}

/// The first argument CLI11 could not place, as an error that says what it is.
std::string describe_extra(const CLI::App& root, const std::string& program) {
  const std::vector<std::string> extras = root.remaining(true);
  if (extras.empty()) return "unexpected arguments";
  const std::string& first = extras.front();
  if (first.size() > 1 && first[0] == '-') {
    return fmt::format("unknown option {} (see {} --help)", first.substr(0, first.find('=')),
                       program);
  }
  if (subcommand_missing(root)) {
    return fmt::format("unknown command '{}' (see {} --help)", first, program);
  }
  return fmt::format("unexpected argument '{}'", first);
}

/// CLI11's error as this project words it: "option --name: what was wrong".
std::string describe(const CLI::ParseError& error, const CLI::App& root,
                     const std::string& program) {
  const bool no_subcommand =
      dynamic_cast<const CLI::RequiredError*>(&error) != nullptr && subcommand_missing(root);
  if (dynamic_cast<const CLI::ExtrasError*>(&error) != nullptr ||
      (no_subcommand && !root.remaining(true).empty())) {
    return describe_extra(root, program);
  }
  if (no_subcommand) return fmt::format("a command is required (see {} --help)", program);
  const std::string what = error.what();
  if (what.rfind("--", 0) == 0) return "option " + what;
  if (dynamic_cast<const CLI::ValidationError*>(&error) != nullptr) return "argument " + what;
  return what;
}

}  // namespace

CLI::Validator at_least(double min) {
  return CLI::Validator(
      [min](std::string& text) {
        double value = 0;
        return CLI::detail::lexical_cast(text, value) && value >= min
                   ? std::string()
                   : fmt::format("expected a number >= {}, got '{}'", min, text);
      },
      "");
}

CLI::Validator positive() {
  return CLI::Validator(
      [](std::string& text) {
        double value = 0;
        return CLI::detail::lexical_cast(text, value) && value > 0
                   ? std::string()
                   : fmt::format("expected a number > 0, got '{}'", text);
      },
      "");
}

CommandLine::CommandLine(std::string program, std::string summary)
    : owned_(std::make_unique<CLI::App>(std::move(summary), program)),
      app_(owned_.get()),
      program_(std::move(program)) {
  configure(*app_);
}

CommandLine::CommandLine(CLI::App* app, std::string program)
    : app_(app), program_(std::move(program)) {}

CommandLine::CommandLine(CommandLine&&) noexcept = default;
CommandLine& CommandLine::operator=(CommandLine&&) noexcept = default;
CommandLine::~CommandLine() = default;

void CommandLine::flag(const std::string& name, bool* target, const std::string& help) {
  app_->add_flag("--" + name, *target, help)->disable_flag_override();
}

void CommandLine::custom_flag(const std::string& name, std::function<void()> set,
                              const std::string& help) {
  app_->add_flag_callback("--" + name, std::move(set), help)
      ->disable_flag_override()
      ->trigger_on_parse();
}

void CommandLine::custom_option(const std::string& name,
                                std::function<void(const std::string&)> parse,
                                const std::string& default_text, const std::string& help,
                                const std::string& type_name) {
  const std::string option = "--" + name;
  // Called as each occurrence is parsed (in argv order, as the parse functions expect).
  app_->add_option_function<std::string>(
          option,
          [parse = std::move(parse), option](const std::string& value) {
            try {
              parse(value);
            } catch (const UsageError&) {
              throw;
            } catch (const std::exception& e) {
              throw UsageError(fmt::format("option {}: {}", option, e.what()));
            }
          },
          help)
      ->default_str(default_text)
      ->type_name(type_name)
      ->trigger_on_parse();
}

void CommandLine::repeatable(const std::string& name, std::vector<std::string>* target,
                             const std::string& help) {
  // One value per occurrence (CLI11 lets a vector option take several), all of them kept.
  app_->add_option("--" + name, *target, help)
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->default_str("");  // not "[]"
}

void CommandLine::positionals(const std::string& name, std::vector<std::string>* target,
                              const std::string& help, bool required) {
  app_->add_option(name, *target, help)
      ->required(required)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->default_str("");  // not "[]"
}

void CommandLine::choices(const std::string& name, const std::vector<std::string>& values) {
  app_->get_option("--" + name)->check(CLI::IsMember(values));
}

CLI::Option* CommandLine::find(const std::string& name) {
  CLI::Option* option = app_->get_option_no_throw("--" + name);
  return option != nullptr ? option : app_->get_option(name);  // a positional; throws if unknown
}

void CommandLine::require(const std::string& name) { find(name)->required(); }

void CommandLine::check(const std::string& name, const CLI::Validator& validator) {
  find(name)->check(validator);
}

CommandLine& CommandLine::subcommand(const std::string& name, const std::string& summary) {
  CLI::App* app = app_->add_subcommand(name, summary);
  subcommands_.push_back(std::unique_ptr<CommandLine>(new CommandLine(app, program_ + " " + name)));
  return *subcommands_.back();
}

CommandLine& CommandLine::subcommand(const std::string& name) {
  for (const auto& sub : subcommands_) {
    if (sub->app_->get_name() == name) return *sub;
  }
  throw std::out_of_range("no subcommand " + name + " of " + program_);
}

void CommandLine::require_subcommand() { app_->require_subcommand(1); }

std::string CommandLine::chosen() const {
  const auto chosen = app_->get_subcommands();
  return chosen.empty() ? "" : chosen.front()->get_name();
}

void CommandLine::pass_on_rest() {
  app_->prefix_command();
  app_->set_help_flag();  // --help goes to the handler too
}

CommandLine::Rest CommandLine::rest() const {
  Rest rest;
  rest.args.push_back(program_);
  for (std::string& arg : app_->remaining()) rest.args.push_back(std::move(arg));
  for (const std::string& arg : rest.args) rest.pointers.push_back(arg.c_str());
  return rest;
}

bool CommandLine::parse(int argc, const char* const* argv) {
  try {
    app_->parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << usage();
    return false;
  } catch (const CLI::ParseError& e) {
    // "see auv_log list --help" when the error is in a subcommand's options.
    std::string program = program_;
    for (const CLI::App* app = app_; !app->get_subcommands().empty();) {
      app = app->get_subcommands().front();
      program += " " + app->get_name();
    }
    throw UsageError(describe(e, *app_, program));
  }
  return true;
}

std::string CommandLine::usage() const {
  // A subcommand's usage line starts with its parent's name ("auv_log list").
  const auto space = program_.rfind(' ');
  return owned_ != nullptr
             ? app_->help()
             : app_->help(space == std::string::npos ? "" : program_.substr(0, space));
}

std::string CommandLine::find_value(int argc, const char* const* argv, const std::string& name) {
  // A throwaway CLI11 app that knows only --name and lets everything else through.
  CLI::App app;
  app.allow_extras();
  app.set_help_flag();
  std::string value;
  app.add_option("--" + name, value)->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError&) {
    return "";  // --name without a value: parse() reports it
  }
  return value;
}

}  // namespace auvrl::cli
