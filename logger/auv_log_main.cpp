// auv_log: tools for LCM event logs (auv_logger's, lcm-logger's): list, export, filter.
// Parses the command line (CLI11 subcommands through common/cli) and wires library pieces; the
// logic is in logger/log_tools.cpp. Reads files only: it opens no LCM socket, so it needs no
// network namespace.
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "common/cli.hpp"
#include "logger/event_log.hpp"
#include "logger/log_tools.hpp"
#include "logger/schema.hpp"

namespace {

using namespace auvrl;
using namespace auvrl::logger;

/// Everything the three commands take from the command line.
struct Request {
  std::string types_dir = default_types_dir();
  bool expand_bytes = false;
  std::vector<std::string> logs;
  std::vector<std::string> where;
  ExportOptions export_options;
  FilterOptions filter_options;
};

/// Declares the commands list, export and filter on cmd, bound to request.
void declare_commands(cli::CommandLine& cmd, Request& r) {
  cli::CommandLine& list =
      cmd.subcommand("list", "channels, counts, rates, bytes and types (by fingerprint)");
  cli::CommandLine& exp =
      cmd.subcommand("export", "one CSV per channel (OUT/CHANNEL.csv), decoded field by field");
  exp.option("out", &r.export_options.out_dir, "output directory (one CHANNEL.csv per channel)");
  exp.require("out");
  exp.option("channels", &r.export_options.channels, "full-match regex of channels to export");
  cli::CommandLine& filter =
      cmd.subcommand("filter",
                     "the rows of a channel whose fields have the given values (e.g. one episode), "
                     "to one CSV");
  filter.option("channel", &r.filter_options.channel, "full-match regex of the channel to read");
  filter.require("channel");
  filter.repeatable("where", &r.where, "FIELD=VALUE: keep rows whose field equals the value");
  filter.option("out", &r.filter_options.out_file, "output CSV file");
  filter.require("out");
  for (cli::CommandLine* sub : {&exp, &filter}) {
    sub->flag("expand-bytes", &r.expand_bytes, "one column per byte of byte arrays (default: hex)");
  }
  for (cli::CommandLine* sub : {&list, &exp, &filter}) {
    sub->option("types-dir", &r.types_dir, "directory of the .lcm files that decode the messages");
    sub->positionals("LOG", &r.logs,
                     "LCM event log files, or directories (their *.lcmlog files in name order)");
  }
  cmd.require_subcommand();
}

/// Checks what CLI11 cannot: the --where terms and that the logs exist.
void check_request(Request& r) {
  for (const std::string& text : r.where) r.filter_options.where.push_back(parse_where(text));
  r.logs = expand_log_paths(r.logs);
  for (const std::string& log : r.logs) {
    if (!std::filesystem::is_regular_file(log)) {
      throw LogError("no log file " + log + " (expected an LCM event log or a directory)");
    }
  }
}

/// Runs the chosen command; returns the exit code.
int run(const std::string& command, Request& r) {
  std::unique_ptr<Schema> schema;
  try {
    schema = std::make_unique<Schema>(Schema::from_directories({r.types_dir}));
  } catch (const SchemaError& e) {
    std::cerr << "auv_log: " << e.what() << "\n";
    return kExitError;
  }
  r.export_options.decode.byte_arrays_as_blobs = !r.expand_bytes;
  r.filter_options.decode.byte_arrays_as_blobs = !r.expand_bytes;
  try {
    if (command == "list") return list_logs(r.logs, *schema, std::cout, std::cerr);
    if (command == "export") {
      return export_logs(r.logs, *schema, r.export_options, std::cout, std::cerr);
    }
    return filter_logs(r.logs, *schema, r.filter_options, std::cout, std::cerr);
  } catch (const std::exception& e) {
    std::cerr << "auv_log " << command << ": " << e.what() << "\n";
    return kExitError;
  }
}

}  // namespace

int main(int argc, char** argv) {
  Request request;
  cli::CommandLine cmd(
      "auv_log",
      "Tools for LCM event logs (auv_logger's, lcm-logger's); auv_log COMMAND --help for a "
      "command's options.\n"
      "Exit codes: 0 ok, 1 error, 2 bad command line, 3 done but a log was damaged or held\n"
      "malformed messages (the damage and its byte offset are printed on stderr).\n"
      "Replay a log onto LCM with lcm-logplayer inside the system's namespace (see docs/logs.md).");
  declare_commands(cmd, request);
  std::string command;
  try {
    if (!cmd.parse(argc, argv)) return kExitOk;
    command = cmd.chosen();
    check_request(request);
  } catch (const cli::UsageError& e) {
    command = cmd.chosen();  // may be known although the parse failed
    std::cerr << "auv_log" << (command.empty() ? "" : " " + command) << ": " << e.what() << "\n";
    return kExitUsage;
  } catch (const std::invalid_argument& e) {  // a bad --where
    std::cerr << "auv_log " << command << ": " << e.what() << "\n";
    return kExitUsage;
  } catch (const LogError& e) {
    std::cerr << "auv_log " << command << ": " << e.what() << "\n";
    return kExitError;
  }
  return run(command, request);
}
