#include "logger/logger.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <stdexcept>

#include "logger/decode.hpp"

namespace auvrl::logger {

namespace {

using Clock = std::chrono::steady_clock;

Clock::duration seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

ThrottleRule parse_throttle_rule(const std::string& text) {
  const auto eq = text.rfind('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw std::invalid_argument("throttle '" + text +
                                "': expected REGEX=SECONDS, e.g. POLICY_WEIGHTS=10");
  }
  ThrottleRule rule;
  rule.pattern = text.substr(0, eq);
  const std::string seconds_text = text.substr(eq + 1);
  char* end = nullptr;
  rule.interval_s = std::strtod(seconds_text.c_str(), &end);
  if (*end != '\0' || !std::isfinite(rule.interval_s) || rule.interval_s < 0.0) {
    throw std::invalid_argument("throttle '" + text + "': interval '" + seconds_text +
                                "' is not a number of seconds >= 0");
  }
  try {
    std::regex check(rule.pattern);
  } catch (const std::regex_error& e) {
    throw std::invalid_argument("throttle '" + text + "': '" + rule.pattern +
                                "' is not a valid regex (" + e.what() + ")");
  }
  return rule;
}

Logger::Logger(transport::Transport& transport, LoggerConfig config)
    : transport_(transport),
      config_(std::move(config)),
      writer_(config_.dir, config_.prefix,
              static_cast<std::uint64_t>(std::max(1.0, config_.max_file_mb * 1e6))) {
  if (!(config_.max_file_mb > 0.0) || !(config_.flush_period_s > 0.0) ||
      !(config_.heartbeat_period_s > 0.0)) {
    throw std::invalid_argument("max file size, flush period and heartbeat period must be > 0");
  }
  if (config_.max_channels < 1) {
    throw std::invalid_argument("max channels must be >= 1, not " +
                                std::to_string(config_.max_channels));
  }
  std::vector<ThrottleRule> rules = config_.throttles;
  rules.push_back(kDefaultPolicyThrottle);
  for (const ThrottleRule& rule : rules) {
    try {
      throttles_.emplace_back(std::regex(rule.pattern), rule.interval_s);
    } catch (const std::regex_error& e) {
      throw std::invalid_argument("throttle regex '" + rule.pattern + "' is invalid: " + e.what());
    }
  }
  start_utime_ = transport::now_utime();
  start_ = Clock::now();
  next_flush_ = start_ + seconds(config_.flush_period_s);
  next_heartbeat_ = start_;
  subscription_ = transport_.subscribe(
      config_.channels, [this](const transport::RawMessage& raw) { on_message(raw); },
      config_.queue_capacity);
}

Logger::~Logger() {
  if (subscription_ >= 0) transport_.unsubscribe(subscription_);
}

double Logger::throttle_interval(const std::string& channel) const {
  for (const auto& [regex, interval] : throttles_) {
    if (std::regex_match(channel, regex)) return interval;
  }
  return 0.0;
}

ChannelCounts& Logger::channel(const std::string& name) {
  // Beyond max_channels, new channels share one entry, never throttled (its channels differ).
  const bool alone = channels_.size() < static_cast<std::size_t>(config_.max_channels);
  auto it = channel_index_.find(name);
  if (it == channel_index_.end() && !alone) it = channel_index_.find(kOtherChannels);
  if (it != channel_index_.end()) return channels_[it->second];
  const std::string& key = alone ? name : kOtherChannels;
  channel_index_.emplace(key, channels_.size());
  ChannelCounts counts;
  counts.channel = key;
  // Regexes run once per channel.
  counts.throttle_interval_s = alone ? throttle_interval(name) : 0.0;
  channels_.push_back(std::move(counts));
  return channels_.back();
}

void Logger::on_message(const transport::RawMessage& raw) {
  ChannelCounts& counts = channel(raw.channel);
  ++counts.received;
  ++received_;
  std::uint64_t fingerprint = 0;
  if (read_fingerprint(raw.data, raw.size, fingerprint) && counts.fingerprints.size() < 4 &&
      std::find(counts.fingerprints.begin(), counts.fingerprints.end(), fingerprint) ==
          counts.fingerprints.end()) {
    counts.fingerprints.push_back(fingerprint);
  }
  if (counts.throttle_interval_s > 0.0 && counts.written > 0 &&
      static_cast<double>(raw.recv_utime - counts.last_written_utime) <
          counts.throttle_interval_s * 1e6) {
    ++counts.throttled;
    ++throttled_;
    return;
  }
  try {
    writer_.write(raw.channel, raw.data, raw.size, raw.recv_utime);
  } catch (const LogError& e) {
    ++counts.write_errors;
    ++write_errors_;
    // One line per error would flood a full disk's worth of messages into stderr.
    if (write_errors_ == 1 || write_errors_ % 1000 == 0) {
      std::cerr << "auv_logger: " << e.what() << " (" << write_errors_ << " write errors)\n";
    }
    return;
  }
  ++counts.written;
  ++written_;
  counts.bytes_written += RotatingLogWriter::event_bytes(raw.channel.size(), raw.size);
  counts.last_written_utime = raw.recv_utime;
  unflushed_ = true;
}

void Logger::flush() {
  if (!unflushed_) return;
  try {
    writer_.flush();
  } catch (const LogError& e) {
    std::cerr << "auv_logger: " << e.what() << "\n";
  }
  unflushed_ = false;
}

void Logger::poll(int timeout_ms) {
  // A bounded batch: under a flood, the flush and the heartbeat below still run on time.
  constexpr int kBatch = 2000;
  if (transport_.handle_one(timeout_ms)) {
    for (int i = 1; i < kBatch && transport_.handle_one(0); ++i) {
    }
  }
  const auto now = Clock::now();
  if (now >= next_flush_) {
    flush();
    next_flush_ = now + seconds(config_.flush_period_s);
  }
  if (now >= next_heartbeat_) {
    publish_heartbeat();
    next_heartbeat_ = now + seconds(config_.heartbeat_period_s);
  }
}

int Logger::drain(int max_ms) {
  const auto deadline = Clock::now() + std::chrono::milliseconds(max_ms);
  int count = 0;
  while (Clock::now() < deadline && transport_.handle_one(0)) ++count;
  return count;
}

auvrl_lcm::logger_heartbeat_t Logger::heartbeat() const {
  auvrl_lcm::logger_heartbeat_t hb{};
  hb.utime = transport::now_utime();
  hb.pid = static_cast<std::int32_t>(getpid());
  hb.log_dir = config_.dir;
  hb.current_file = writer_.current_path();
  hb.files_written = static_cast<std::int32_t>(writer_.files().size());
  hb.bytes_written = static_cast<std::int64_t>(writer_.bytes_written());
  hb.messages_received = received_;
  hb.messages_written = written_;
  hb.messages_throttled = throttled_;
  hb.write_errors = write_errors_;
  hb.uptime_s = std::chrono::duration<double>(Clock::now() - start_).count();
  hb.num_channels = static_cast<std::int32_t>(channels_.size());
  for (const ChannelCounts& c : channels_) {
    hb.channel.push_back(c.channel);
    hb.received.push_back(c.received);
    hb.written.push_back(c.written);
    hb.throttled.push_back(c.throttled);
  }
  return hb;
}

void Logger::publish_heartbeat() {
  try {
    transport::publish(transport_, channels::kLoggerHeartbeat, heartbeat());
  } catch (const transport::TransportError& e) {
    std::cerr << "auv_logger: heartbeat not sent: " << e.what() << "\n";
  }
}

void Logger::write_summary(std::ostream& out, const Schema* schema) const {
  const std::int64_t now = transport::now_utime();
  out << "auv_logger summary\n";
  out << "started   " << utc_text(start_utime_) << " (utime " << start_utime_ << ")\n";
  out << "stopped   " << utc_text(now) << " (utime " << now << ")\n";
  out << "directory " << config_.dir << "\n";
  out << "files    ";
  for (const std::string& file : writer_.files()) {
    out << " " << file.substr(file.rfind('/') + 1);
  }
  out << "\nbytes_written " << writer_.bytes_written() << "\n";
  out << "messages received " << received_ << " written " << written_ << " throttled " << throttled_
      << " write_errors " << write_errors_ << "\n\n";
  std::size_t width = 8;
  for (const ChannelCounts& c : channels_) width = std::max(width, c.channel.size());
  out << fmt::format("{:<{}}{:>12}{:>12}{:>12}{:>8}{:>14}  type\n", "channel", width, "received",
                     "written", "throttled", "errors", "bytes");
  for (const ChannelCounts& c : channels_) {
    std::string types;
    for (const std::uint64_t fp : c.fingerprints) {
      if (!types.empty()) types += ", ";
      types += schema != nullptr ? schema->names_for(fp) : fingerprint_hex(fp);
    }
    out << fmt::format("{:<{}}{:>12}{:>12}{:>12}{:>8}{:>14}  {}\n", c.channel, width, c.received,
                       c.written, c.throttled, c.write_errors, c.bytes_written, types);
  }
}

std::string Logger::finish(const Schema* schema) {
  if (finished_) return "";
  finished_ = true;
  drain(2000);
  flush();
  writer_.close();
  publish_heartbeat();
  if (subscription_ >= 0) {
    transport_.unsubscribe(subscription_);
    subscription_ = -1;
  }
  const std::string path = fmt::format("{}/{}-{:04d}-summary.txt", config_.dir, config_.prefix,
                                       writer_.first_file_number());
  std::ofstream out(path);
  write_summary(out, schema);
  out.close();
  if (!out) throw LogError("cannot write the summary " + path);
  return path;
}

}  // namespace auvrl::logger
