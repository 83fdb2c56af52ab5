#include "logger/log_tools.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <ostream>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "common/csv.hpp"
#include "logger/event_log.hpp"

namespace auvrl::logger {

namespace fs = std::filesystem;

namespace {

/// Problems met while reading, for the report and the exit code.
struct ReadReport {
  std::int64_t events = 0;
  std::int64_t damaged_regions = 0;
  std::int64_t malformed = 0;                     ///< known type, bytes do not decode
  std::map<std::uint64_t, std::int64_t> unknown;  ///< unknown fingerprints and their counts
  std::int64_t files_unreadable = 0;

  int exit_code() const {
    if (files_unreadable > 0) return kExitError;
    return damaged_regions > 0 || malformed > 0 ? kExitDamaged : kExitOk;
  }
};

/// Calls fn(file, event) for each event of the files in order; damage goes to err.
template <class Fn>
void read_logs(const std::vector<std::string>& files, ReadReport& report, std::ostream& err,
               Fn fn) {
  LogEvent event;
  for (const std::string& file : files) {
    std::unique_ptr<LogReader> reader;
    try {
      reader = std::make_unique<LogReader>(file);
    } catch (const LogError& e) {
      err << "auv_log: " << e.what() << "\n";
      ++report.files_unreadable;
      continue;
    }
    while (reader->next(event)) {
      ++report.events;
      fn(file, event);
    }
    for (const LogDamage& damage : reader->damage()) {
      ++report.damaged_regions;
      err << "auv_log: " << damage.file << ": damaged at byte " << damage.offset << ": "
          << damage.what << " (" << damage.bytes_skipped << " bytes skipped)\n";
    }
  }
}

void report_problems(const ReadReport& report, const Schema& schema, std::ostream& err) {
  for (const auto& [fingerprint, count] : report.unknown) {
    err << "auv_log: " << count << " messages of " << schema.names_for(fingerprint)
        << " skipped (is --types-dir the directory of this system's .lcm files?)\n";
  }
  if (report.malformed > 0) {
    err << "auv_log: " << report.malformed << " messages did not decode as their type\n";
  }
}

/// The union of the columns of a channel's messages, in encoding order (see
/// column_order_key): variable arrays of different lengths share one header in which every
/// element sits where it belongs. Types are ordered by first appearance (a channel normally
/// carries one type).
class ColumnSet {
 public:
  void add_row(const StructType& type, const std::vector<FieldValue>& fields) {
    std::int64_t rank = 0;
    for (; rank < static_cast<std::int64_t>(types_.size()); ++rank) {
      if (types_[static_cast<std::size_t>(rank)] == &type) break;
    }
    if (rank == static_cast<std::int64_t>(types_.size())) types_.push_back(&type);
    for (const FieldValue& field : fields) {
      if (index_.count(field.name) != 0) continue;
      std::vector<std::int64_t> key = column_order_key(type, field.name);
      key.insert(key.begin(), rank);
      sorted_.emplace(std::move(key), field.name);  // the name breaks ties (never expected)
      index_.emplace(field.name, 0);
      dirty_ = true;
    }
  }
  /// Column names in order.
  const std::vector<std::string>& names() const {
    refresh();
    return names_;
  }
  /// Position of a column, or -1.
  std::ptrdiff_t find(const std::string& name) const {
    refresh();
    const auto it = index_.find(name);
    return it == index_.end() ? -1 : static_cast<std::ptrdiff_t>(it->second);
  }

