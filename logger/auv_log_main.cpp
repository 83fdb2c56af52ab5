// auv_log: tools for LCM event logs (auv_logger's, lcm-logger's): list, export, filter.
// Parses the command line and wires library pieces; the logic is in logger/log_tools.cpp.
// Reads files only: it opens no LCM socket, so it needs no network namespace.
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <stdexcept>

#include "logger/command_line.hpp"
#include "logger/event_log.hpp"
#include "logger/log_tools.hpp"
#include "logger/schema.hpp"

namespace {

using namespace auvrl;
using namespace auvrl::logger;

const char* const kUsage =
    "usage: auv_log COMMAND [options] LOG...\n"
    "LOG: an LCM event log file, or a directory (its *.lcmlog files in name order).\n"
    "Exit codes: 0 ok, 1 error, 2 bad command line, 3 done but a log was damaged or held\n"
    "malformed messages (the damage and its byte offset are printed on stderr).\n\n"
    "commands:\n"
    "  list LOG...                        channels, counts, rates, types (by fingerprint)\n"
    "  export LOG... --out DIR [--channels REGEX]\n"
    "                                     one CSV per channel, decoded field by field\n"
    "  filter LOG... --channel REGEX --where FIELD=VALUE [--where ...] --out FILE.csv\n"
    "                                     the rows whose fields match, e.g. one episode\n"
    "  COMMAND --help                     that command's options\n"
    "Replay a log onto LCM with lcm-logplayer inside the system's namespace (see README).\n";

/// Loads the types; prints the error and returns false if they cannot be loaded.
bool load_schema(const std::string& types_dir, std::unique_ptr<Schema>& schema) {
  try {
    schema = std::make_unique<Schema>(Schema::from_directories({types_dir}));
    return true;
  } catch (const SchemaError& e) {
    std::cerr << "auv_log: " << e.what() << "\n";
    return false;
  }
}

int run(const std::string& command, int argc, char** argv) {
  std::string types_dir = default_types_dir();
  bool expand_bytes = false;
  const std::map<std::string, std::string> summaries = {
      {"list", "Lists the channels of LCM event logs: counts, rates, bytes, types."},
      {"export",
       "Exports channels of LCM event logs to CSV, one file per channel, decoded field "
       "by field."},
      {"filter", "Writes the rows of a channel whose fields have the given values to one CSV."}};
  const auto summary = summaries.find(command);
  ToolCommandLine cmd("auv_log " + command, summary == summaries.end() ? "" : summary->second,
                      "LOG...");
  cmd.option("types-dir", &types_dir, "directory of the .lcm files that decode the messages");

  ExportOptions export_options;
  FilterOptions filter_options;
  std::vector<std::string> where;
  if (command == "list") {
    // Nothing else.
  } else if (command == "export") {
    cmd.option("out", &export_options.out_dir, "output directory (one CHANNEL.csv per channel)");
    cmd.option("channels", &export_options.channels, "full-match regex of channels to export");
    cmd.flag("expand-bytes", &expand_bytes, "one column per byte of byte arrays (default: hex)");
  } else if (command == "filter") {
    cmd.option("channel", &filter_options.channel, "full-match regex of the channel to read");
    cmd.repeatable("where", &where, "FIELD=VALUE: keep rows whose field equals the value");
    cmd.option("out", &filter_options.out_file, "output CSV file");
    cmd.flag("expand-bytes", &expand_bytes, "one column per byte of byte arrays (default: hex)");
  } else {
    std::cerr << "auv_log: unknown command '" << command << "'\n" << kUsage;
    return kExitUsage;
  }

  std::vector<std::string> logs;
  try {
    if (!cmd.parse(argc, argv, 2)) return kExitOk;
    if (cmd.positional().empty()) throw cli::UsageError("no LOG given");
    if (command == "export" && export_options.out_dir.empty()) {
      throw cli::UsageError("--out DIR is required");
    }
    if (command == "filter") {
      if (filter_options.channel.empty()) throw cli::UsageError("--channel is required");
      if (filter_options.out_file.empty()) throw cli::UsageError("--out FILE.csv is required");
      for (const std::string& text : where) filter_options.where.push_back(parse_where(text));
    }
    logs = expand_log_paths(cmd.positional());
    for (const std::string& log : logs) {
      if (!std::filesystem::is_regular_file(log)) {
        throw LogError("no log file " + log + " (expected an LCM event log or a directory)");
      }
    }
  } catch (const cli::UsageError& e) {
    std::cerr << "auv_log " << command << ": " << e.what() << "\n";
    return kExitUsage;
  } catch (const std::invalid_argument& e) {
    std::cerr << "auv_log " << command << ": " << e.what() << "\n";
    return kExitUsage;
  } catch (const LogError& e) {
    std::cerr << "auv_log " << command << ": " << e.what() << "\n";
    return kExitError;
  }

  std::unique_ptr<Schema> schema;
  if (!load_schema(types_dir, schema)) return kExitError;
  export_options.decode.byte_arrays_as_blobs = !expand_bytes;
  filter_options.decode.byte_arrays_as_blobs = !expand_bytes;
  try {
    if (command == "list") return list_logs(logs, *schema, std::cout, std::cerr);
    if (command == "export") {
      return export_logs(logs, *schema, export_options, std::cout, std::cerr);
    }
    return filter_logs(logs, *schema, filter_options, std::cout, std::cerr);
  } catch (const std::exception& e) {
    std::cerr << "auv_log " << command << ": " << e.what() << "\n";
    return kExitError;
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    std::cout << kUsage;
    return argc < 2 ? kExitUsage : kExitOk;
  }
  return run(argv[1], argc, argv);
}
