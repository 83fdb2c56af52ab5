// auv_logger: logs every channel (or a pattern) into rotating LCM event logs until SIGINT or
// SIGTERM, then flushes, writes a summary of counts and exits. Parses the command line and
// wires library pieces; the logic is in logger/logger.cpp and logger/logger_process.cpp.
#include <iostream>
#include <memory>

#include "common/cli.hpp"
#include "common/transport_options.hpp"
#include "logger/logger.hpp"
#include "logger/logger_process.hpp"
#include "logger/schema.hpp"

int main(int argc, char** argv) {
  using namespace auvrl;
  logger::LoggerConfig config;
  transport::TransportConfig transport_config;
  std::vector<std::string> throttles;
  std::string types_dir = logger::default_types_dir();

  cli::CommandLine cmd(
      "auv_logger",
      "Writes the traffic of the transport (LCM or DDS; every channel, or those matching "
      "--channels) into LCM event logs "
      "(lcm-logger's format) in --dir, rotating by size, and publishes counts on " +
          channels::kLoggerHeartbeat + ".");
  cmd.option("dir", &config.dir, "directory of the log files (created if missing)");
  cmd.require("dir");
  cmd.option("prefix", &config.prefix, "log files are PREFIX-NNNN.lcmlog");
  cmd.option("channels", &config.channels, "full-match regex of the channels to log");
  cmd.option("max-file-mb", &config.max_file_mb, "start a new file before one exceeds this, MB");
  cmd.option("flush-period", &config.flush_period_s, "flush buffered events at least every, s");
  cmd.option("heartbeat-period", &config.heartbeat_period_s, "heartbeat period, s");
  cmd.repeatable("throttle", &throttles,
                 "REGEX=SECONDS: log those channels at most once per interval (built in: " +
                     logger::kDefaultPolicyThrottle.pattern + "=10; =0 turns a rule off)");
  cmd.option("types-dir", &types_dir, "directory of the .lcm files (names types in the summary)");
  cmd.option("queue-capacity", &config.queue_capacity,
             "messages the transport may hold between polls");
  cmd.option("max-channels", &config.max_channels,
             "channels counted each on its own; further ones are logged and counted together "
             "as " +
                 logger::kOtherChannels);
  transport::add_transport_options(cmd, transport_config);
  transport_config.dds.role = "logger";
  try {
    if (!cmd.parse(argc, argv)) return 0;
    logger::add_throttle_rules(throttles, config);
  } catch (const std::exception& e) {
    std::cerr << "auv_logger: " << e.what() << "\n";
    return 2;
  }
  const std::unique_ptr<logger::Schema> schema = logger::load_summary_schema(types_dir, std::cerr);
  try {
    return logger::run_logger_process(config, transport_config, schema.get(), std::cerr);
  } catch (const std::exception& e) {
    std::cerr << "auv_logger: " << e.what() << "\n";
    return 1;
  }
}