 private:
  void refresh() const {
    if (!dirty_) return;
    names_.clear();
    for (const auto& [key, name] : sorted_) {
      index_[name] = names_.size();
      names_.push_back(name);
    }
    dirty_ = false;
  }
  std::vector<const StructType*> types_;
  std::set<std::pair<std::vector<std::int64_t>, std::string>> sorted_;
  mutable std::unordered_map<std::string, std::size_t> index_;
  mutable std::vector<std::string> names_;
  mutable bool dirty_ = false;
};

/// The CSV of one channel (or of a filter's matches): a row per message, a column per field
/// of the set (empty where a message lacks the field).
class ChannelCsv {
 public:
  ChannelCsv(const std::string& path, const ColumnSet& columns)
      : columns_(columns), out_(path, header(columns)), cells_(columns.names().size()) {}
  void write_row(const LogEvent& event, const std::vector<FieldValue>& fields) {
    std::fill(cells_.begin(), cells_.end(), std::string());
    for (const FieldValue& field : fields) {
      const std::ptrdiff_t i = columns_.find(field.name);
      if (i >= 0) cells_[static_cast<std::size_t>(i)] = format_value(field);
    }
    out_.cell(event.timestamp_us).cell(event.channel);
    for (const std::string& cell : cells_) out_.cell(cell);
    out_.end_row();
  }
  void close() { out_.flush(); }
  std::int64_t rows() const { return out_.rows(); }
  const std::string& path() const { return out_.path(); }

 private:
  static std::vector<std::string> header(const ColumnSet& columns) {
    std::vector<std::string> names{"utime_log_us", "channel"};
    names.insert(names.end(), columns.names().begin(), columns.names().end());
    return names;
  }
  const ColumnSet& columns_;
  csv::Writer out_;
  std::vector<std::string> cells_;
};

/// File name for a channel's CSV: characters other than letters, digits, '_', '-' and '.'
/// become '_'.
std::string file_name_for(const std::string& channel) {
  std::string name = channel;
  for (char& c : name) {
    const bool ok =
        std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-' || c == '.';
    if (!ok) c = '_';
  }
  if (name.empty() || name[0] == '.') name = "_" + name;
  return name;
}

std::regex make_regex(const std::string& pattern, const char* what) {
  try {
    return std::regex(pattern);
  } catch (const std::regex_error& e) {
    throw std::invalid_argument(std::string(what) + " '" + pattern + "' is not a valid regex (" +
                                e.what() + ")");
  }
}

/// Decodes an event; counts unknown and malformed messages (malformed ones are reported).
bool decode_event(const Schema& schema, const std::string& file, const LogEvent& event,
                  const DecodeOptions& options, DecodedMessage& message, ReadReport& report,
                  std::ostream& err, bool report_malformed) {
  std::string error;
  const DecodeStatus status =
      decode_message(schema, event.data.data(), event.data.size(), message, error, options);
  if (status == DecodeStatus::kUnknownType) {
    if (report_malformed) ++report.unknown[message.fingerprint];
    return false;
  }
  if (status == DecodeStatus::kMalformed) {
    if (report_malformed) {
      ++report.malformed;
      err << "auv_log: " << file << ": event " << event.event_number << " at byte " << event.offset
          << " on " << event.channel << ": " << error << "\n";
    }
    return false;
  }
  return true;
}

bool numeric(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return *end == '\0';
}

bool matches(const std::vector<FieldValue>& fields,
             const std::vector<std::pair<std::string, std::string>>& where) {
  for (const auto& condition : where) {
    // Not a structured binding: clang 14 (the fuzz build) cannot capture one in a lambda.
    const std::string& name = condition.first;
    const std::string& wanted = condition.second;
    const auto it = std::find_if(fields.begin(), fields.end(),
                                 [&](const FieldValue& f) { return f.name == name; });
    if (it == fields.end()) return false;
    const std::string have = format_value(*it);
    double a = 0.0, b = 0.0;
    if (numeric(have, a) && numeric(wanted, b)) {
      if (a != b) return false;
    } else if (have != wanted) {
      return false;
    }
  }
  return true;
}

}  // namespace

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cells.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cells.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      cells.emplace_back();
    } else {
      cells.back() += c;
    }
  }
  return cells;
}

std::pair<std::string, std::string> parse_where(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw std::invalid_argument("condition '" + text +
                                "': expected FIELD=VALUE, e.g. actor_id=1 or thrust_n[0]=0.5");
  }
  return {text.substr(0, eq), text.substr(eq + 1)};
}

