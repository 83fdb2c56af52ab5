// The log tools behind auv_log: list a log's channels, export channels to CSV decoded field by
// field, filter one channel's rows by field values (an actor's episode, once the actors'
// types exist). Each reads damaged logs as far as they are readable and says where the damage
// is; the exit code tells a damaged log from a clean one.
#pragma once

#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

#include "logger/decode.hpp"
#include "logger/schema.hpp"

namespace auvrl::logger {

/// auv_log's exit codes.
inline constexpr int kExitOk = 0;
inline constexpr int kExitError = 1;    ///< nothing useful done: a file missing, bad types
inline constexpr int kExitUsage = 2;    ///< bad command line
inline constexpr int kExitDamaged = 3;  ///< done, but a log was damaged or held malformed messages

/// `auv_log list`: per channel the event count, rate, bytes and type (by fingerprint); the
/// logs' span; any damage. Returns an exit code.
int list_logs(const std::vector<std::string>& log_files, const Schema& schema, std::ostream& out,
              std::ostream& err);

/// What `auv_log export` writes.
struct ExportOptions {
  std::string channels = ".*";  ///< full-match regex of the channels to export
  std::string out_dir;          ///< one CHANNEL.csv per channel (created if missing)
  DecodeOptions decode;
};

/// `auv_log export`: one CSV per channel, columns utime_log_us, channel, then the decoded
/// fields (the union over the channel's messages, so variable arrays of different lengths
/// share one header; missing cells are empty). Messages of unknown type are counted and
/// skipped. Returns an exit code.
int export_logs(const std::vector<std::string>& log_files, const Schema& schema,
                const ExportOptions& options, std::ostream& out, std::ostream& err);

/// What `auv_log filter` writes.
struct FilterOptions {
  std::string channel;  ///< full-match regex of the channel(s) to read
  /// field=value conditions, all of which a row must meet; numbers compare as numbers
  /// ("1" matches 1.0), anything else as text.
  std::vector<std::pair<std::string, std::string>> where;
  std::string out_file;
  DecodeOptions decode;
};

/// Parses "FIELD=VALUE" (split at the first '='); throws std::invalid_argument.
std::pair<std::string, std::string> parse_where(const std::string& text);

/// `auv_log filter`: the rows of the chosen channel whose fields match, into one CSV (same
/// columns as export). A condition on a field that no message of the channel has is an error
/// (a misspelt field would otherwise silently match nothing). Returns an exit code.
int filter_logs(const std::vector<std::string>& log_files, const Schema& schema,
                const FilterOptions& options, std::ostream& out, std::ostream& err);

/// Splits one CSV line (cells quoted as csv::quote writes them) into cells.
std::vector<std::string> split_csv_line(const std::string& line);

}  // namespace auvrl::logger
