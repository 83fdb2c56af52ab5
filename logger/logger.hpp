// auv_logger's logic: every message on the subscribed channels into rotating LCM event logs,
// big frequent channels throttled to one message per interval, counts per channel in a
// heartbeat and a summary. It handles messages as bytes: it needs no type to log one.
#pragma once

#include <auvrl_lcm/logger_heartbeat_t.hpp>
#include <chrono>
#include <cstdint>
#include <iosfwd>
#include <regex>
#include <string>
#include <unordered_map>
#include <vector>

#include "common/channels.hpp"
#include "common/transport.hpp"
#include "logger/event_log.hpp"
#include "logger/schema.hpp"

namespace auvrl::logger {

/// Channels matching pattern (a full-match regex) are written at most once per interval_s
/// (receive time); 0 writes every message.
struct ThrottleRule {
  std::string pattern;
  double interval_s = 0.0;
};

/// Parses "REGEX=SECONDS" (split at the last '=', so the regex may hold '='). Throws
/// std::invalid_argument naming what is wrong.
ThrottleRule parse_throttle_rule(const std::string& text);

/// How auv_logger logs.
struct LoggerConfig {
  std::string dir;                ///< directory of the log files (created if missing)
  std::string prefix = "lcmlog";  ///< files are PREFIX-NNNN.lcmlog
  std::string channels = ".*";    ///< full-match regex of the channels to log
  double max_file_mb = 128.0;     ///< a new file before one would exceed this, MB (1e6 bytes)
  double flush_period_s = 0.2;    ///< buffered events reach the OS at least this often, s
  double heartbeat_period_s = 1.0;
  /// Checked in order, first match wins; the built-in POLICY_WEIGHTS=10 rule comes after
  /// these (so "POLICY_WEIGHTS=0" turns it off).
  std::vector<ThrottleRule> throttles;
  /// Messages LCM may hold between two polls (received by its thread, not yet handled).
  int queue_capacity = 100000;
  /// Channels counted each on its own (in the heartbeat and the summary); the messages of
  /// further ones are still logged, unthrottled, and counted together under
  /// kOtherChannels, so that a flood of names cannot grow the logger or its heartbeat.
  int max_channels = 1024;
};

/// The one entry that counts the channels beyond LoggerConfig::max_channels.
inline const std::string kOtherChannels = "(other channels)";

/// The built-in throttle: policy weights (large, after every update) at most every 10 s.
inline const ThrottleRule kDefaultPolicyThrottle{channels::kPolicyWeights, 10.0};

/// What the logger did with one channel's messages.
struct ChannelCounts {
  std::string channel;
  std::int64_t received = 0;
  std::int64_t written = 0;
  std::int64_t throttled = 0;
  std::int64_t write_errors = 0;
  std::uint64_t bytes_written = 0;  ///< event bytes in the logs (header and channel included)
  double throttle_interval_s = 0.0;
  std::int64_t last_written_utime = 0;
  std::vector<std::uint64_t> fingerprints;  ///< distinct fingerprints seen (at most 4 kept)
};

/// Logs a transport's traffic. Not thread-safe (one thread, as the transport).
class Logger {
 public:
  /// Subscribes at once; the first log file is created with the first message. Throws
  /// LogError (directory) or std::invalid_argument (a bad regex).
  Logger(transport::Transport& transport, LoggerConfig config);
  ~Logger();
  Logger(const Logger&) = delete;
  Logger& operator=(const Logger&) = delete;

  /// Handles messages for up to timeout_ms (at most a bounded batch, so flushes and
  /// heartbeats stay on time under load), then flushes and publishes the heartbeat when due.
  void poll(int timeout_ms);
  /// Handles whatever LCM has already received, for up to max_ms; returns how many.
  int drain(int max_ms);
  /// Final drain, flush and close; publishes a last heartbeat; writes the summary file and
  /// returns its path. Call once, at the end.
  std::string finish(const Schema* schema);

  /// The summary text (also written by finish()); schema names the types (may be null).
  void write_summary(std::ostream& out, const Schema* schema) const;

  const std::vector<ChannelCounts>& channels() const { return channels_; }
  std::int64_t received() const { return received_; }
  std::int64_t written() const { return written_; }
  std::int64_t throttled() const { return throttled_; }
  std::int64_t write_errors() const { return write_errors_; }
  const RotatingLogWriter& writer() const { return writer_; }
  /// The heartbeat as it would be published now.
  auvrl_lcm::logger_heartbeat_t heartbeat() const;

 private:
  void on_message(const transport::RawMessage& raw);
  ChannelCounts& channel(const std::string& name);
  double throttle_interval(const std::string& channel) const;
  void flush();
  void publish_heartbeat();

  transport::Transport& transport_;
  LoggerConfig config_;
  std::vector<std::pair<std::regex, double>> throttles_;
  RotatingLogWriter writer_;
  transport::SubscriptionId subscription_ = -1;
  std::vector<ChannelCounts> channels_;
  std::unordered_map<std::string, std::size_t> channel_index_;
  std::int64_t received_ = 0;
  std::int64_t written_ = 0;
  std::int64_t throttled_ = 0;
  std::int64_t write_errors_ = 0;
  std::int64_t start_utime_ = 0;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point next_flush_;
  std::chrono::steady_clock::time_point next_heartbeat_;
  bool unflushed_ = false;
  bool finished_ = false;
};

}  // namespace auvrl::logger