int list_logs(const std::vector<std::string>& log_files, const Schema& schema, std::ostream& out,
              std::ostream& err) {
  struct Stats {
    std::int64_t events = 0;
    std::uint64_t bytes = 0;
    std::int64_t first = 0;
    std::int64_t last = 0;
    std::map<std::uint64_t, std::int64_t> types;
  };
  std::vector<std::string> order;
  std::unordered_map<std::string, Stats> stats;
  std::uint64_t total_file_bytes = 0;
  std::int64_t first = 0, last = 0;
  ReadReport report;
  read_logs(log_files, report, err, [&](const std::string&, const LogEvent& event) {
    auto [it, inserted] = stats.try_emplace(event.channel);
    Stats& s = it->second;
    if (inserted) {
      order.push_back(event.channel);
      s.first = event.timestamp_us;
    }
    ++s.events;
    s.bytes += event.data.size();
    s.last = event.timestamp_us;
    std::uint64_t fingerprint = 0;
    if (read_fingerprint(event.data.data(), event.data.size(), fingerprint)) {
      ++s.types[fingerprint];
    }
    if (report.events == 1) first = event.timestamp_us;
    first = std::min(first, event.timestamp_us);
    last = std::max(last, event.timestamp_us);
  });
  for (const std::string& file : log_files) {
    std::error_code error;
    const auto size = fs::file_size(file, error);
    if (!error) total_file_bytes += size;
  }
  std::sort(order.begin(), order.end());
  const double span_s = static_cast<double>(last - first) * 1e-6;
  out << log_files.size() << " file(s), " << total_file_bytes << " bytes, " << report.events
      << " events";
  if (report.events > 0) {
    out << fmt::format(", {:.3f} s from {} to {}", span_s, utc_text(first), utc_text(last));
  }
  out << "\n\n";
  std::size_t width = 7;
  for (const std::string& channel : order) width = std::max(width, channel.size());
  out << fmt::format("{:<{}}{:>10}{:>11}{:>13}  type\n", "channel", width, "events", "rate_hz",
                     "bytes");
  for (const std::string& channel : order) {
    const Stats& s = stats[channel];
    std::string rate = "-";
    if (s.events > 1 && s.last > s.first) {
      rate = fmt::format("{:.2f}", static_cast<double>(s.events - 1) /
                                       (static_cast<double>(s.last - s.first) * 1e-6));
    }
    std::string types;
    for (const auto& [fingerprint, count] : s.types) {
      if (!types.empty()) types += "; ";
      types += schema.names_for(fingerprint);
      if (s.types.size() > 1) types += " (" + std::to_string(count) + ")";
    }
    if (types.empty()) types = "(too short for a fingerprint)";
    out << fmt::format("{:<{}}{:>10}{:>11}{:>13}  {}\n", channel, width, s.events, rate, s.bytes,
                       types);
  }
  if (report.damaged_regions > 0) {
    out << "\ndamaged regions: " << report.damaged_regions << " (see messages on stderr)\n";
  }
  return report.exit_code();
}

int export_logs(const std::vector<std::string>& log_files, const Schema& schema,
                const ExportOptions& options, std::ostream& out, std::ostream& err) {
  const std::regex channels = make_regex(options.channels, "--channels");
  std::error_code error;
  fs::create_directories(options.out_dir, error);
  if (!fs::is_directory(options.out_dir)) {
    err << "auv_log: cannot create the output directory " << options.out_dir << "\n";
    return kExitError;
  }
  // Pass 1: each channel's columns (the union over its messages).
  std::map<std::string, ColumnSet> columns;
  DecodedMessage message;
  ReadReport report;
  read_logs(log_files, report, err, [&](const std::string& file, const LogEvent& event) {
    if (!std::regex_match(event.channel, channels)) return;
    if (!decode_event(schema, file, event, options.decode, message, report, err, true)) return;
    columns[event.channel].add_row(*message.type, message.fields);
  });
  if (report.files_unreadable > 0) return kExitError;
  // Pass 2: the rows. Damage was reported in pass 1; the second pass reads the same events.
  std::map<std::string, std::unique_ptr<ChannelCsv>> writers;
  std::map<std::string, std::string> used_names;
  for (const auto& [channel, set] : columns) {
    std::string name = file_name_for(channel);
    for (int n = 2; used_names.count(name) != 0; ++n) {
      name = file_name_for(channel) + "_" + std::to_string(n);
    }
    used_names[name] = channel;
    writers[channel] = std::make_unique<ChannelCsv>(options.out_dir + "/" + name + ".csv", set);
  }
  ReadReport second;
  std::ostringstream ignored;
  read_logs(log_files, second, ignored, [&](const std::string& file, const LogEvent& event) {
    const auto it = writers.find(event.channel);
    if (it == writers.end()) return;
    if (!decode_event(schema, file, event, options.decode, message, second, ignored, false)) {
      return;
    }
    it->second->write_row(event, message.fields);
  });
  for (auto& [channel, writer] : writers) {
    writer->close();
    out << writer->path() << ": " << writer->rows() << " rows, " << columns[channel].names().size()
        << " fields\n";
  }
  if (writers.empty()) out << "no messages on channels matching '" << options.channels << "'\n";
  report_problems(report, schema, err);
  return report.exit_code();
}

int filter_logs(const std::vector<std::string>& log_files, const Schema& schema,
                const FilterOptions& options, std::ostream& out, std::ostream& err) {
  const std::regex channel = make_regex(options.channel, "--channel");
  ColumnSet all_columns;      // every field of the channel's messages (to check conditions)
  ColumnSet matched_columns;  // fields of the matching rows (the CSV header)
  DecodedMessage message;
  ReadReport report;
  std::int64_t decoded = 0;
  read_logs(log_files, report, err, [&](const std::string& file, const LogEvent& event) {
    if (!std::regex_match(event.channel, channel)) return;
    if (!decode_event(schema, file, event, options.decode, message, report, err, true)) return;
    ++decoded;
    all_columns.add_row(*message.type, message.fields);
    if (matches(message.fields, options.where)) {
      matched_columns.add_row(*message.type, message.fields);
    }
  });
  if (report.files_unreadable > 0) return kExitError;
  if (decoded == 0) {
    err << "auv_log: no decodable messages on channels matching '" << options.channel << "'\n";
    report_problems(report, schema, err);
    return report.exit_code() == kExitOk ? kExitError : report.exit_code();
  }
  for (const auto& [name, value] : options.where) {
    if (all_columns.find(name) >= 0) continue;
    err << "auv_log: field '" << name << "' is not a column of the messages on '" << options.channel
        << "'; columns:";
    std::size_t shown = 0;
    for (const std::string& column : all_columns.names()) {
      if (++shown > 30) {
        err << " ...";
        break;
      }
      err << " " << column;
    }
    err << "\n";
    return kExitError;
  }
  const fs::path parent = fs::path(options.out_file).parent_path();
  std::error_code error;
  if (!parent.empty()) fs::create_directories(parent, error);
  ChannelCsv writer(options.out_file, matched_columns);
  ReadReport second;
  std::ostringstream ignored;
  read_logs(log_files, second, ignored, [&](const std::string& file, const LogEvent& event) {
    if (!std::regex_match(event.channel, channel)) return;
    if (!decode_event(schema, file, event, options.decode, message, second, ignored, false)) {
      return;
    }
    if (matches(message.fields, options.where)) writer.write_row(event, message.fields);
  });
  writer.close();
  out << options.out_file << ": " << writer.rows() << " rows of " << decoded << " messages, "
      << matched_columns.names().size() << " fields\n";
  report_problems(report, schema, err);
  return report.exit_code();
}

}  // namespace auvrl::logger
